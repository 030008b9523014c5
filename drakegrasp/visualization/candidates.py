"""Planned grasps as pictures: ghost hands in Meshcat, the score distribution.

:func:`draw_candidates` draws the best ``top`` candidates of a ranked planning
result as translucent copies of the hand, each at its planned pose and finger
opening, coloured by score (:func:`score_colors`: red for the lowest score
drawn, through yellow, to green for the highest), so one look shows where the
good grasps sit on the object.  :func:`plot_score_distribution` draws the
histogram of every candidate's score (matplotlib), force-closure candidates
apart from the others, with the score of the ``top``-th best marked.

Candidates are read by their attributes only (``X_WH``, ``q_hand``,
``joint_names``, ``hand_base``, ``score``, ``is_closure`` and ``apply``, as
:class:`~drakegrasp.planning.candidates.GraspCandidate` has them): this layer
sits inside the planning one and does not import it.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
from pydrake.geometry import Meshcat, Rgba, Role

from drakegrasp.core.calls import checked_call
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.validation import describe, real_array, real_scalar
from drakegrasp.errors import InvalidOptionError
from drakegrasp.plant.fingers import find_joint
from drakegrasp.plant.validation import plant_context_of, resolve_body
from drakegrasp.visualization.certificate_plots import check_axes
from drakegrasp.visualization.plots import import_pyplot
from drakegrasp.visualization.primitives import check_meshcat, check_path

__all__ = [
    "CANDIDATES_PREFIX",
    "MAX_BINS",
    "MAX_CANDIDATES",
    "CandidateDrawing",
    "draw_candidates",
    "plot_score_distribution",
    "score_colors",
]

CANDIDATES_PREFIX = "drakegrasp/candidates"
"""Meshcat path under which :func:`draw_candidates` draws."""

MAX_BINS = 1000
"""Most bins of :func:`plot_score_distribution`: each is two bar patches; 1000
drew in about 1 s, 10**5 took 90 s and 2 GB (and more bins hung)."""

MAX_CANDIDATES = 10**6
"""Most candidates :func:`draw_candidates` and :func:`plot_score_distribution`
take (a planner's result is thousands): an endless iterator is refused, not
listed until memory runs out."""

_STOPS = np.array(
    [[0.85, 0.2, 0.15], [0.95, 0.8, 0.2], [0.2, 0.7, 0.3]]
)  # red, yellow, green


@checked_call
def score_colors(scores, *, alpha: float = 0.4) -> np.ndarray:
    """(K, 4) RGBA colours of scores: red (lowest) → yellow → green (highest).

    Linear in the score between the lowest and the highest of ``scores``; all
    green when they are equal.

    Parameters
    ----------
    scores : array_like of real numbers
        Any shape (flattened), every score finite; may be empty.
    alpha : float, optional
        The opacity, a real number in [0, 1].

    Returns
    -------
    (K, 4) float
        One RGBA row per score, in [0, 1].

    Raises
    ------
    InvalidOptionError
        For scores that are not real numbers (a string, complex, None) or not
        finite, or an ``alpha`` that is not a real number in [0, 1].
    """
    s = real_array("scores", scores, error=InvalidOptionError).reshape(-1)
    a = real_scalar("alpha", alpha)
    if not 0.0 <= a <= 1.0:
        raise InvalidOptionError(f"alpha must be in [0, 1], got {describe(alpha)}")
    if not np.all(np.isfinite(s)):
        raise InvalidOptionError(f"scores must be finite, got {describe(s.tolist())}")
    with np.errstate(over="ignore"):
        span = s.max() - s.min() if len(s) else 0.0
    if not np.isfinite(span):  # scores near ±1.8e308: compare them scaled down
        s = s / np.max(np.abs(s))
        span = s.max() - s.min()
    t = np.ones_like(s) if span <= 0 else (s - s.min()) / span
    x = 2.0 * t  # [0, 2] over the two segments of _STOPS
    k = np.minimum(x.astype(int), 1)
    f = (x - k)[:, None]
    rgb = (1 - f) * _STOPS[k] + f * _STOPS[k + 1]
    return np.column_stack([rgb, np.full(len(s), a)])


@checked_call
@dataclass(frozen=True)
class CandidateDrawing:
    """What :func:`draw_candidates` drew.

    Attributes
    ----------
    paths : tuple of str
        One Meshcat path per drawn candidate, best first.
    scores : (K,) float
        Their scores.
    colors : (K, 4) float
        Their RGBA colours.
    """

    paths: tuple[str, ...]
    scores: np.ndarray
    colors: np.ndarray

    def to_dict(self) -> dict:
        """JSON-ready dictionary."""
        return jsonable(
            {"paths": list(self.paths), "scores": self.scores, "colors": self.colors}
        )

    def __str__(self) -> str:
        if not self.paths:
            return "no candidates drawn"
        return (
            f"{len(self.paths)} ghost hands under {self.paths[0].rsplit('/', 1)[0]}, "
            f"scores {self.scores.max():.4g} (green) to {self.scores.min():.4g} (red)"
        )


def _check_poseable(candidate, k: int) -> None:
    """Refuse a candidate :func:`draw_candidates` cannot pose.

    (Its ``apply`` or Drake's name lookups would raise Python's errors.)
    """
    if not callable(getattr(candidate, "apply", None)):
        raise InvalidOptionError(
            f"candidates[{k}] is a {type(candidate).__name__} without "
            "apply(plant, context), not a GraspCandidate"
        )
    base = getattr(candidate, "hand_base", None)
    names = getattr(candidate, "joint_names", None)
    try:
        named = not isinstance(names, str | bytes) and all(
            isinstance(n, str) for n in names
        )
    except TypeError:  # not iterable
        named = False
    if not (isinstance(base, str) and named):
        raise InvalidOptionError(
            f"candidates[{k}] must name its hand_base 'model::body' and its "
            f"joint_names 'model::joint' as strings, got {describe(base)} and "
            f"{describe(names)}"
        )


def _hand_bodies(plant, candidate, k: int):
    """The bodies of ``candidate``'s hand: its base's and its joints' instances.

    Raises
    ------
    InvalidOptionError
        For a joint name that is not a joint of ``plant``.
    ModelError
        For a ``hand_base`` that is not a body of ``plant``.
    """
    instances = {resolve_body(plant, candidate.hand_base).model_instance()}
    for name in candidate.joint_names:
        try:
            joint = find_joint(plant, name)
        except InvalidOptionError:
            raise InvalidOptionError(
                f"candidates[{k}] names the joint {name!r}, which is not a joint "
                "of the plant (was it planned in another plant?)"
            ) from None
        instances.add(joint.child_body().model_instance())
    return [
        plant.get_body(b) for i in sorted(instances) for b in plant.GetBodyIndices(i)
    ]


@checked_call
def draw_candidates(
    meshcat: Meshcat,
    plant,
    plant_context,
    candidates,
    *,
    top: int = 10,
    alpha: float = 0.4,
    prefix: str = CANDIDATES_PREFIX,
) -> CandidateDrawing:
    """Draw the best ``top`` candidates as ghost hands coloured by score.

    Parameters
    ----------
    meshcat : pydrake.geometry.Meshcat
    plant : MultibodyPlant
        The plant the candidates were planned in.
    plant_context : Context
        Its context (or the diagram's root); read, never changed (the hands
        are posed in a copy).
    candidates : sequence of GraspCandidate
        Ranked best first, e.g. :func:`~drakegrasp.plan_grasps`'s result.
    top : int, optional
        How many to draw (the first ``top``): an integer >= 0.
    alpha : float, optional
        Opacity of the ghosts: a real number in [0, 1] (checked also when no
        candidate is drawn).
    prefix : str, optional
        Meshcat path, non-empty (not ``""`` or ``"/"``, which would delete
        the whole scene); what was under it is deleted first.

    Returns
    -------
    CandidateDrawing
        Candidate ``k`` is under ``{prefix}/{k}``, each hand body under
        ``{prefix}/{k}/{body}`` at its pose ``X_WB`` (world frame).

    Raises
    ------
    InvalidOptionError
        For a ``meshcat`` that is not a Meshcat, a bad ``top``, ``alpha`` or
        ``prefix``, ``candidates`` that are not planned grasps (a real
        ``score``, a boolean ``is_closure``, an ``apply`` method, string
        ``hand_base`` and ``joint_names``), or a candidate that names a joint
        the plant does not have.
    InvalidGraspError
        For a drawn candidate Drake cannot be given (a NaN ``q_hand``, a pose
        that is not a rigid transform: see its ``apply``).
    ModelError, InvalidContextError
        For a plant that is not a finalized MultibodyPlant, a context of
        another system, or a ``hand_base`` that is not a body of the plant.
        Every candidate drawn is posed (in a scratch context) before anything
        is deleted or drawn, so a bad one leaves the previous drawing as it
        was.
    """
    check_meshcat(meshcat)
    prefix = check_path("prefix", prefix)
    if isinstance(top, bool) or not isinstance(top, int | np.integer) or top < 0:
        raise InvalidOptionError(f"top must be an integer >= 0, got {describe(top)}")
    ctx = plant_context_of(plant, plant_context)
    inspector = plant.get_geometry_query_input_port().Eval(ctx).inspector()
    scratch = plant.CreateDefaultContext()  # a copy of the user's configuration
    plant.SetPositions(scratch, plant.GetPositions(ctx))
    shown = _candidate_rows(candidates)[: int(top)]
    scores = np.array([float(c.score) for c in shown])
    colors = score_colors(scores, alpha=alpha)  # (0, 4) when none is shown
    posed = []  # per candidate, (body, X_WB) of each hand body
    for k, c in enumerate(shown):
        _check_poseable(c, k)
        c.apply(plant, scratch)
        bodies = _hand_bodies(plant, c, k)
        posed.append([(b, plant.EvalBodyPoseInWorld(scratch, b)) for b in bodies])
    meshcat.Delete(prefix)
    paths = []
    for k, (bodies, rgba) in enumerate(zip(posed, colors, strict=True)):
        color = Rgba(*rgba)
        path = f"{prefix}/{k}"
        for body, X_WB in bodies:
            frame = plant.GetBodyFrameIdOrThrow(body.index())
            geoms = inspector.GetGeometries(frame, Role.kIllustration)
            geoms = geoms or inspector.GetGeometries(frame, Role.kProximity)
            body_path = f"{path}/{body.name()}"
            for n, g in enumerate(geoms):
                meshcat.SetObject(f"{body_path}/g{n}", inspector.GetShape(g), color)
                meshcat.SetTransform(f"{body_path}/g{n}", inspector.GetPoseInFrame(g))
            meshcat.SetTransform(body_path, X_WB)
        paths.append(path)
    return CandidateDrawing(tuple(paths), scores, colors)


def _candidate_rows(candidates) -> list:
    """``candidates`` as a list of planned grasps, or a clear error.

    Each item needs a real ``score`` and a boolean ``is_closure``, as
    :class:`~drakegrasp.planning.candidates.GraspCandidate` has (duck-typed:
    the planner's layer sits above this one).
    """
    try:
        # An endless iterator is cut at one past the bound, not listed forever.
        rows = list(itertools.islice(candidates, MAX_CANDIDATES + 1))
    except Exception:  # noqa: BLE001 - not iterable, or a hostile __iter__
        rows = None
    if rows is None or isinstance(candidates, str | bytes):
        raise InvalidOptionError(
            "candidates must be a sequence of GraspCandidate (plan_grasps's result), "
            f"got {type(candidates).__name__}"
        )
    if len(rows) > MAX_CANDIDATES:
        raise InvalidOptionError(
            f"candidates holds more than MAX_CANDIDATES = {MAX_CANDIDATES:,} grasps "
            "(or never ends); draw a selection, e.g. candidates[:100]"
        )
    for i, c in enumerate(rows):
        score = getattr(c, "score", None)
        if (
            isinstance(score, bool)
            or not isinstance(score, int | float | np.integer | np.floating)
            or not isinstance(getattr(c, "is_closure", None), bool | np.bool_)
        ):
            raise InvalidOptionError(
                f"candidates[{i}] is a {type(c).__name__}, not a GraspCandidate "
                "(it needs a real score and a boolean is_closure)"
            )
    return rows


def _bin_edges(scores: np.ndarray, bins: int) -> np.ndarray:
    """``bins + 1`` increasing, finite edges over ``scores`` (numpy's if it can)."""
    with np.errstate(over="ignore", invalid="ignore"):  # checked below
        try:
            return np.histogram_bin_edges(
                scores if len(scores) else [0.0, 1.0], bins=bins
            )
        except ValueError:  # scores a few ulps apart: too narrow for `bins` bins
            lo, hi = float(scores.min()), float(scores.max())
            pad = 4 * bins * float(np.spacing(max(abs(lo), abs(hi))))
            edges = np.linspace(lo - pad, hi + pad, bins + 1)
    if not (np.all(np.isfinite(edges)) and np.all(np.diff(edges) > 0)):
        raise InvalidOptionError(
            f"the candidates' scores, from {lo!r} to {hi!r}, cannot be split into "
            f"{bins} finite bins (their span is beyond the floating-point range)"
        )
    return edges


@checked_call
def plot_score_distribution(candidates, *, ax=None, bins: int = 30, top: int = 10):
    """Histogram of the candidates' scores (matplotlib).

    Force-closure candidates and the others are stacked in two colours; a
    dashed line marks the score of the ``top``-th best candidate (the cut of
    :func:`draw_candidates`).

    Parameters
    ----------
    candidates : sequence of GraspCandidate
        Each with a finite real ``score`` and a boolean ``is_closure``.
    ax : matplotlib Axes, optional
        A 2-D axes (``plt.subplots()``; not a polar or 3-D one).  Default: a
        new figure's.
    bins : int, optional
        An integer in ``[1, MAX_BINS]`` = [1, 1000] (:data:`MAX_BINS`).
    top : int, optional
        An integer >= 0.

    Returns
    -------
    matplotlib.axes.Axes

    Raises
    ------
    InvalidOptionError
        For ``candidates`` that are not planned grasps or have a NaN or
        infinite score (or scores whose span overflows), a ``bins`` or ``top``
        out of range, or an ``ax`` that is not a 2-D matplotlib axes.  Nothing
        is drawn then.
    """
    plt = import_pyplot()
    if (
        isinstance(bins, bool)
        or not isinstance(bins, int | np.integer)
        or not 1 <= bins <= MAX_BINS
    ):
        raise InvalidOptionError(
            f"bins must be an integer >= 1 and <= {MAX_BINS} "
            f"(drakegrasp.visualization.candidates.MAX_BINS), got {describe(bins)}"
        )
    if isinstance(top, bool) or not isinstance(top, int | np.integer) or top < 0:
        raise InvalidOptionError(f"top must be an integer >= 0, got {describe(top)}")
    rows = _candidate_rows(candidates)
    scores = np.array([float(c.score) for c in rows])
    if not np.all(np.isfinite(scores)):
        raise InvalidOptionError(
            f"every candidate's score must be finite, got {describe(scores.tolist())}"
        )
    closure = np.array([bool(c.is_closure) for c in rows], dtype=bool)
    edges = _bin_edges(scores, int(bins))
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 3.5))
    else:
        check_axes(ax, "rectilinear")
    ax.hist(
        [scores[closure], scores[~closure]],
        bins=edges,
        stacked=True,
        color=["tab:green", "tab:gray"],
        label=["force closure", "not force closure"],
    )
    if len(rows) and top > 0:
        cut = np.sort(scores)[::-1][min(top, len(scores)) - 1]
        ax.axvline(cut, color="k", linestyle="--", label=f"top {min(top, len(rows))}")
    ax.set_xlabel("score (robustness × weight capacity)")
    ax.set_ylabel("candidates")
    ax.set_title(f"{len(rows)} candidates")
    ax.legend(loc="upper right")
    return ax
