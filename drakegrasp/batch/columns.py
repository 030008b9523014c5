"""The columns of a batch result: one list, for results and for files.

A result of ``K`` grasps holds these per-grasp arrays whatever ``K`` is, and a
file written of it holds them as columns: a file of no grasps has the columns
of any other.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = ["result_arrays"]


def result_arrays(K: int, kind: str, metrics: Sequence[str] = ()):
    """The per-grasp arrays of a ``kind`` result, ``K`` rows of their fill values.

    The one list of a result's columns (names, dtypes, per-grasp shapes) in
    the order of :meth:`~drakegrasp.batch.api.BatchClosureResult.to_arrays`:
    ``drakegrasp.batch.api.collect`` fills them, and a writer given no
    grasps (``K = 0``) writes them empty, so a file has the same columns for
    every ``K``.

    Returns
    -------
    (dict of str to (K,) array, dict of str to (K,) array)
        The result arrays (``normal_certificate`` for ``kind="force"`` only)
        and the metrics, NaN until filled.
    """
    out = {
        "is_closure": np.zeros(K, dtype=bool),
        "d_star": np.zeros(K),
        "rank": np.zeros(K, dtype=int),
        "margin": np.zeros(K),
        "converged": np.ones(K, dtype=bool),
    }
    if kind == "force":
        out["normal_certificate"] = np.zeros(K, dtype=bool)
    return out, {name: np.full(K, np.nan) for name in metrics}
