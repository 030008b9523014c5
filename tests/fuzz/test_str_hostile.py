"""Words given as ``str`` subclasses that raise or lie, or as no str.

A choice (``kind="force"``, ``plane="xy"``, ``mu="plant"``) is compared,
hashed and cut in Python.  A ``str`` subclass passes ``isinstance(x, str)``
while its own ``==``, ``__hash__``, ``strip``, ``rpartition`` or ``encode``
raise or lie; an object whose ``__class__`` claims ``str`` passes it too,
and ``str``'s own methods then raise a bare TypeError.  Each reader reads the value once
as the plain ``str`` it holds (``str.__str__``), or refuses it by name:

- a subclass holding a valid word answers as the plain word does (its lies
  change nothing: ``StrLies("inside")``, equal to everything, was taken for
  ``"outside"`` by ``side == "outside"``);
- one holding no valid word, and the pretender, are a GraspError naming the
  parameter, in a short message.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

import drakegrasp as dg
from drakegrasp.batch.api import iter_batch_closure
from drakegrasp.batch.files.writer import format_of
from drakegrasp.certificates.kinds import check_kind_and_cones
from drakegrasp.closure.programs import check_formulation
from drakegrasp.visualization.geometry import side_sign

sys.path.insert(0, str(Path(__file__).resolve().parent))
import hostile  # noqa: E402

SHORT = 2_000
"""Characters a refusal's message may take, whatever the value."""

KINDS = [type(v).__name__ for v in hostile.str_hostile("x")]


def _grasp():
    return dg.core.examples.equator_fingers(0.5)


def _batch_kind(kind):
    g = _grasp()
    chunk = (g.positions[None], g.normals[None])
    return next(iter_batch_closure([chunk], kind=kind)).is_closure.tolist()


# (parameter, call, a valid word, another valid word): call(word) is a plain
# value to compare; the two words answer differently, so a lie would show.
WORDS = [
    ("side", side_sign, "inside", "outside"),
    ("plane", lambda v: dg.AnalysisOptions(plane=v).plane, "xy", "yz"),
    ("patches", lambda v: dg.AnalysisOptions(patches=v).patches, "witness", None),
    ("mu", lambda v: dg.AnalysisOptions(mu=v).mu, "plant", None),
    ("load", lambda v: dg.AnalysisOptions(load=v).load, "gravity", None),
    ("kernel", lambda v: dg.BatchOptions(kernel=v).kernel, "numpy", "auto"),
    ("metric", lambda v: dg.BatchOptions(metrics=[v]).metrics, "isotropy", None),
    ("format", lambda v: format_of("out", v), "parquet", "npz"),
    ("norm", lambda v: dg.ferrari_canny(_grasp(), norm=v), "Linf", "L1"),
    ("kind", _batch_kind, "form", None),  # "force" takes mu, "form" refuses it
    ("formulation", check_formulation, "generators", "facets"),
    (
        "kind",
        lambda v: check_kind_and_cones(v, "exact", ("force", "form"), ("exact",)),
        "form",
        "force",
    ),
]
WORD_IDS = [f"{name}-{i}" for i, (name, *_) in enumerate(WORDS)]


@pytest.mark.parametrize(("name", "call", "word", "other"), WORDS, ids=WORD_IDS)
def test_a_word_of_a_hostile_str_subclass_answers_as_the_plain_word(
    name, call, word, other
):
    plain = call(word)
    if other is not None:
        assert call(other) != plain  # the two words tell the answers apart
    for kind, value in zip(KINDS, hostile.str_hostile(word), strict=True):
        if kind == "ClaimsStr":
            continue  # holds no word: refused below
        answer = call(value)
        assert answer == plain, kind
        assert type(answer) is type(plain), kind  # a plain str, never the subclass


@pytest.mark.parametrize(("name", "call", "word", "other"), WORDS, ids=WORD_IDS)
def test_a_hostile_str_that_holds_no_word_is_refused_by_name(name, call, word, other):
    values = [*hostile.str_hostile("nope"), "\ud800", "a\0b", "x" * hostile.HUGE]
    for value in values:
        with pytest.raises(dg.GraspError, match=name) as refused:
            call(value)
        assert len(str(refused.value)) <= SHORT, type(value).__name__
