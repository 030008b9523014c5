"""``evaluate_on_cluster``'s ``kind`` is named with describe(), as the engine's.

A ``kind`` whose ``repr`` raises leaked that exception (``RuntimeError``)
instead of the ``InvalidOptionError`` that names the valid kinds; the local
engine (``iter_batch_closure``) already read it with describe().  Refused
before any client is used.
"""

from __future__ import annotations

import numpy as np
import pytest

from drakegrasp.errors import InvalidOptionError

pytest.importorskip("distributed", reason="dask is an optional extra")

from drakegrasp.distributed import evaluate_on_cluster  # noqa: E402


class _Raises:
    def __repr__(self):
        raise RuntimeError("repr")


class _Huge(str):
    def __repr__(self):
        return "x" * 10**6


@pytest.mark.parametrize("kind", [_Raises(), _Huge("forcee")])
def test_a_hostile_kind_is_refused_by_name(kind):
    P = np.zeros((1, 3, 3))
    with pytest.raises(InvalidOptionError, match="kind must be 'force' or 'form'") as e:
        evaluate_on_cluster(None, P, P, mu=0.5, kind=kind)
    assert len(str(e.value)) < 300
