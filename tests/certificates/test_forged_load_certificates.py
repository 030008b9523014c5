"""``LoadCertificate.check`` refuses forged and foreign load certificates.

A genuine certificate of ``max_load`` (two fingers on a box, μ = 0.5, a 100 N
squeeze bound: the closed form 2 μ 50 N / (m g) = 5.0968 x the weight of 1 kg)
is edited one field at a time.  A claimed bound that is NaN, negative or
infinite proves nothing (the grasp always holds α = 0 with no force), nor do
negative or NaN limits that no force can meet: each must fail its check.  A
certificate read against another grasp or hand, or with fields that are not
real arrays, is refused with a ``GraspError`` that names the field.
"""

import dataclasses

import numpy as np
import pytest

import drakegrasp as dg

G_EARTH = 9.81
WEIGHT = np.array([0, 0, -G_EARTH, 0, 0, 0])


def _pinch():
    return dg.Grasp(
        [
            dg.Contact([-0.05, 0, 0], [1, 0, 0], mu=0.5),
            dg.Contact([0.05, 0, 0], [-1, 0, 0], mu=0.5),
        ]
    )


@pytest.fixture(scope="module")
def squeeze_bound():
    g = _pinch()
    r = dg.max_load(g, WEIGHT, max_squeeze=100.0)
    assert r.alpha == pytest.approx(2 * 0.5 * 50.0 / G_EARTH, rel=1e-6)
    assert r.certificate.check(g).holds
    return g, r.certificate


@pytest.fixture(scope="module")
def motor_bound():
    g = dg.examples.equator_fingers(0.5, num_fingers=3)
    J = np.eye(9)[:, :4] + 0.1
    r = dg.max_load(g, WEIGHT, hand_jacobian=J, torque_limits=1.0)
    assert r.certificate.check(g, hand_jacobian=J).holds
    assert np.any(r.certificate.joint_multipliers != 0.0)
    return g, J, r.certificate


@pytest.mark.parametrize(
    "change",
    [
        {"bound": np.nan},
        {"bound": -np.inf},
        {"bound": -1.0},
        {"bound": np.inf},
        {"max_squeeze": -100.0},
        {"max_squeeze": np.nan},
        {"squeeze_multiplier": np.nan},
        {"squeeze_multiplier": -1.0},
        {"twist": np.array([0, 0, np.inf, 0, 0, 0])},
        {"max_normal_force": np.array([-1.0, -1.0])},
    ],
    ids=str,
)
def test_forged_squeeze_bounds_fail(squeeze_bound, change):
    g, cert = squeeze_bound
    check = dataclasses.replace(cert, **change).check(g)
    assert not check.holds
    assert check.violation == np.inf


@pytest.mark.parametrize("limits", [-1e3 * np.ones(4), np.full(4, np.nan)], ids=str)
def test_forged_motor_limits_fail(motor_bound, limits):
    g, J, cert = motor_bound
    check = dataclasses.replace(cert, torque_limits=limits).check(g, hand_jacobian=J)
    assert not check.holds


def test_a_certificate_without_the_limits_it_uses_proves_nothing(motor_bound):
    g, J, cert = motor_bound
    check = dataclasses.replace(cert, torque_limits=None).check(g, hand_jacobian=J)
    assert not check.holds


@pytest.mark.parametrize(
    "change,match",
    [
        ({"normal_multipliers": np.zeros(1)}, "normal_multipliers"),
        ({"normal_multipliers": np.zeros(5)}, "normal_multipliers"),
        ({"twist": "abc"}, "twist"),
        ({"wrench": np.zeros(3)}, "wrench"),
        ({"max_normal_force": np.ones(3)}, "max_normal_force"),
        ({"bound": "big"}, "bound"),
        ({"num_generators": 0}, "num_generators"),
    ],
    ids=str,
)
def test_malformed_fields_are_named(squeeze_bound, change, match):
    g, cert = squeeze_bound
    with pytest.raises(dg.InvalidOptionError, match=match):
        dataclasses.replace(cert, **change).check(g)


def test_foreign_grasps_hands_and_tolerances_are_refused(squeeze_bound, motor_bound):
    g, cert = squeeze_bound
    with pytest.raises(dg.InvalidGraspError, match="grasp"):
        cert.check("not a grasp")
    with pytest.raises(dg.InvalidOptionError, match="another grasp"):
        cert.check(dg.examples.equator_fingers(0.5, num_fingers=3))
    for tol in (None, "1e-7", 0.0, 1.0, np.nan):
        with pytest.raises(dg.InvalidOptionError, match="tol"):
            cert.check(g, tol=tol)
    g3, J, motor = motor_bound
    with pytest.raises(dg.InvalidOptionError, match="torque_limits"):
        dataclasses.replace(motor, torque_limits=np.ones(2)).check(g3, hand_jacobian=J)
    with pytest.raises(dg.InvalidOptionError, match="columns"):
        motor.check(g3, hand_jacobian=J[:, :3])


@pytest.mark.parametrize("certify", [np.ones(2), "no", np.nan, 2])
def test_max_load_certify_is_a_flag(certify):
    with pytest.raises(dg.InvalidOptionError, match="certify"):
        dg.max_load(_pinch(), WEIGHT, max_squeeze=100.0, certify=certify)
