r"""Joint couplings of a hand: read where the models enter the plant, used in J.

A URDF ``<mimic>`` or an SDFormat ``<drake:mimic>`` makes Drake add a coupler
constraint ``q_0 = ρ q_1 + Δq`` (``MultibodyPlant.AddCouplerConstraint(joint_0,
joint_1, ρ, Δq)``): ``joint_0`` *follows* ``joint_1``.  pydrake cannot read a
constraint back from a plant, so drakegrasp reads each coupling where it enters
the plant and records it on the plant:

- :func:`add_models` — a drop-in for ``Parser.AddModels`` that also reads the
  mimic elements of the file (or URL, or text) it parses;
- :func:`drakegrasp.load_scene` — every model of a scene file;
- :func:`add_coupler_constraint` — ``plant.AddCouplerConstraint`` for a
  coupling written in code.

:func:`plant_couplings` returns what was recorded; an explicit ``couplings=``
argument (of :func:`~drakegrasp.close_hand`, :func:`~drakegrasp.grasp_from_plant`
and :func:`~drakegrasp.analyze_grasp`) overrides it, and a plant with more
constraints than recorded couplings is refused rather than analysed as if its
joints were free.

**The coupling map.**  With the hand's velocities ``v_h`` (one-dof joints:
``v = q̇``), a follower moves as ``v_f = ρ v_l``, so ``v_h = C u`` with ``u``
the *independent* velocities (every hand velocity but the followers') and
``C`` the identity on them plus ``ρ`` in the follower's row and the leader's
column.  The hand Jacobian of a coupled hand is ``J C``: one column per
independent motion, so LP3 judges the motors the hand has.

**The motors of a coupled hand.**  Every actuator still pushes: with ``τ``
the actuators' efforts on ``v_h`` (``|τ_k| <= τ_max,k``) and ``λ`` the
coupler constraint's force, statics reads ``Jᵀ f = τ + λ`` with ``λ`` in
``N(Cᵀ)`` (a constraint force does no work along ``v_h = C u``), so the
generalized force on the independent coordinates is
``(J C)ᵀ f = Cᵀ τ``: on ``u_i``, ``τ_i + Σ_k ρ_k τ_k`` over the joints that
follow it.  The motors' set is the image of the box of effort limits under
``Cᵀ``; a follower follows one leader (one nonzero per row of ``C``), so
that image is again a box, ``|u_i| <= Σ_k |C_ki| τ_max,k``
(:func:`coupled_torque_limits`).
"""

from __future__ import annotations

import math
import re
import weakref
import xml.etree.ElementTree as ET
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import Joint, ModelInstanceIndex

from drakegrasp.core.calls import checked_call
from drakegrasp.core.files import MISSING, not_a_file
from drakegrasp.core.tolerances import COUPLING_TOL
from drakegrasp.core.validation import describe, path_text, plain_str
from drakegrasp.errors import InvalidOptionError, ModelError, type_name
from drakegrasp.plant.fingers import (
    chain_root,
    coupling_entries,
    coupling_entry,
    joint_name,
)
from drakegrasp.plant.models import load_models
from drakegrasp.plant.validation import check_plant

__all__ = [
    "COUPLING_TOL",
    "CouplingViolation",
    "JointCoupling",
    "add_coupler_constraint",
    "add_models",
    "check_joint_limits",
    "coupled_positions",
    "coupled_torque_limits",
    "coupling_map",
    "coupling_violations",
    "couplings_in_model",
    "model_resolver",
    "motor_shares",
    "plant_couplings",
    "record_model_couplings",
    "recorded_couplings",
    "split_coupled_torque",
]

_DRAKE_NS = "{http://drake.mit.edu}"


@checked_call
class JointCoupling(NamedTuple):
    """``q_follower = gear_ratio * q_leader + offset`` (Drake's coupler constraint).

    A tuple ``(joint_0, joint_1, gear_ratio, offset)`` as ``couplings=`` takes
    it; the joints are scoped names ``model::joint``.
    """

    follower: str
    leader: str
    gear_ratio: float
    offset: float

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return dict(self._asdict())


_RECORDED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
"""Per plant: the couplings recorded as its models were added."""


def _record(plant: MultibodyPlant, couplings: Iterable[JointCoupling]) -> None:
    known = _RECORDED.setdefault(plant, [])
    for c in couplings:
        if c not in known:
            known.append(c)


def couplings_in_model(
    text: str, kind: str, *, resolve=None
) -> list[list[tuple[str, str, float, float]]]:
    """The mimic elements of a URDF or SDFormat document, per model.

    Parameters
    ----------
    text : str
        The document.
    kind : {"urdf", "sdf"}
        Its format.
    resolve : callable, optional
        ``resolve(uri) -> (text, kind, resolve) or None``: an SDFormat
        ``<include>``'s document (and how to resolve the includes in it);
        without it, includes are not read.

    Returns
    -------
    list of list of (follower, leader, gear_ratio, offset)
        One list per model, in the document's order (a URDF has one model; an
        SDFormat file one per top-level ``<model>``), with joint names local
        to the model: a nested (or included) model's joints as
        ``nested::joint``, as Drake scopes them.  ``multiplier`` defaults to 1
        and ``offset`` to 0, as in Drake's parsers.

    Raises
    ------
    ModelError
        For a document that is not XML or a mimic element without a joint.
    """
    if kind not in ("urdf", "sdf"):
        raise InvalidOptionError(f"kind must be 'urdf' or 'sdf', got {kind!r}")
    root = _xml_root(text, "cannot read the model's couplings")
    if kind == "urdf":
        return [_mimics(root, "mimic", "", recurse=False)]
    models = [root] if root.tag == "model" else root.findall("model")
    return [_sdf_mimics(m, "", resolve, 0) for m in models]


_MAX_INCLUDE_DEPTH = 16
"""Includes followed at most this deep (a loop of includes stops there)."""


def _xml_root(text: str, what: str):
    try:
        return ET.fromstring(_with_prefixes_declared(text))
    except ET.ParseError as e:
        raise ModelError(f"{what}: {e}") from None


def _mimics(element, tag: str, prefix: str, *, recurse: bool) -> list[tuple]:
    """``(follower, leader, ratio, offset)`` of the joints of ``element``."""
    found = []
    joints = element.iter("joint") if recurse else element.findall("joint")
    for joint in joints:
        for mimic in joint.findall(tag):
            leader = mimic.get("joint")
            if not leader:
                raise ModelError(
                    f"the mimic element of joint {joint.get('name')!r} names no "
                    "joint to follow"
                )
            found.append(
                (
                    prefix + str(joint.get("name")),
                    prefix + leader,
                    float(mimic.get("multiplier", 1.0)),
                    float(mimic.get("offset", 0.0)),
                )
            )
    return found


def _sdf_mimics(model, prefix: str, resolve, depth: int) -> list[tuple]:
    """A model's mimics, its nested and included models' scoped under it."""
    found = _mimics(model, _DRAKE_NS + "mimic", prefix, recurse=False)
    for nested in model.findall("model"):
        found += _sdf_mimics(nested, f"{prefix}{nested.get('name')}::", resolve, depth)
    if resolve is None or depth >= _MAX_INCLUDE_DEPTH:
        return found
    for include in model.findall("include"):
        got = resolve((include.findtext("uri") or "").strip())
        if got is None:
            continue
        text, kind, inner = got
        root = _xml_root(text, "cannot read an included model's couplings")
        if kind == "urdf":
            name = include.findtext("name") or root.get("name")
            merged = (include.get("merge") or "").strip().lower() == "true"
            scope = prefix if merged else f"{prefix}{name}::"
            found += _mimics(root, "mimic", scope, recurse=False)
            continue
        merged = (include.get("merge") or "").strip().lower() == "true"
        for included in [root] if root.tag == "model" else root.findall("model")[:1]:
            name = include.findtext("name") or included.get("name")
            scope = prefix if merged else f"{prefix}{name}::"  # merge: the parent's
            found += _sdf_mimics(included, scope, inner, depth + 1)
    return found


def model_resolver(package_map, folder: Path):
    """``resolve(uri)`` for :func:`couplings_in_model` and :func:`check_joint_limits`.

    ``package://`` and ``file://`` URIs through ``package_map``, other paths
    beside ``folder``; None for what is not a URDF or SDFormat file there.
    """

    def resolve(uri: str):
        try:
            if "://" in uri:
                path = Path(package_map.ResolveUrl(uri))
            else:
                path = folder / uri
            kind = _kind_of(str(path))
            if not kind or not path.is_file():
                return None  # a model folder (model.config), or nothing there
            return path.read_text(), kind, model_resolver(package_map, path.parent)
        except (RuntimeError, OSError, ValueError):
            return None  # Drake's parser reports what it cannot find

    return resolve


_PROLOG = re.compile(
    r"\ufeff?(?:\s|<\?.*?\?>|<!--.*?-->|<!DOCTYPE[^>]*>)*<([\w:.-]+)", re.S
)
"""What comes before the root element's name (an XML declaration, comments,
a doctype), then that name."""


def _with_prefixes_declared(text: str) -> str:
    """``text``, its root declaring every namespace prefix it uses undeclared.

    Drake's parser reads ``<drake:mimic>`` in a file that declares no
    ``xmlns:drake``, or a URDF's ``<gazebo><sensor:camera/>``; an XML parser
    refuses them.  ``drake`` gets Drake's namespace (where ``<drake:mimic>``
    is looked for), any other prefix a placeholder.
    """
    used = set(re.findall(r"</?([A-Za-z_][\w.-]*):[A-Za-z_]", text))
    used |= set(re.findall(r"\s([A-Za-z_][\w.-]*):[A-Za-z_][\w.-]*\s*=", text))
    used -= {"xmlns", "xml"}
    missing = sorted(p for p in used if f"xmlns:{p}=" not in text)
    root = _PROLOG.match(text)
    if not missing or root is None:
        return text
    declared = " ".join(
        f'xmlns:{p}="{_DRAKE_NS[1:-1] if p == "drake" else "urn:undeclared:" + p}"'
        for p in missing
    )
    return f"{text[: root.end()]} {declared}{text[root.end() :]}"


def _kind_of(name: str) -> str:
    suffix = Path(name).suffix.lower()
    if suffix == ".urdf":
        return "urdf"
    if suffix == ".sdf":
        return "sdf"
    return ""


def _scoped(plant: MultibodyPlant, instance, local: str) -> str:
    return f"{plant.GetModelInstanceName(instance)}::{local}"


def _record_text(
    plant, text: str, kind: str, instances: Sequence, resolve=None
) -> None:
    """Record the mimic couplings of models just parsed, if Drake kept them.

    Drake's parser ignores a ``<mimic>`` (with a warning) unless the plant can
    enforce it (a discrete SAP plant, or a continuous one): then the joints
    move freely in its simulation, and recording them as coupled would make
    the analysis, the pose check and the load check judge a hand Drake does
    not simulate.  So they are recorded only when the plant holds a
    constraint for each (its constraints at least those recorded plus these).
    """
    if "mimic" not in text and "<include" not in text:
        return  # nothing to record: the file is not read as XML
    # the top-level models' instances (Drake lists nested ones after each)
    names = [plant.GetModelInstanceName(i) for i in instances]
    instances = [
        i
        for i, name in zip(instances, names, strict=True)
        if not any(name.startswith(f"{other}::") for other in names)
    ]
    try:
        per_model = list(couplings_in_model(text, kind, resolve=resolve))
        per_model = per_model[: len(instances)]
    except ModelError:
        if plant.num_constraints() <= len(_RECORDED.get(plant, ())):
            return  # a file XML cannot read, but Drake made no coupler of it
        raise
    declared = sum(len(found) for found in per_model)
    if plant.num_constraints() < len(_RECORDED.get(plant, ())) + declared:
        return  # Drake dropped them: the joints are free in this plant
    for instance, found in zip(instances, per_model, strict=False):
        _record(
            plant,
            (
                JointCoupling(
                    _scoped(plant, instance, f), _scoped(plant, instance, lead), r, o
                )
                for f, lead, r, o in found
            ),
        )


def record_model_couplings(
    plant: MultibodyPlant, infos: Iterable, package_map=None
) -> None:
    """Record the couplings of models added by ``ProcessModelDirectives``.

    Parameters
    ----------
    plant : MultibodyPlant
        The plant the models were added to.
    infos : iterable of ModelInstanceInfo
        What ``ProcessModelDirectives`` returned (each with its resolved
        ``model_path`` and ``model_instance``).
    package_map : PackageMap, optional
        The parser's, to read the mimics of the models' ``<include>`` s.
    """
    for info in infos:
        kind = _kind_of(info.model_path)
        if kind:
            path = Path(info.model_path)
            _record_text(
                plant,
                path.read_text(),
                kind,
                [info.model_instance],
                model_resolver(package_map, path.parent) if package_map else None,
            )


@checked_call
def add_models(
    parser: Parser,
    file_name: str | Path | None = None,
    *,
    url: str | None = None,
    text: str | None = None,
    kind: str | None = None,
) -> list[ModelInstanceIndex]:
    """``Parser.AddModels`` that also records the models' mimic couplings.

    Parameters
    ----------
    parser : pydrake.multibody.parsing.Parser
        The user's parser (its package map resolves ``url``).
    file_name : str or Path, optional
        A URDF or SDFormat file.
    url : str, optional
        A ``package://`` or ``file://`` URL instead.
    text : str, optional
        The document itself instead; then ``kind`` (``"urdf"`` or ``"sdf"``)
        is required.

    Returns
    -------
    list of ModelInstanceIndex
        What the parser returned.

    Raises
    ------
    InvalidOptionError
        Unless exactly one of ``file_name``, ``url`` and ``text`` is given,
        as a string (``file_name`` also a path); for a ``parser`` that is not
        a pydrake ``Parser``.
    ModelError
        Drake cannot load the models (a missing or unreadable file, an unknown
        package, text that is not a model), as :func:`drakegrasp.load_scene`.
    """
    if not isinstance(parser, Parser):
        raise InvalidOptionError(
            f"parser must be a pydrake Parser, got {describe(parser)} "
            f"({type(parser).__name__})"
        )
    given = [x is not None for x in (file_name, url, text)]
    if sum(given) != 1:
        raise InvalidOptionError("give exactly one of file_name, url and text")
    if file_name is not None:
        file_name = path_text(
            "file_name", file_name, must="a string or a path (an os.PathLike)"
        )
    if url is not None:
        if not issubclass(type(url), str):  # no path: a URL
            raise InvalidOptionError(
                f"url must be a string, got {describe(url)} ({type(url).__name__})"
            )
        url = path_text("url", url, must="a string")
    text = plain_str(text)
    if text is not None and type(text) is not str:
        raise InvalidOptionError(
            f"text must be a string, got {describe(text)} ({type_name(text)})"
        )
    plant = parser.plant()
    if text is not None:
        kind = plain_str(kind)
        if type(kind) is not str or kind not in ("urdf", "sdf"):
            raise InvalidOptionError(
                f"text needs kind='urdf' or 'sdf', got {describe(kind)}"
            )
        resolve = model_resolver(parser.package_map(), Path.cwd())
        check_joint_limits(text, kind, "the model text", resolve=resolve)
        instances = load_models(
            "the model text", parser.AddModelsFromString, text, kind
        )
        _record_text(plant, text, kind, instances, resolve)
        return instances
    if url is not None:
        where = f"model URL {describe(url)}"
        path = load_models(where, parser.package_map().ResolveUrl, url)
    else:
        where = f"model file {file_name!r}"
        path = file_name
    why = not_a_file(path, "a model file")
    if why and why != MISSING:  # a pipe would block Drake's parser for good
        raise ModelError(f"{where} {why}")
    kind = _kind_of(path)
    document = None
    if kind and not why:
        try:
            document = Path(path).read_text()
        except (OSError, UnicodeDecodeError) as e:
            raise ModelError(f"{where}: cannot read it: {e}") from None
    resolve = model_resolver(parser.package_map(), Path(path).parent)
    if document is not None:
        check_joint_limits(document, kind, path, resolve=resolve)
    # through load_models: a shape Drake refuses (a sphere of radius NaN)
    # is a ModelError, not pydrake's SystemExit that ends the program
    if url is not None:
        instances = load_models(where, parser.AddModels, url=url)
    else:
        instances = load_models(where, parser.AddModels, file_name)
    if document is not None:
        _record_text(plant, document, kind, instances, resolve)
    return instances


def check_joint_limits(
    text: str, kind: str, where: str, *, resolve=None, depth: int = 0
) -> None:
    """Refuse joint limits that would stop the process inside Drake.

    Drake stops the whole process (a failed internal condition, not an
    exception) on a joint whose lower position limit lies above its upper one,
    or is NaN.  Its SDFormat parser refuses a reversed pair itself, but not a
    NaN; its URDF parser refuses a NaN, not a reversed pair.  So the document
    (and with ``resolve``, as for :func:`couplings_in_model`, the SDFormat
    files it includes) is read first, as
    Drake reads it: the limits of revolute and prismatic joints, and of a
    URDF's continuous ones (Drake ignores the others'), a missing bound as no
    bound (∓inf).  A URDF
    value is read by its leading decimal number, as Drake's URDF parser reads
    it (``0.5abc`` is 0.5, ``1_0`` is 1, ``0x1p-1`` is 0); an SDFormat pair is
    compared only where both are plain numbers (SDFormat reads other forms
    its own way, and Drake refuses a reversed pair there itself).  A document
    that is not XML, or a value without a leading number, is left to Drake's
    parser, which reports it.

    Raises
    ------
    ModelError
        Naming the joint, its limits and ``where`` the document came from.
    """
    if "limit" not in text and "<include" not in text:
        return
    try:
        root = ET.fromstring(_with_prefixes_declared(text))
    except ET.ParseError:
        return
    if kind == "sdf" and resolve is not None and depth < _MAX_INCLUDE_DEPTH:
        for include in root.iter("include"):
            uri = (include.findtext("uri") or "").strip()
            got = resolve(uri)
            if got is not None:
                inner_text, inner_kind, inner = got
                check_joint_limits(
                    inner_text, inner_kind, f"{uri} (included by {where})",
                    resolve=inner, depth=depth + 1,
                )  # fmt: skip
    for joint in root.iter("joint"):
        if (joint.get("type") or "").lower() not in _LIMITED_JOINTS[kind]:
            continue
        if kind == "urdf":
            limit = joint.find("limit")
            bounds = [] if limit is None else [(limit.get("lower"), limit.get("upper"))]
        else:
            bounds = [
                (limit.findtext("lower"), limit.findtext("upper"))
                for limit in joint.findall("axis/limit")
            ]
        name = joint.get("name")
        for lower, upper in bounds:
            lo = _limit_value(lower, -math.inf, kind)
            hi = _limit_value(upper, math.inf, kind)
            if any(v is not None and math.isnan(v) for v in (lo, hi)):
                raise ModelError(
                    f"joint {name!r} in {where} has a limit that is not a number "
                    f"(lower {lower!r}, upper {upper!r}): give a number or leave the "
                    "bound out (Drake cannot load such a joint)"
                )
            if lo is None or hi is None:
                continue  # no number Drake reads alike: its parser says
            if lo > hi:
                raise ModelError(
                    f"joint {name!r} in {where} has its lower limit {lo:g} above "
                    f"its upper limit {hi:g}: swap them (Drake cannot load such a "
                    "joint)"
                )


_LIMITED_JOINTS = {
    "urdf": ("revolute", "prismatic", "continuous"),
    "sdf": ("revolute", "prismatic"),
}
"""Joint types whose position limits Drake reads (an SDFormat continuous joint
has none in Drake; SDFormat itself refuses its reversed pair)."""

_LEADING_NUMBER = re.compile(r"\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)")
_NAN = re.compile(r"\s*[+-]?nan", re.IGNORECASE)


def _limit_value(text: str | None, missing: float, kind: str) -> float | None:
    """A limit's text as Drake reads it: a number, NaN, or None (Drake's to say).

    A URDF value's leading decimal number; an SDFormat value only when it is
    a plain number as a whole.
    """
    if text is None:
        return missing
    if _NAN.match(text):
        return math.nan
    number = (
        _LEADING_NUMBER.match(text)
        if kind == "urdf"
        else _LEADING_NUMBER.fullmatch(text.strip())
    )
    return float(number.group(1)) if number else None


@checked_call
def add_coupler_constraint(
    plant: MultibodyPlant,
    joint_0: Joint,
    joint_1: Joint,
    gear_ratio: float,
    offset: float = 0.0,
):
    """``plant.AddCouplerConstraint`` that drakegrasp can read back.

    ``q_0 = gear_ratio * q_1 + offset``; returns Drake's constraint id.

    Raises
    ------
    ModelError
        For what is not a ``MultibodyPlant``, or one already finalized.
    InvalidOptionError
        For what is not a joint of the plant, a joint coupled to itself, a
        gear ratio that is not a finite non-zero real number or an offset that
        is not a finite real number (Drake would take a NaN, or another
        plant's joint for the one of that index).
    """
    check_plant(plant, finalized=False)
    if plant.is_finalized():
        raise ModelError(
            "add_coupler_constraint adds a constraint to the plant before "
            "plant.Finalize(); this plant is finalized"
        )
    joint_0, joint_1, gear_ratio, offset = coupling_entry(
        plant, (joint_0, joint_1, gear_ratio, offset)
    )
    cid = plant.AddCouplerConstraint(joint_0, joint_1, gear_ratio, offset)
    _record(
        plant,
        [
            JointCoupling(
                _scoped(plant, joint_0.model_instance(), joint_0.name()),
                _scoped(plant, joint_1.model_instance(), joint_1.name()),
                float(gear_ratio),
                float(offset),
            )
        ],
    )
    return cid


@checked_call
def plant_couplings(plant: MultibodyPlant, couplings=None) -> tuple:
    """The couplings to use: ``couplings`` when given, else those of the plant.

    A chain of couplings (a joint following a joint that follows another, as
    Drake's coupler constraints allow) is resolved to its root: each follower
    of a chain is coupled to the chain's first leader, ``q_2 = ρ_a q_1 + Δ_a``
    and ``q_1 = ρ_b q_0 + Δ_b`` giving ``q_2 = ρ_a ρ_b q_0 + ρ_a Δ_b + Δ_a``,
    the same set of positions, so every follower follows a joint that follows
    none.

    Parameters
    ----------
    plant : MultibodyPlant
    couplings : sequence of (joint_0, joint_1, gear_ratio, offset), optional
        An explicit list (``()`` for none) overrides what was recorded.

    Returns
    -------
    tuple
        ``couplings`` as given, or the recorded :class:`JointCoupling` s; where
        they hold a chain, :class:`JointCoupling` s of scoped names, each
        follower's to the root of its chain.

    Raises
    ------
    InvalidOptionError
        When ``couplings`` is None and the plant has constraints that were not
        recorded as couplings (a ``<mimic>`` parsed by a bare ``Parser``, a
        constraint added in code): names the ways to tell drakegrasp.  For
        couplings that close a loop, or a joint that follows two joints.
    """
    if couplings is not None:
        return _resolved_chains(plant, coupling_entries(couplings))
    check_plant(plant, finalized=False)
    known = tuple(_RECORDED.get(plant, ()))
    if plant.num_constraints() > len(known):
        raise InvalidOptionError(
            f"the plant has {plant.num_constraints()} constraint(s) and drakegrasp "
            f"knows {len(known)} of them as joint couplings (a URDF <mimic> or "
            "SDFormat <drake:mimic> becomes a coupler constraint, which pydrake "
            "cannot read back): load the models with drakegrasp.plant.add_models"
            "(parser, ...) or a scene file, add the constraint with "
            "drakegrasp.plant.add_coupler_constraint, or pass couplings=[(joint_0, "
            "joint_1, gear_ratio, offset)] (couplings=() to ignore them)"
        )
    return _resolved_chains(plant, known)


def _resolved_chains(plant: MultibodyPlant, entries: tuple) -> tuple:
    """``entries`` with each chain resolved to its root (:func:`plant_couplings`).

    Entries without a chain are returned as they are (the same objects).
    """
    if len(entries) < 2:
        return entries
    named = {}
    for entry in entries:
        if type(entry) is JointCoupling:  # recorded: scoped names, checked then
            follower, leader, rho, offset = entry
        else:
            j0, j1, rho, offset = coupling_entry(plant, entry)
            follower, leader = joint_name(plant, j0), joint_name(plant, j1)
        if named.get(follower, (leader, rho, offset)) == (leader, rho, offset):
            named[follower] = (leader, rho, offset)  # a repeated coupling is one
            continue
        if follower in named:
            raise InvalidOptionError(
                f"joint {follower} follows two joints ({named[follower][0]} and "
                f"{leader}); a joint follows at most one"
            )
    if not any(leader in named for leader, _, _ in named.values()):
        return entries
    resolved = []
    for follower in named:
        root, rho, offset, path = chain_root(named, follower)
        coupling = _ChainCoupling(follower, root, rho, offset)
        coupling.links = tuple(JointCoupling(f, *named[f]) for f in path[:-1])
        resolved.append(coupling)
    return tuple(resolved)


class _ChainCoupling(JointCoupling):
    """A :class:`JointCoupling` resolved to its chain's root.

    Equal to the plain tuple; ``links`` holds the chain as recorded, follower
    first, for :func:`coupling_map`, which keeps the part of a chain inside
    the hand when its root lies outside.
    """

    links: tuple = ()


def coupling_map(
    plant: MultibodyPlant, velocity_indices: np.ndarray, couplings: Sequence
) -> tuple[np.ndarray, np.ndarray]:
    """``C`` with ``v_h = C u``, and the plant indices of ``u``.

    Parameters
    ----------
    plant : MultibodyPlant
    velocity_indices : (n_h,) int
        The hand's velocities (plant indices).
    couplings : sequence of (joint_0, joint_1, gear_ratio, offset)
        Couplings whose joints are not both among the hand's velocities are
        left out.  A chain (as recorded, or as :func:`plant_couplings`
        resolves it) is followed to its last joint among them: with ``c → b →
        a`` and ``a`` outside, ``c`` follows ``b``.

    Returns
    -------
    C : (n_h, n_u) float
        Identity on the independent velocities, at (follower, leader) the
        product of the gear ratios along the chain.
    independent : (n_u,) int
        Plant velocity indices of the independent velocities, in order.

    Raises
    ------
    InvalidOptionError
        For an unknown joint, a joint that is not one-dof, or couplings that
        close a loop.
    """
    v = [int(i) for i in velocity_indices]
    row = {vi: k for k, vi in enumerate(v)}
    follows: dict[int, tuple[int, float, float]] = {}
    by_velocity: dict[int, Joint] = {}
    links = [
        link
        for entry in coupling_entries(couplings)
        for link in getattr(entry, "links", None) or (entry,)
    ]
    for entry in links:
        j0, j1, rho, _ = coupling_entry(plant, entry)
        for j in (j0, j1):
            if j.num_velocities() != 1:
                raise InvalidOptionError(
                    f"coupled joint {j.name()!r} has {j.num_velocities()} "
                    "velocities; a coupling joins one-dof joints"
                )
        f, lead = j0.velocity_start(), j1.velocity_start()
        if f in row and lead in row:
            follows[f] = (lead, rho, 0.0)  # velocities: no offset
            by_velocity[f] = j0
    follows = {  # each follower on its chain's last joint here
        f: chain_root(follows, f, lambda x: joint_name(plant, by_velocity[x]))[:2]
        for f in follows
    }
    independent = [vi for vi in v if vi not in follows]
    col = {vi: k for k, vi in enumerate(independent)}
    C = np.zeros((len(v), len(independent)))
    for vi in independent:
        C[row[vi], col[vi]] = 1.0
    for f, (lead, rho) in follows.items():
        C[row[f], col[lead]] = rho
    return C, np.array(independent, dtype=int)


def motor_shares(couplings, joints, actuated, *, drives=()) -> tuple[dict, dict]:
    """Which followers a leader's motor drives, and what it presses them with.

    A ``<mimic>`` follower without an actuator of its own is driven by its
    leader's motor through the coupler: the motor's generalized force is
    ``τ_leader + Σ ρ τ_follower``, so for the leader and each follower to
    press with ``τ`` it applies ``τ (1 + Σ|ρ|)`` (a one-motor jaw: twice
    the squeeze, each finger half the motor's effort limit).  A leader that
    is not among ``joints``, or is one of ``drives`` (a hidden drive: a slide
    or linkage with no geometry, which the fingers follow), presses nothing
    itself: it applies ``τ Σ|ρ|``.

    Parameters
    ----------
    couplings : sequence of (follower, leader, gear_ratio, offset)
        Scoped joint names (:func:`plant_couplings`).
    joints : iterable of str
        The joints considered (a candidate's closing joints), scoped names.
    actuated : iterable of str
        The joints with an actuator: those of ``joints``, and any leader
        outside them whose motor is to count.
    drives : iterable of str, optional
        Leaders that are hidden drives
        (:func:`~drakegrasp.plant.fingers.hidden_drives`): they touch nothing,
        so their motors press only through their followers, also when they are
        among ``joints`` (a multi-finger hand's closing joints hold every joint
        of the hand, its drive too).

    Returns
    -------
    driven : dict of str to str
        Each follower among ``joints`` without an actuator whose leader has
        one, and that leader.
    shares : dict of str to float
        Per leader that drives any: ``1 + Σ|ρ|`` over its driven followers
        (``Σ|ρ|`` for a leader outside ``joints`` or among ``drives``).
    """
    joints, actuated = set(joints) - set(drives), set(actuated)
    driven, shares = {}, {}
    for follower, leader, rho, _ in couplings:
        if follower in joints - actuated and leader in actuated:
            driven[follower] = leader
            own = 1.0 if leader in joints else 0.0
            shares[leader] = shares.get(leader, own) + abs(rho)
    return driven, shares


def coupled_positions(couplings, known: dict) -> dict:
    """Positions of the joints that couplings tie to ``known`` ones.

    ``q_follower = ρ q_leader + Δq`` read both ways, along chains of
    couplings: a leader outside ``known`` (a hidden drive the fingers
    follow) gets ``(q_follower - Δq) / ρ``, a follower ``ρ q_leader + Δq``.
    Setting them makes a pose that the coupler constraints hold.

    Parameters
    ----------
    couplings : sequence of (follower, leader, gear_ratio, offset)
        Scoped joint names (:func:`plant_couplings`).
    known : dict of str to float
        Joint positions (metres or radians) by scoped name.

    Returns
    -------
    dict of str to float
        The positions of the tied joints that are not in ``known`` (the
        first value found where two couplings would give one).
    """
    found = dict(known)
    changed = True
    while changed:
        changed = False
        for follower, leader, rho, offset in couplings:
            if leader in found and follower not in found:
                found[follower] = rho * found[leader] + offset
                changed = True
            elif follower in found and leader not in found and rho != 0:
                found[leader] = (found[follower] - offset) / rho
                changed = True
    return {name: float(q) for name, q in found.items() if name not in known}


def coupled_torque_limits(C: np.ndarray, limits: np.ndarray) -> np.ndarray:
    r"""Limits on the independent coordinates' generalized forces, ``|C|ᵀ τ_max``.

    Parameters
    ----------
    C : (n_h, n_u) float
        The coupling map of :func:`coupling_map` (one nonzero per row).
    limits : (n_h,) float
        Effort limit of the actuator on each hand velocity (N or N·m;
        ``inf`` = none, 0 = passive).

    Returns
    -------
    (n_u,) float
        .. math:: \bar\tau_{\max,i} = \sum_k |C_{ki}|\, \tau_{\max,k}

        the box that ``Cᵀ`` maps the actuators' box onto: a coupled joint's
        actuator adds its effort (times ``|ρ|``) to its leader's.

    Raises
    ------
    InvalidOptionError
        For a ``C`` with a row of more than one nonzero (its image would not
        be a box) or shapes that do not match.
    """
    C = np.asarray(C, dtype=float)
    lim = np.asarray(limits, dtype=float).reshape(-1)
    if C.ndim != 2 or C.shape[0] != lim.size:
        raise InvalidOptionError(
            f"coupling map of shape {C.shape} and {lim.size} effort limits do not "
            "match: one limit per hand velocity"
        )
    if np.any(np.count_nonzero(C, axis=1) > 1):
        raise InvalidOptionError(
            "a hand velocity that follows more than one coordinate: the motors' "
            "limits are no longer a box"
        )
    A = np.abs(C)
    # 0 * inf is 0 here: a velocity that does not move u_i adds nothing to it
    return np.array(
        [
            float(np.sum(lim[A[:, i] > 0.0] * A[A[:, i] > 0.0, i]))
            for i in range(C.shape[1])
        ]
    )


def split_coupled_torque(
    C: np.ndarray, limits: np.ndarray, generalized: np.ndarray
) -> np.ndarray:
    """Actuator efforts ``τ`` with ``Cᵀ τ = generalized``, each within its limit.

    Each coordinate's generalized force is shared among the actuators that
    drive it in proportion to their limits (every one at the same fraction
    of its limit); an actuator without a limit takes all of it.

    Parameters
    ----------
    C : (n_h, n_u) float
    limits : (n_h,) float
    generalized : (n_u,) float
        Generalized forces on the independent coordinates (``(J C)ᵀ f``).

    Returns
    -------
    (n_h,) float
        One effort per hand velocity (N or N·m).
    """
    C = np.asarray(C, dtype=float)
    lim = np.asarray(limits, dtype=float).reshape(-1)
    g = np.asarray(generalized, dtype=float).reshape(-1)
    tau = np.zeros(C.shape[0])
    for i in range(C.shape[1]):
        rows = np.flatnonzero(C[:, i])
        unlimited = [k for k in rows if math.isinf(lim[k])]
        if unlimited:
            k = unlimited[0]
            tau[k] = g[i] / C[k, i]
            continue
        total = float(np.sum(np.abs(C[rows, i]) * lim[rows]))
        if total > 0.0:
            tau[rows] = np.sign(C[rows, i]) * lim[rows] * (g[i] / total)
        elif rows.size:  # passive coordinate: whatever it carries, on its own joint
            k = rows[0]
            tau[k] = g[i] / C[k, i]
    return tau


@dataclass(frozen=True)
class CouplingViolation:
    """A configuration that breaks a coupling ``q_0 = ρ q_1 + Δq``.

    Attributes
    ----------
    follower, leader : str
        Scoped joint names ``model::joint``.
    gear_ratio, offset : float
        ``ρ`` and ``Δq`` (m or rad).
    follower_value, leader_value : float
        ``q_0`` and ``q_1`` in the context (m or rad).
    """

    follower: str
    leader: str
    gear_ratio: float
    offset: float
    follower_value: float
    leader_value: float

    def __str__(self) -> str:
        rho, off = self.gear_ratio, self.offset
        return (
            f"the configuration breaks the coupling {self.follower} = {rho:g} * "
            f"{self.leader} + {off:g}: {self.follower_value:.6g} != {rho:g} * "
            f"{self.leader_value:.6g} + {off:g}"
        )


def recorded_couplings(plant: MultibodyPlant) -> tuple[JointCoupling, ...]:
    """The couplings recorded on the plant (its coupler constraints we know)."""
    return tuple(_RECORDED.get(plant, ()))


def coupling_violations(
    plant: MultibodyPlant,
    plant_context,
    couplings: Sequence,
    *,
    model_instances=None,
    tol: float = COUPLING_TOL,
) -> tuple[CouplingViolation, ...]:
    """The couplings that the plant's configuration breaks.

    Parameters
    ----------
    plant : MultibodyPlant
    plant_context : Context
        The plant's context (positions).
    couplings : sequence of (joint_0, joint_1, gear_ratio, offset)
    model_instances : iterable of ModelInstanceIndex, optional
        Only couplings with a joint in one of these (the hand's) are checked.
    tol : float, optional
        ``|q_0 - (ρ q_1 + Δq)| > tol`` breaks it (default
        :data:`~drakegrasp.core.tolerances.COUPLING_TOL`, close_hand's).

    Returns
    -------
    tuple of CouplingViolation
    """
    keep = None if model_instances is None else {int(m) for m in model_instances}
    found, seen = [], set()
    for entry in coupling_entries(couplings):
        j0, j1, rho, off = coupling_entry(plant, entry)
        key = (int(j0.index()), int(j1.index()), rho, off)
        if key in seen:
            continue
        seen.add(key)
        if keep is not None and not (
            int(j0.model_instance()) in keep or int(j1.model_instance()) in keep
        ):
            continue
        if j0.num_positions() != 1 or j1.num_positions() != 1:
            continue  # coupling_map refuses these where it matters
        q0 = float(j0.GetOnePosition(plant_context))
        q1 = float(j1.GetOnePosition(plant_context))
        if abs(q0 - (rho * q1 + off)) > tol:
            found.append(
                CouplingViolation(
                    _scoped(plant, j0.model_instance(), j0.name()),
                    _scoped(plant, j1.model_instance(), j1.name()),
                    float(rho),
                    float(off),
                    q0,
                    q1,
                )
            )
    return tuple(found)
