"""Hostile arguments to the planning stages: a GraspError naming the argument.

The planning stages below the planner (:func:`weight_capacity`,
:func:`fan_capacity`, :func:`robustness`, :func:`perturbed_copies`,
:func:`reclosed_robustness`, :func:`sample_poses`) take arrays and options
straight from a caller.  Each bad value must raise a
:class:`drakegrasp.GraspError` whose message names the argument, before any
LP or draw: never a raw ``TypeError``/``ValueError``/``AxisError``, a NaN
``mu`` reaching Drake (which aborted the interpreter), nor a silent answer
(a negative ``mu`` gave the capacity of ``|mu|``, ``tol=nan`` a robustness
of 0).
Valid calls keep their numbers (recorded before the checks were added).

Everything here is numpy and small LPs: no plant, no simulation.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from grasp_builders import two_pads
from pydrake.geometry import Box
from pydrake.math import RigidTransform

import drakegrasp as dg
from drakegrasp.planning import (
    checks,
    motors,
    opposition,
    planner,
    ranking,
    reclose,
    weight,
)
from drakegrasp.planning.gripper import ParallelJaw
from drakegrasp.planning.placement import sample_poses
from drakegrasp.planning.planner import plan_grasps
from drakegrasp.planning.ranking import perturbed_copies, robustness, verdicts
from drakegrasp.planning.reclose import reclosed_robustness
from drakegrasp.planning.surface import ObjectSurface, piece_of_shape
from drakegrasp.planning.weight import WEIGHT_DIRECTIONS, fan_capacity, weight_capacity

NOISE = {"position": 4e-3, "angle_deg": 8.0, "friction": 0.3}

# Shared hostile pools: each value is refused wherever the argument is taken.
BAD_MU = [
    -0.5,
    -1e-30,
    np.nan,
    np.inf,
    -np.inf,
    1e13,
    1e-13,
    True,
    "0.5",
    [0.5],
    None,
    np.array([0.5, 0.5]),
    0.5 + 0.1j,
]
BAD_COUNT = [-1, 2.5, 4.0, True, "4", None, [4]]
# copies whose points exceed checks.MAX_COPY_BYTES: a MemoryError before the cap
BAD_SAMPLES = [*BAD_COUNT, 10**12, 2**40]


class _Opaque:
    """An object of no type the API takes, with a repr that names no address
    (so every pytest-xdist worker collects the same test ids)."""

    def __repr__(self) -> str:
        return "<an object>"


BAD_RNG = [None, 0, "seed", _Opaque()]
BAD_SIGMA = [-1e-3, np.nan, np.inf, "0.1", None, True]
BAD_LENGTH = [0.0, -1e-4, np.nan, np.inf, "1e-4", None, True]


def _box_grasp():
    """Four contacts on a 6 cm cube's faces ±x, ±y, one finger each (closure)."""
    P = np.array(
        [[0.03, 0.01, 0.0], [-0.03, -0.01, 0.0], [0.0, 0.03, 0.01], [0.0, -0.03, -0.01]]
    )
    N = -np.array([[1.0, 0, 0], [-1.0, 0, 0], [0, 1.0, 0], [0, -1.0, 0]])
    return P[None], N[None], np.arange(4)[None]


def _pads(K=3, half=2, seed=8000):
    """``K`` grasps of two pads of ``half`` contacts each across x = ±0.03."""
    return two_pads(np.random.default_rng(seed), K, half)


def _box_surface():
    return ObjectSurface.from_pieces(
        [piece_of_shape(Box(0.06, 0.1, 0.2), RigidTransform(), "o")]
    )


def _jaw():
    """A parallel jaw of stroke [0, 0.1] m: all that sample_poses reads."""
    return ParallelJaw(
        base=None,
        joints=(None, None),
        finger_bodies=((), ()),
        position_indices=np.array([0, 1]),
        lower=np.zeros(2),
        upper=np.full(2, 0.05),
        X_HK=RigidTransform(),
        pad_at_zero=np.array([-0.05, 0.05]),
        pad_rate=np.array([1.0, -1.0]),
        pad_geometries=((), ()),
        min_opening=0.0,
        max_opening=0.1,
    )


def _refused_up_front(call, name, kwargs, monkeypatch, *backends):
    """``call()`` raises a GraspError naming ``name`` before any draw or LP.

    ``backends`` are ``(module, attribute)`` of the computation behind the
    stage (the LPs, the copies): each is replaced by a tripwire, so an error
    raised from inside them (a perturbed copy's μ, a chunk's normal) fails the
    test as it does without the checks.  ``kwargs["rng"]``, when given and not
    the bad value, must come out undrawn.
    """

    def tripwire(*args, **kwargs):
        raise AssertionError(f"{name}: the bad value reached the computation")

    for module, attribute in backends:
        monkeypatch.setattr(module, attribute, tripwire)
    rng = kwargs.get("rng") if name != "rng" else None
    state = rng.bit_generator.state if rng is not None else None
    with pytest.raises(dg.GraspError, match=name):
        call()
    if rng is not None:
        assert rng.bit_generator.state == state, f"{name}: rng drawn before the check"


def _stage_refuses(stage, build, name, value, monkeypatch, *backends):
    """``stage`` with ``build(name=value)``'s arguments: :func:`_refused_up_front`."""
    args, kwargs = build(**{name: value})
    call = functools.partial(stage, *args, **kwargs)
    _refused_up_front(call, name, kwargs, monkeypatch, *backends)


def _split(args, change, positional):
    """``(positional values, keyword arguments)``: ``args`` updated by ``change``."""
    args = {**args, **change}
    return [args.pop(k) for k in positional], args


def _cases(name, values):
    """``(name, value)`` parameters, with short one-line ids."""
    return [
        pytest.param(name, v, id=f"{name}{i}=" + " ".join(repr(v).split())[:40])
        for i, v in enumerate(values)
    ]


# ---------------------------------------------------------------- weight_capacity

P_BOX, N_BOX, L_BOX = _box_grasp()

WEIGHT_BAD = (
    _cases("mu", BAD_MU)
    + _cases("torque_scale", [*BAD_LENGTH, 1e9, 1e-300])  # out of scale: 0.03 m
    + _cases("torsional_friction", [-0.1, np.nan, "0.1", True, [0.1]])
    + _cases("contact_model", ["finger", None, 3])
    + _cases(
        "directions",
        [
            np.zeros((2, 3)),
            [[np.nan, 0, 0]],
            [1.0, 0, 0],
            np.zeros((0, 3)),
            "up",
            [[1.0, 0]],
        ],
    )
    + _cases("num_generators", [2, 1000, 8.5, True, "8"])
    + _cases(
        "positions", [P_BOX[0], P_BOX * np.nan, "abc", None, P_BOX[..., :2], P_BOX * 1j]
    )
    + _cases("normals", [N_BOX * 0.0, N_BOX * np.nan, N_BOX[:, :3], None])
    + _cases(
        "fingers",
        [L_BOX[0], -L_BOX, L_BOX + 0.5, L_BOX * np.nan, L_BOX > 1, L_BOX * 10**9, "0"],
    )
    + _cases("solver", [None, ["batch"], np.array(["batch", "drake"])])
    + _cases("workers", [0, -1, True, 1.5, "2"])
    + _cases("palm", [-1, 64, 2.5, True, "2", np.nan, [2]])
)


def _weight_args(**change):
    args = dict(
        positions=P_BOX, normals=N_BOX, fingers=L_BOX, mu=0.5, torque_scale=0.05
    )
    return _split(args, change, ("positions", "normals", "fingers"))


@pytest.mark.parametrize(("name", "value"), WEIGHT_BAD)
def test_weight_capacity_names_a_bad_argument(name, value, monkeypatch):
    _stage_refuses(
        weight_capacity, _weight_args, name, value, monkeypatch, (weight, "_capacity")
    )


def test_weight_capacity_soft_finger_needs_torsional_friction():
    args, kwargs = _weight_args(contact_model="soft_finger")
    with pytest.raises(dg.GraspError, match="torsional_friction"):
        weight_capacity(*args, **kwargs)


def test_weight_capacity_is_refused_for_bad_arguments_of_no_grasp_too():
    # K = 0 returned before any check: a bad option is still an error
    empty = (np.zeros((0, 4, 3)), np.zeros((0, 4, 3)), np.zeros((0, 4), int))
    assert weight_capacity(*empty, mu=0.5, torque_scale=0.05).shape == (0, 14)
    with pytest.raises(dg.GraspError, match="mu"):
        weight_capacity(*empty, mu=-1.0, torque_scale=0.05)


def test_weight_capacity_keeps_its_numbers_and_grows_with_mu():
    # recorded before the checks: the box grasp at mu = 0.5
    a = weight_capacity(P_BOX, N_BOX, L_BOX, mu=0.5, torque_scale=0.05)
    assert a.shape == (1, len(WEIGHT_DIRECTIONS)) and np.all(np.isfinite(a))
    assert a.min() == pytest.approx(1.014293594568831, rel=1e-12)
    # more friction never holds less, and a negative mu is no "more" (it gave
    # the capacity of |mu| before)
    mus = [0.0, 0.1, 0.3, 0.5, 1.0, 2.0, 10.0]
    worst = [
        weight_capacity(P_BOX, N_BOX, L_BOX, mu=m, torque_scale=0.05).min() for m in mus
    ]
    assert np.all(np.diff(worst) >= -1e-9) and worst[-1] > worst[3] > 0
    with pytest.raises(dg.GraspError, match="mu"):
        weight_capacity(P_BOX, N_BOX, L_BOX, mu=-0.5, torque_scale=0.05)


def test_weight_capacity_normalises_normals_and_directions():
    # a non-unit normal gave a larger capacity (1.40 for 1.01), and the batch
    # and Drake routes disagreed on a non-unit direction (α |u| and α / |u|)
    base = weight_capacity(P_BOX, N_BOX, L_BOX, mu=0.5, torque_scale=0.05)
    scaled = weight_capacity(P_BOX, 3.0 * N_BOX, L_BOX, mu=0.5, torque_scale=0.05)
    np.testing.assert_allclose(scaled, base, rtol=1e-12)
    dirs = np.array([[1.0, 0, 0], [0, 0, -1.0]])
    unit = weight_capacity(
        P_BOX, N_BOX, L_BOX, mu=0.5, torque_scale=0.05, directions=dirs
    )
    for solver in ("batch", "drake"):
        got = weight_capacity(
            P_BOX,
            N_BOX,
            L_BOX,
            mu=0.5,
            torque_scale=0.05,
            directions=dirs * [[2.0], [3.0]],
            solver=solver,
        )
        np.testing.assert_allclose(got, unit, rtol=1e-7)
    # integral float labels are the integer labels
    as_float = weight_capacity(P_BOX, N_BOX, L_BOX * 1.0, mu=0.5, torque_scale=0.05)
    np.testing.assert_array_equal(as_float, base)


def test_a_huge_torque_scale_is_refused_not_answered_wrong():
    # moments divided by 1e10 m fell below the LPs' resolution: 1.81 for 1.01
    with pytest.raises(dg.GraspError, match="torque_scale"):
        weight_capacity(P_BOX, N_BOX, L_BOX, mu=0.5, torque_scale=1e10)
    # the capacity does not depend on torque_scale within the range
    a = weight_capacity(P_BOX, N_BOX, L_BOX, mu=0.5, torque_scale=0.05)
    b = weight_capacity(P_BOX, N_BOX, L_BOX, mu=0.5, torque_scale=100.0)
    np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-12)


# ------------------------------------------------------------------- fan_capacity

FANS = np.full((1, 4, 2, 3), np.nan)
FANS[0, 0] = [[-1.0, 0, 0], [0, 0, -1.0]]
P_EDGE = P_BOX.copy()
P_EDGE[0, 0] = [0.03, 0.01, 0.03]

_partial = FANS.copy()
_partial[0, 1, 0, 0] = 1.0  # one number of a fan that is otherwise NaN
_zero_end = FANS.copy()
_zero_end[0, 0, 1] = 0.0

FAN_BAD = (
    _cases("mu", BAD_MU)
    + _cases("samples", BAD_SAMPLES)
    + _cases("rng", BAD_RNG)
    + _cases("torque_scale", [*BAD_LENGTH, 1e9, 1e-300])  # out of scale, undrawn
    + _cases("fans", [_partial, _zero_end, FANS[0], "fan", None])
    + _cases("fingers", [L_BOX[0], -L_BOX])
    + _cases("positions", [P_EDGE[0], P_EDGE + np.inf])
    + _cases("contact_model", ["finger"])
    + _cases("torsional_friction", [-1.0, np.nan])
    + _cases("palm", [-2, True, "1"])
)


def _fan_args(**change):
    args = dict(
        positions=P_EDGE,
        normals=N_BOX,
        fans=FANS,
        fingers=L_BOX,
        mu=0.8,
        samples=6,
        rng=np.random.default_rng(3),
        torque_scale=0.05,
        contact_model="hard_finger",
        torsional_friction=None,
    )
    return _split(args, change, ("positions", "normals", "fans", "fingers"))


@pytest.mark.parametrize(("name", "value"), FAN_BAD)
def test_fan_capacity_names_a_bad_argument(name, value, monkeypatch):
    _stage_refuses(
        fan_capacity, _fan_args, name, value, monkeypatch,
        (weight, "weight_capacity"),
    )  # fmt: skip


def test_fan_capacity_keeps_its_numbers():
    args, kwargs = _fan_args()
    got = fan_capacity(*args, **kwargs)
    # recorded before the checks (the drawn normals are now normalised: ulps)
    assert got[0] == pytest.approx(1.2652667684613446, rel=1e-12)
    args, kwargs = _fan_args(samples=0, rng=np.random.default_rng(0))
    nominal = weight_capacity(P_EDGE, N_BOX, L_BOX, mu=0.8, torque_scale=0.05)
    assert fan_capacity(*args, **kwargs)[0] == pytest.approx(nominal.min())


# ------------------------------------------------------ perturbed_copies, robustness

P_PADS, N_PADS, F_PADS = _pads()

COPIES_BAD = (
    _cases("mu", BAD_MU)
    + _cases("samples", BAD_SAMPLES)
    + _cases("rng", BAD_RNG)
    + _cases("position", BAD_SIGMA)
    + _cases("angle_deg", BAD_SIGMA)
    + _cases("friction", BAD_SIGMA)
    + _cases(
        "groups",
        ["01", 5, [0.5], [None], [-5, 99], [64], [0, 0], (1, 0, 1), [np.int64(-1)]],
    )
    + _cases("positions", [P_PADS[0], P_PADS * np.nan, None])
    + _cases("normals", [N_PADS * 0.0, N_PADS[:, :1]])
    + _cases("fingers", [F_PADS[0], F_PADS - 1, F_PADS + 0.5, F_PADS > 0])
)


def _copies_args(**change):
    args = dict(
        positions=P_PADS,
        normals=N_PADS,
        fingers=F_PADS,
        mu=0.5,
        samples=4,
        rng=np.random.default_rng(7),
        **NOISE,
    )
    return _split(args, change, ("positions", "normals", "fingers"))


@pytest.mark.parametrize(("name", "value"), COPIES_BAD)
def test_perturbed_copies_names_a_bad_argument(name, value, monkeypatch):
    _stage_refuses(perturbed_copies, _copies_args, name, value, monkeypatch)


ROBUST_BAD = (
    _cases("mu", BAD_MU)
    + _cases("samples", BAD_SAMPLES)
    + _cases("rng", BAD_RNG)
    + _cases(
        "noise",
        [
            None,
            {},
            "noise",
            {**NOISE, "extra": 1.0},
            {"position": 1e-3, "angle_deg": 1.0},
        ],
    )
    + _cases("position", [-1e-3, np.nan])  # noise["position"]
    + _cases("angle_deg", [np.inf, "3"])  # noise["angle_deg"]
    + _cases("friction", [-0.1, None])  # noise["friction"]
    + _cases("contact_model", ["finger", None])
    + _cases("torsional_friction", [-0.1, np.nan, "0.05"])
    + _cases("workers", [0, True, "1"])
    + _cases("groups", ["01", 5, [-5, 99], [0, 0]])
    + _cases("fingers", [F_PADS[0], F_PADS - 1])
    + _cases("normals", [N_PADS * np.nan])
)


def _robust_args(**change):
    noise = dict(NOISE)
    for key in list(change):
        if key in NOISE:
            noise[key] = change.pop(key)
    args = dict(
        positions=P_PADS,
        normals=N_PADS,
        fingers=F_PADS,
        mu=0.5,
        samples=8,
        rng=np.random.default_rng(7),
        noise=noise,
        contact_model="hard_finger",
        torsional_friction=None,
        workers=1,
    )
    return _split(args, change, ("positions", "normals", "fingers"))


@pytest.mark.parametrize(("name", "value"), ROBUST_BAD)
def test_robustness_names_a_bad_argument(name, value, monkeypatch):
    _stage_refuses(
        robustness, _robust_args, name, value, monkeypatch,
        (ranking, "perturbed_copies"), (ranking, "force_verdicts"),
    )  # fmt: skip


def test_robustness_names_the_users_mu_not_a_perturbed_copy():
    # the batch engine used to refuse the first copy: "mu of grasp 0 is -0.87..."
    args, kwargs = _robust_args(mu=-1.0)
    with pytest.raises(dg.GraspError, match=r"^mu must be .*got -1\.0$"):
        robustness(*args, **kwargs)


@pytest.mark.parametrize("mu", [1e-12, 1e12])
def test_robustness_takes_a_mu_at_either_bound(mu):
    # a copy's mu = mu (1 + σ ξ) left the valid range and was refused
    args, kwargs = _robust_args(mu=mu, samples=16)
    rho = robustness(*args, **kwargs)
    assert rho.shape == (3,) and np.all((rho >= 0) & (rho <= 1))


def test_robustness_and_copies_keep_their_numbers():
    args, kwargs = _robust_args(samples=16)
    rho = robustness(*args, **kwargs)
    # recorded before the checks (the same seed)
    np.testing.assert_array_equal(rho, [0.9375, 1.0, 0.5625])
    args, kwargs = _copies_args()
    P, Nrm, mus = perturbed_copies(*args, **kwargs)
    assert P.shape == Nrm.shape == (12, 4, 3) and mus.shape == (12,)
    assert P.sum() == pytest.approx(-0.009072059807729294, rel=1e-9)
    assert mus[:3] == pytest.approx(
        [0.4964834122167733, 0.5107162766438909, 0.38715327913316167], rel=1e-12
    )
    np.testing.assert_allclose(np.linalg.norm(Nrm, axis=2), 1.0)
    args, kwargs = _robust_args(samples=0)
    np.testing.assert_array_equal(robustness(*args, **kwargs), np.zeros(3))


def test_empty_groups_move_no_contact_and_perturb_mu_only():
    # no finger moves: the copies keep the contacts; only their mu is drawn
    args, kwargs = _copies_args(groups=())
    P, Nrm, mus = perturbed_copies(*args, **kwargs)
    np.testing.assert_array_equal(P, np.repeat(P_PADS, 4, axis=0))
    np.testing.assert_array_equal(Nrm, np.repeat(N_PADS, 4, axis=0))
    xi = np.random.default_rng(7).standard_normal(12)
    np.testing.assert_array_equal(mus, 0.5 * np.maximum(0.0, 1.0 + 0.3 * xi))


def test_the_copies_bound_is_exact_and_far_above_the_planners_use():
    K, N = 3, 4
    most = checks.MAX_COPY_BYTES // (K * N * 3 * 8)
    assert checks.checked_samples(most, K, N) == most
    with pytest.raises(dg.InvalidOptionError, match=r"^samples = .*MAX_COPY_BYTES"):
        checks.checked_samples(most + 1, K, N)
    assert checks.checked_samples(10**15, 0, N) == 10**15  # no grasp: no copies
    # 1,500 poses, the default 32 copies, 20 contacts: 23 times below the bound
    assert 1500 * 32 * 20 * 24 * 23 < checks.MAX_COPY_BYTES


@pytest.mark.parametrize(("name", "value"), _cases("torque_scale", BAD_LENGTH))
def test_verdicts_name_a_bad_torque_scale(name, value):
    # it reached batch_epsilon_l1 as characteristic_lengths (or nothing at all
    # when no grasp closed)
    with pytest.raises(dg.GraspError, match=name):
        verdicts(
            P_BOX, N_BOX, mu=0.5, torque_scale=value, contact_model="hard_finger",
            torsional_friction=None, workers=1,
        )  # fmt: skip


# ------------------------------------------------------------ reclosed_robustness

BOX = _box_surface()
P_RE, _, F_RE = _pads(K=3, half=3, seed=8100)
AXES = np.tile([1.0, 0, 0], (3, 1))

RECLOSE_BAD = (
    _cases("mu", BAD_MU)
    + _cases("samples", BAD_SAMPLES)
    + _cases("rng", BAD_RNG)
    + _cases("tol", BAD_LENGTH)
    + _cases("position", BAD_SIGMA)
    + _cases("angle_deg", BAD_SIGMA)
    + _cases("friction", BAD_SIGMA)
    + _cases("axes", [np.zeros((3, 3)), AXES * np.nan, AXES[:2], AXES[0], "x"])
    + _cases("reference", [[np.nan, 0, 0], [0.0, 0.0], "o"])
    + _cases("surface", [None, "box"])
    + _cases("fingers", [F_RE[0], F_RE - 1])
    + _cases("positions", [P_RE[0], P_RE * np.nan])
    + _cases("contact_model", ["finger"])
    + _cases("torsional_friction", [np.nan])
    + _cases("workers", [0])
)


def _reclose_args(**change):
    args = dict(
        surface=BOX,
        positions=P_RE,
        fingers=F_RE,
        axes=AXES,
        mu=0.6,
        samples=16,
        rng=np.random.default_rng(2),
        position=3e-3,
        angle_deg=5.0,
        friction=0.3,
        tol=1e-4,
        contact_model="hard_finger",
        torsional_friction=None,
        workers=1,
    )
    return _split(args, change, ("surface", "positions", "fingers", "axes"))


@pytest.mark.parametrize(("name", "value"), RECLOSE_BAD)
def test_reclosed_robustness_names_a_bad_argument(name, value, monkeypatch):
    _stage_refuses(
        reclosed_robustness, _reclose_args, name, value, monkeypatch,
        (reclose, "reclosed_copies"), (reclose, "force_verdicts"),
    )  # fmt: skip


def test_reclosed_robustness_keeps_its_numbers():
    args, kwargs = _reclose_args()
    rho = reclosed_robustness(*args, **kwargs)
    # recorded before the checks (tol=nan gave [0, 0, 0] without a word)
    np.testing.assert_array_equal(rho, [1.0, 1.0, 0.9375])
    args, kwargs = _reclose_args(mu=1e-12)  # copies' mu below the range: kept
    assert np.all(reclosed_robustness(*args, **kwargs) >= 0)


# --------------------------------------------------------------------- sample_poses

POSES_BAD = (
    _cases("mu", BAD_MU)
    + _cases("n", BAD_COUNT)
    + _cases("rng", BAD_RNG)
    + _cases("clearance", BAD_SIGMA)
    + _cases("tol", BAD_LENGTH)
    + _cases("surface", [None, "box"])
    + _cases("gripper", [None, "wsg"])
    + _cases("X_WO", [None, np.eye(4)])
)


def _poses_args(**change):
    args = dict(
        surface=BOX,
        gripper=_jaw(),
        X_WO=RigidTransform(),
        n=60,
        mu=0.5,
        clearance=5e-3,
        rng=np.random.default_rng(3),
        tol=1e-4,
    )
    return _split(args, change, ("surface", "gripper", "X_WO", "n"))


@pytest.mark.parametrize(("name", "value"), POSES_BAD)
def test_sample_poses_names_a_bad_argument(name, value, monkeypatch):
    _stage_refuses(sample_poses, _poses_args, name, value, monkeypatch)


def test_sample_poses_keeps_its_numbers():
    args, kwargs = _poses_args()
    poses, rejections = sample_poses(*args, **kwargs)
    # recorded before the checks (the same seed)
    assert len(poses["sample"]) + sum(rejections.values()) == 60
    assert len(poses["sample"]) == 53 and rejections == {"wider than the stroke": 7}
    assert float(poses["opening"].sum()) == pytest.approx(4.37, rel=1e-12)
    assert float(poses["p_WH"].sum()) == pytest.approx(0.5884382116538976, rel=1e-9)
    args, kwargs = _poses_args(n=0)
    poses, rejections = sample_poses(*args, **kwargs)
    assert len(poses["sample"]) == 0 and not rejections


# -------------------------------------------------------------- plan_grasps options

PLAN_BAD = (
    _cases("robustness_samples", [10**12, checks.MAX_COPY_BYTES // 48 + 1, -1, True])
    + _cases("torsional_friction", [-0.1, np.nan, "0.1", True, [0.1]])
    + _cases("clearance", BAD_SIGMA)
    + _cases("seed", [-1, 1.5, "1", True])
    + _cases("certify", BAD_COUNT)
    + _cases("weight_check", [-1, 2.5, True, "3"])
    + _cases("min_fingers", [1, 0, 2.0, True])
    + _cases(
        "noise",
        [{"wobble": 1}, {"position": -1.0}, {"angle_deg": np.nan}, "loud", 3],
    )
)


def _plan_args(**change):
    """No plant, object or hand: every option is checked before they are read."""
    args = dict(plant=None, plant_context=None, object_body=None, hand=None)
    args.update(num_candidates=4, mu=0.5)
    return _split(args, change, ("plant", "plant_context", "object_body"))


@pytest.mark.parametrize(("name", "value"), PLAN_BAD)
def test_plan_grasps_names_a_bad_option_before_reading_the_plant(
    name, value, monkeypatch
):
    # robustness_samples = 10**12 and torsional_friction = nan were taken: the
    # first ended in a MemoryError once the candidates were closed, the second
    # was refused by the ranking, or never when no candidate closed
    _stage_refuses(
        plan_grasps, _plan_args, name, value, monkeypatch,
        (planner, "plant_context_of"),
    )  # fmt: skip


# ---------------------------------------------------------- the squeeze push


def _opposition_cases():
    """``(call, bad argument)``: every bad value must be named, never answered."""
    J, F = np.eye(3), np.eye(3)[None]
    calls = {
        "closing_directions": lambda **k: opposition.closing_directions(
            **{"J": J, "frames": F, "components": [3], "signs": [1.0, 1.0, 1.0], **k}
        ),
        "squeeze_push_of": lambda directions: opposition.squeeze_push_of(directions),
        "push_text": lambda push: opposition.push_text(push),
    }
    bad = {
        ("closing_directions", "J"): [J * np.nan, "J", None, J[0], J * 1j],
        ("closing_directions", "frames"): [F * 0.0, F * 2.0, F * np.nan, F[0], "O"],
        ("closing_directions", "components"): [["a"], None, 3, [3.7], [True], [2]],
        ("closing_directions", "signs"): [
            [np.nan, 1, 1],
            [np.inf, 1, 1],
            "abc",
            [[1, 1, 1]],
        ],
        ("squeeze_push_of", "directions"): [
            [[1, 0, 0], [0, 0, 0]],
            [[np.nan, 0, 0]],
            np.zeros((0, 3)),
            None,
            "x",
            [1, 0, 0],
            [[True, False, False]],
            np.ones((2, 3, 1)),
        ],
        ("push_text", "push"): [-0.1, 1.5, np.inf, "0.9", None, True, [0.9]],
    }
    for (call, name), values in bad.items():
        for i, v in enumerate(values):
            label = " ".join(repr(v).split())[:30]
            yield pytest.param(calls[call], name, v, id=f"{call}-{name}{i}={label}")


@pytest.mark.parametrize(("call", "name", "value"), list(_opposition_cases()))
def test_the_squeeze_push_functions_refuse_what_they_cannot_read(call, name, value):
    # a NaN sign or a zero frame made every contact "passive" or gave a zero
    # "unit" direction; a zero direction was read as opposing the others;
    # push_text(1) (an int) said nothing, push_text("0.9") too; a component
    # count "a" raised a raw ValueError
    with np.errstate(all="ignore"), pytest.raises(dg.GraspError):
        call(**{name: value})


def test_with_squeeze_push_names_what_is_not_a_run():
    with pytest.raises(dg.GraspError, match="result"):
        motors.with_squeeze_push(None, None, None, None, top=1, started=0.0)
    empty = dg.GraspCandidates(
        candidates=(), rejections={}, num_sampled=0, object_body="box", mu=0.5,
        torque_scale=0.05,
    )  # fmt: skip
    for bad in ({"top": -1}, {"top": "3"}, {"check": 2.5}, {"started": "now"}):
        with pytest.raises(dg.GraspError, match=next(iter(bad))):
            motors.with_squeeze_push(
                empty, None, None, None, **{"top": 1, "started": 0.0, **bad}
            )
    with pytest.raises(dg.GraspError, match="push_last"):
        motors.with_squeeze_push(
            empty, None, None, None, top=1, started=0.0, push_last="no"
        )
