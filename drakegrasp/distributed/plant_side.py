"""The plant layer on a Dask cluster: many configurations of one scene.

:func:`analyze_poses` builds each worker process's scene once, in a
per-process cache keyed by the scene, and ships only joint positions; a plant
is never pickled.  Needs the optional extra ``dask``.
"""

from __future__ import annotations

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.validation import describe, integer_or_none, path_text
from drakegrasp.distributed.client import connected, results_or_cancel
from drakegrasp.errors import GraspError, InvalidOptionError
from drakegrasp.plant.options import AnalysisOptions, checked_options

__all__ = ["analyze_poses", "cached_scenes"]

_SCENES: dict = {}


def _scene(name: str):
    """The worker process's scene ``name``, loaded on first use."""
    if name not in _SCENES:
        from drakegrasp.plant.scene import load_scene

        _SCENES[name] = load_scene(name)
    return _SCENES[name]


@checked_call
def cached_scenes() -> list[str]:
    """Names of the scenes this process has loaded (run on a worker to inspect)."""
    return sorted(_SCENES)


def _analyze_block(
    scene_name: str,
    q_block: np.ndarray,
    options: AnalysisOptions | None,
    overrides: dict,
):
    from drakegrasp.plant.analysis import analyze_grasp

    scene = _scene(scene_name)
    plant, ctx = scene.plant, scene.plant_context
    n_q = plant.num_positions()
    if q_block.shape[1] != n_q:  # Drake would raise SystemExit and kill the task
        raise InvalidOptionError(
            f"positions have {q_block.shape[1]} columns, but scene {scene_name!r} "
            f"has {n_q} positions (its plant's GetPositions order); pass an array "
            f"of shape (P, {n_q})"
        )
    out = {"is_force_closure": np.zeros(len(q_block), dtype=bool),
           "d_star": np.zeros(len(q_block)),
           "num_contacts": np.zeros(len(q_block), dtype=int),
           "error": [""] * len(q_block)}  # fmt: skip
    # the scene's own options are known here only; given options come checked
    analysis = scene.options.replace(**overrides) if options is None else options
    for i, q in enumerate(q_block):
        plant.SetPositions(ctx, q)
        try:
            report = analyze_grasp(
                plant, ctx, scene.object_body, hand=scene.hand, options=analysis
            )
        except GraspError as e:  # a refusal is this row's, not the job's
            out["d_star"][i] = np.nan
            out["error"][i] = f"{type(e).__name__}: {e}"
            continue
        out["is_force_closure"][i] = report.is_force_closure
        out["d_star"][i] = report.force_closure.d_star
        out["num_contacts"][i] = len(report.contacts)
    return out


@checked_call
def analyze_poses(
    client,
    scene: str,
    positions: np.ndarray,
    *,
    block: int = 64,
    options: AnalysisOptions | None = None,
    **overrides,
) -> dict[str, np.ndarray]:
    """:func:`drakegrasp.analyze_grasp` for many plant configurations of a scene.

    Parameters
    ----------
    client : distributed.Client or str
    scene : str
        A shipped scene name or a scene file visible to the workers; each
        worker process loads it once (a per-process cache) and reuses it.
    positions : (P, n_q) float
        Plant positions ``q`` (the scene plant's ``GetPositions`` order).
    block : int, optional
        Configurations per task (an integer >= 1).
    options : AnalysisOptions, optional
        The analysis options, instead of the scene file's (checked once, here,
        and shipped to the workers as they are).
    **overrides
        Changes to the options (e.g. ``mu=0.8``): to ``options`` when given,
        else to each scene's own (read on the worker).

    Returns
    -------
    dict of str to (P,) array
        ``is_force_closure``, ``d_star`` (LP2 of the report's force closure),
        ``num_contacts`` and ``error`` (empty arrays for ``P = 0``).  A
        configuration the analysis refuses (no contact, an impossible pose,
        ...) is a row of its own: not in force closure, ``d_star`` NaN, no
        contacts, and ``error`` the refusal (``"NoContactsError: ..."``); the
        others' ``error`` is ``""``, so one such configuration does not end
        the whole job.

    Raises
    ------
    InvalidOptionError
        A bad option or ``block``; positions that are not a finite (P, n_q)
        array, or whose ``n_q`` is not the scene plant's number of positions.
    """
    if options is not None:
        options, overrides = checked_options(options).replace(**overrides), {}
    else:
        AnalysisOptions().replace(**overrides)  # a bad one fails here, not remotely
    n = integer_or_none(block)
    if n is None or n < 1:
        raise InvalidOptionError(
            "block (configurations per task) must be an integer >= 1, got "
            f"{describe(block)}"
        )
    block = n
    # read here, not on each worker: a str subclass or os.PathLike of the
    # user's own would travel pickled and fail remotely, once per task
    scene = path_text(
        "scene",
        scene,
        must="a shipped scene's name or a scene file's path (a str or an os.PathLike)",
    )
    q = _configurations(positions)
    with connected(client) as client:
        futs = [client.submit(_analyze_block, scene, q[s:s + block], options,
                              overrides, pure=False)
                for s in range(0, len(q), block)]  # fmt: skip
        parts = results_or_cancel(client, futs)
    names = {"is_force_closure": bool, "d_star": float, "num_contacts": int,
             "error": str}  # fmt: skip
    return {
        k: np.concatenate([np.asarray(p[k], dtype) for p in parts])
        if parts
        else np.zeros(0, dtype)
        for k, dtype in names.items()
    }


def _configurations(positions) -> np.ndarray:
    """``positions`` as a finite (P, n_q) float array, or a clear error."""
    try:
        q = np.asarray(positions)
    except (TypeError, ValueError) as err:
        raise InvalidOptionError(
            f"positions must be a (P, n_q) array of plant positions: {err}"
        ) from None
    if q.ndim != 2 or q.dtype.kind not in "iuf":
        raise InvalidOptionError(
            "positions must be a real (P, n_q) array of plant positions, one row "
            f"per configuration; got shape {q.shape} and dtype {q.dtype}"
        )
    q = q.astype(float)
    bad = ~np.isfinite(q).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InvalidOptionError(
            f"configuration {i} is not finite ({q[i].tolist()}); plant positions "
            "must be finite numbers"
        )
    return q
