"""Review r22 of the planning stages: groups, directions and noise σ refused.

* ``robustness``/``perturbed_copies`` took ``groups`` naming no finger of
  ``fingers`` (and ``robustness`` an empty ``groups``): no contact moved and
  the robustness read 1.0 against 0.81 with the fingers' labels.
* ``torque_capacity`` read ``directions`` itself: ``1e300`` overflowed to a
  zero direction (``inf`` without a word), a string raised a raw ValueError,
  complex input a ComplexWarning.
* a noise σ of ``1e300`` was taken: numpy's overflow warning in
  ``reclosed_robustness``, copies scattered to 1e300 m in ``perturbed_copies``.
"""

from __future__ import annotations

import hashlib
import types
import warnings

import numpy as np
import pytest
from pydrake.geometry import Box
from pydrake.math import RigidTransform

import drakegrasp as dg
from drakegrasp.errors import InvalidOptionError
from drakegrasp.planning import checks, motors
from drakegrasp.planning.ranking import (
    DEFAULT_NOISE,
    checked_noise,
    perturbed_copies,
    robustness,
)
from drakegrasp.planning.reclose import reclosed_robustness
from drakegrasp.planning.surface import ObjectSurface, piece_of_shape

_E = dg.examples.equator_fingers(0.5)
P3 = _E.positions[None] * 0.05  # three fingers 12 cm apart on a 5 cm circle
N3 = _E.normals[None]
F3 = np.array([[0, 1, 2]])
ROBUST = dict(
    mu=0.5, samples=32, noise={"position": 0.01, "angle_deg": 20, "friction": 0.0},
    contact_model="hard_finger", torsional_friction=None, workers=1,
)  # fmt: skip
COPIES = dict(mu=0.5, samples=4, position=0.01, angle_deg=20, friction=0.1)


def _digest(*arrays) -> list[str]:
    return [
        hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()[:16]
        for a in arrays
    ]


@pytest.fixture
def quiet():
    """Any warning is an error (numpy's overflow, a ComplexWarning)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        yield


# ----------------------------------------------------------------- 1. groups


@pytest.mark.parametrize("groups", [(5,), (3, 4), [63]])
def test_robustness_refuses_groups_naming_no_finger_of_fingers(groups):
    with pytest.raises(InvalidOptionError, match=r"groups.*\[0, 1, 2\]"):
        robustness(P3, N3, F3, rng=np.random.default_rng(0), groups=groups, **ROBUST)


def test_robustness_refuses_empty_groups():
    with pytest.raises(InvalidOptionError, match=r"groups.*empty.*\[0, 1, 2\]"):
        robustness(P3, N3, F3, rng=np.random.default_rng(0), groups=(), **ROBUST)


def test_perturbed_copies_refuses_groups_naming_no_finger_of_fingers():
    with pytest.raises(InvalidOptionError, match=r"groups.*\[0, 1, 2\]"):
        perturbed_copies(
            P3, N3, F3, rng=np.random.default_rng(3), groups=(5,), **COPIES
        )


def test_groups_are_checked_before_any_draw():
    rng = np.random.default_rng(0)
    state = rng.bit_generator.state
    with pytest.raises(InvalidOptionError, match="groups"):
        robustness(P3, N3, F3, rng=rng, groups=(7,), **ROBUST)
    assert rng.bit_generator.state == state


def test_valid_groups_keep_their_numbers():
    # recorded before the check: the same draws, the same copies
    rng = np.random.default_rng(0)
    rho = robustness(P3, N3, F3, rng=rng, groups=(0, 1, 2), **ROBUST)
    np.testing.assert_array_equal(rho, [0.8125])
    got = perturbed_copies(
        P3, N3, F3, rng=np.random.default_rng(3), groups=(0, 1, 2), **COPIES
    )
    assert _digest(*got) == ["8e506d6c380b5f8d", "7e43e86e471d844e", "89e57fed33b34825"]
    # the multi-finger planner passes every finger of the hand; a batch may
    # lack one (finger 1 here): the others move as before
    F = np.array([[0, 2, 3]])
    got = perturbed_copies(
        P3, N3, F, rng=np.random.default_rng(3), groups=(0, 1, 2, 3), **COPIES
    )
    assert _digest(*got) == ["f1286364ef2596fe", "bde32e5972bc5045", "d2b6e623f3dc9316"]
    rng = np.random.default_rng(0)
    rho = robustness(P3, N3, F, rng=rng, groups=(0, 1, 2, 3), **ROBUST)
    np.testing.assert_array_equal(rho, [0.875])


def test_no_grasp_takes_any_valid_groups():
    none = np.zeros((0, 3, 3))
    rho = robustness(
        none, none, np.zeros((0, 3), int), rng=np.random.default_rng(0),
        groups=(5,), **ROBUST,
    )  # fmt: skip
    assert rho.shape == (0,)


# ------------------------------------------------------------ 2. directions


class _Grasp:
    """``torque_capacity`` on a fixed grasp and Jacobian, without a plant."""

    def __init__(self, monkeypatch):
        self.candidate = types.SimpleNamespace(grasp=_E)
        J = np.random.default_rng(5).standard_normal((_E.num_components, 6))
        monkeypatch.setattr(motors, "finger_jacobian", lambda *a, **k: J)
        # six joints, each its own motor (no plant to read couplings from)
        monkeypatch.setattr(motors, "_motor_map", lambda *a, **k: None)

    def __call__(self, directions):
        return motors.torque_capacity(
            None, None, self.candidate, None, directions=directions
        )


def test_torque_capacity_normalises_huge_directions(monkeypatch, quiet):
    beta = _Grasp(monkeypatch)
    unit = beta([[0.0, 0.0, -1.0], [0.0, 1.0, -1.0]])
    huge = beta([[0.0, 0.0, -1e300], [0.0, 1e300, -1e300]])
    tiny = beta([[0.0, 0.0, -1e-300], [0.0, 1e-300, -1e-300]])
    assert np.all(np.isfinite(unit)) and np.all(unit > 0)
    np.testing.assert_allclose(huge, unit, rtol=1e-9)
    np.testing.assert_allclose(tiny, unit, rtol=1e-9)


@pytest.mark.parametrize(
    "directions",
    [
        "abc",
        np.array([[1j, 0, 0]]),
        [[1, 0]],
        np.zeros((0, 3)),
        [[0.0, 0.0, 0.0]],
        [[np.nan, 0.0, 1.0]],
        None,
        [[1, 0, 0], [1, 0]],
    ],
    ids=["str", "complex", "2d", "empty", "zero", "nan", "none", "ragged"],
)
def test_torque_capacity_names_bad_directions(directions, quiet):
    with pytest.raises(InvalidOptionError, match="directions"):
        motors.torque_capacity(None, None, None, None, directions=directions)


# ----------------------------------------------------------------- 3. noise σ


def _box():
    return ObjectSurface.from_pieces(
        [piece_of_shape(Box(0.06, 0.1, 0.2), RigidTransform(), "o")]
    )


P_RE = np.array([[[-0.03, 0.0, 0.0], [0.03, 0.0, 0.0]]])
F_RE = np.array([[0, 1]])
AXES = np.array([[1.0, 0.0, 0.0]])
RECLOSE = dict(
    mu=0.5, samples=8, position=2e-3, angle_deg=3.0, friction=0.1, tol=1e-4,
    contact_model="hard_finger", torsional_friction=None, workers=1,
)  # fmt: skip
HUGE = {"position": 1e300, "angle_deg": 1e300, "friction": 1e300}


@pytest.mark.parametrize("key", sorted(HUGE))
@pytest.mark.parametrize("value", ["huge", "just_over"])
def test_reclosed_robustness_refuses_a_huge_sigma(key, value, quiet):
    if value == "huge":
        sigma = HUGE[key]
    else:
        sigma = np.nextafter(checks.NOISE_MAX[key], np.inf)
    rng = np.random.default_rng(0)
    state = rng.bit_generator.state
    with pytest.raises(InvalidOptionError, match=rf"^{key} .*NOISE_MAX"):
        reclosed_robustness(
            _box(), P_RE, F_RE, AXES, rng=rng, **{**RECLOSE, key: sigma}
        )
    assert rng.bit_generator.state == state


@pytest.mark.parametrize("key", sorted(HUGE))
def test_robustness_and_copies_refuse_a_huge_sigma(key):
    noise = {**ROBUST["noise"], key: HUGE[key]}
    kw = {k: v for k, v in ROBUST.items() if k != "noise"}
    with pytest.raises(InvalidOptionError, match=rf"^noise\['{key}'\] .*NOISE_MAX"):
        robustness(P3, N3, F3, rng=np.random.default_rng(0), noise=noise, **kw)
    with pytest.raises(InvalidOptionError, match=rf"^{key} .*NOISE_MAX"):
        perturbed_copies(
            P3, N3, F3, rng=np.random.default_rng(3), **{**COPIES, key: HUGE[key]}
        )
    with pytest.raises(InvalidOptionError, match=rf"noise\['{key}'\]"):
        checked_noise(noise, "noise[{!r}]")  # the planner's check of noise=


def test_sigmas_at_their_bounds_run_without_a_warning(quiet):
    top = dict(checks.NOISE_MAX)
    rho = reclosed_robustness(
        _box(), P_RE, F_RE, AXES, rng=np.random.default_rng(0), **{**RECLOSE, **top}
    )
    P, Nrm, mus = perturbed_copies(
        P3, N3, F3, rng=np.random.default_rng(3), groups=(0, 1, 2),
        **{**COPIES, **top},
    )  # fmt: skip
    kw = {k: v for k, v in ROBUST.items() if k != "noise"}
    rob = robustness(
        P3, N3, F3, rng=np.random.default_rng(0), noise=top, groups=(0, 1, 2),
        **{**kw, "samples": 8},
    )  # fmt: skip
    assert rho.shape == (1,) and 0.0 <= rho[0] <= 1.0
    assert rob.shape == (1,) and 0.0 <= rob[0] <= 1.0
    assert np.all(np.isfinite(P)) and np.all(np.abs(P) <= 1e20)
    assert np.all(np.isfinite(mus))


def test_the_noise_bounds_are_far_above_any_sensible_sigma():
    assert checked_noise(DEFAULT_NOISE) == DEFAULT_NOISE
    assert set(checks.NOISE_MAX) == set(DEFAULT_NOISE)
    for key, value in DEFAULT_NOISE.items():
        assert checks.NOISE_MAX[key] >= 1e5 * value
    # the clearance (also checked_nonnegative) keeps no upper bound
    assert checks.checked_nonnegative("clearance", 1e300, "metres") == 1e300
