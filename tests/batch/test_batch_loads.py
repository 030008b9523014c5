"""batch_grasp_forces: the single path's answers on many grasps."""

import json

import numpy as np
import pytest

import drakegrasp as dg


def _grasps(rng, K):
    out = []
    for k in range(K):
        contacts = []
        for _ in range(3 + k % 3):  # 3, 4 and 5 contacts
            p = rng.normal(size=3)
            p *= 0.04 / np.linalg.norm(p)
            n = -p / np.linalg.norm(p) + 0.3 * rng.normal(size=3)
            contacts.append(dg.Contact(p, n, mu=rng.uniform(0.2, 0.9)))
        out.append(dg.Grasp(contacts))
    return out


@pytest.mark.parametrize("cones", ["exact", "polyhedral"])
def test_batch_matches_the_single_path(cones):
    rng = np.random.default_rng(7)
    grasps = _grasps(rng, 9)
    W = np.column_stack([rng.normal(size=(9, 3)) * 3, rng.normal(size=(9, 3)) * 0.05])
    Js = [rng.normal(size=(g.num_components, 3)) * 0.04 for g in grasps]
    limits = [rng.uniform(0.05, 0.5, size=3) for _ in grasps]
    batch = dg.batch_grasp_forces(
        grasps, W, hand_jacobians=Js, torque_limits=limits, cones=cones
    )
    assert 0 < batch.feasible.sum() < len(grasps)  # both answers occur
    for k, g in enumerate(grasps):
        one = dg.grasp_forces(
            g, W[k], hand_jacobian=Js[k], torque_limits=limits[k], cones=cones
        )
        assert batch.feasible[k] == one.feasible
        if one.feasible:
            assert batch.squeeze[k] == pytest.approx(one.squeeze, rel=1e-9)
            assert batch.torque_usage[k] == pytest.approx(one.torque_usage, rel=1e-9)
        else:
            cert = batch.results[k].certificate
            assert cert.check(g, hand_jacobian=Js[k]).holds
    json.dumps(batch.to_dict())
    assert "grasps hold their load" in str(batch)


def test_batch_broadcasts_one_load_and_refuses_wrong_lengths():
    rng = np.random.default_rng(1)
    grasps = _grasps(rng, 3)
    w = np.array([0, 0, -1.0, 0, 0, 0])
    batch = dg.batch_grasp_forces(grasps, w, max_squeeze=50.0)
    assert batch.squeeze == pytest.approx(
        [dg.grasp_forces(g, w, max_squeeze=50.0).squeeze for g in grasps],
        nan_ok=True,
    )
    with pytest.raises(dg.InvalidOptionError, match="one per grasp"):
        dg.batch_grasp_forces(grasps, w, max_squeeze=[1.0, 2.0])
    with pytest.raises(dg.InvalidOptionError, match="wrenches"):
        dg.batch_grasp_forces(grasps, np.zeros((2, 6)))


class _Hostile(Exception):
    pass


def _boom(*_args):
    raise _Hostile("a hostile dunder")


class _LenRaises(list):
    __len__ = _boom


class _IterRaises:
    def __len__(self):
        return 2

    __iter__ = _boom
    __getitem__ = _boom


@pytest.mark.parametrize("name", ["torque_limits", "max_normal_force", "max_squeeze"])
def test_a_per_grasp_option_whose_items_cannot_be_read_is_named(name):
    # list(value) let the hostile dunder's exception through (fuzz seed 5).
    grasps = _grasps(np.random.default_rng(3), 2)
    W = np.zeros((2, 6))
    with pytest.raises(dg.InvalidOptionError, match=f"^{name} must be"):
        dg.batch_grasp_forces(grasps, W, **{name: _IterRaises()})


def test_a_per_grasp_list_is_read_without_its_length():
    grasps = _grasps(np.random.default_rng(3), 2)
    W = np.zeros((2, 6))
    want = dg.batch_grasp_forces(grasps, W, max_squeeze=[2.0, 3.0])
    got = dg.batch_grasp_forces(grasps, W, max_squeeze=_LenRaises([2.0, 3.0]))
    np.testing.assert_array_equal(got.squeeze, want.squeeze)
