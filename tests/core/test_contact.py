import dataclasses

import numpy as np
import pytest

import drakegrasp as dg


def test_frame_is_a_right_handed_rotation_with_normal_first(rng):
    normals = rng.normal(size=(200, 3))
    normals = np.vstack([normals, np.eye(3), -np.eye(3), [[1, 1, 0], [1, 1, 1]]])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    R = dg.contact_frames(normals)
    assert np.allclose(R @ np.swapaxes(R, 1, 2), np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.det(R), 1.0)
    assert np.allclose(R[:, :, 0], normals)
    assert np.allclose(R[:, :, 2], np.cross(R[:, :, 0], R[:, :, 1]))


def test_single_and_vectorised_frames_agree_and_depend_on_n_alone(rng):
    for n in rng.normal(size=(20, 3)):
        R = dg.contact_frame(n)
        assert np.allclose(R, dg.contact_frame(3.0 * n), rtol=0, atol=1e-15)
        unit = n / np.linalg.norm(n)
        assert np.allclose(R, dg.contact_frames(unit[None])[0], rtol=0, atol=1e-15)


def test_documented_tangent_choice():
    # t1: projection of the axis where |n| is smallest (first on ties).
    R = dg.contact_frame([0, 0, 1])
    assert np.allclose(R[:, 1], [1, 0, 0]) and np.allclose(R[:, 2], [0, 1, 0])
    n = np.array([-np.cos(0.3), -np.sin(0.3), 0.0])
    assert np.allclose(dg.contact_frame(n)[:, 1], [0, 0, 1])


def test_planar_frame():
    n = np.array([0.6, 0.8])
    R = dg.contact_frame(n)
    assert np.allclose(R, [[0.6, -0.8], [0.8, 0.6]])
    assert np.isclose(np.linalg.det(R), 1.0)


def test_contact_normalises_and_is_immutable():
    c = dg.Contact([1, 2, 3], [0, 0, -2], mu=0.4)
    assert np.allclose(c.normal, [0, 0, -1])
    with pytest.raises(ValueError):
        c.position[0] = 5.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.mu = 1.0
    assert c.component_names == ("f_n", "f_t1", "f_t2")
    assert c.with_(mu=0.7).mu == 0.7 and c.mu == 0.4


@pytest.mark.parametrize(
    ("kwargs", "expected"),
    [
        ({"contact_model": "frictionless", "mu": 0.5}, (0,)),
        ({"contact_model": "hard_finger", "mu": 0.0}, (0,)),
        ({"contact_model": "hard_finger", "mu": 0.5}, (0, 1, 2)),
        (
            {"contact_model": "soft_finger", "mu": 0.5, "torsional_friction": 0.1},
            (0, 1, 2, 3),
        ),
        (
            {"contact_model": "soft_finger", "mu": 0.5, "torsional_friction": 0},
            (0, 1, 2),
        ),
        (
            {"contact_model": "soft_finger", "mu": 0.0, "torsional_friction": 0.1},
            (0, 3),
        ),
    ],
)
def test_effective_components(kwargs, expected):
    c = dg.Contact([0, 0, 1], [0, 0, -1], **kwargs)
    assert c.effective_components() == expected


def test_model_enum_and_strings_are_interchangeable():
    a = dg.Contact([0, 0], [1, 0], contact_model=dg.ContactModel.FRICTIONLESS)
    b = dg.Contact([0, 0], [1, 0], contact_model="Frictionless")
    assert a.contact_model is b.contact_model is dg.ContactModel.FRICTIONLESS
    assert a.to_dict()["contact_model"] == "frictionless"


def test_a_contact_made_a_soft_finger_needs_its_torsion_coefficient():
    # Contact.with_ and Grasp.with_friction took the hard finger's 0 as the
    # soft finger's ν: a soft finger that resists no torsion, silently (a
    # grasp whose verdict then read "no").  Now as Contact(...) does.
    grasp = dg.examples.spatial_two_fingers(0.5)
    with pytest.raises(dg.InvalidContactError, match="torsional_friction"):
        grasp.with_friction(contact_model="soft_finger")
    with pytest.raises(dg.InvalidContactError, match="torsional_friction"):
        grasp.contacts[0].with_(contact_model="soft_finger")
    soft = grasp.with_friction(contact_model="soft_finger", torsional_friction=0.1)
    assert all(c.torsional_friction == 0.1 for c in soft.contacts)
    assert dg.force_closure(soft).is_closure
    # a soft finger keeps its own ν through other changes, and ν = 0 stays
    # possible when asked for
    assert soft.with_friction(mu=0.8).contacts[0].torsional_friction == 0.1
    explicit = grasp.with_friction(contact_model="soft_finger", torsional_friction=0)
    assert explicit.contacts[0].torsional_friction == 0.0
    # a hard finger may carry a ν of its own: made a soft finger, it keeps it
    hard = dg.Contact([0, 0, 0.1], [0, 0, -1], mu=0.5, torsional_friction=0.02)
    assert hard.with_(contact_model="soft_finger").torsional_friction == 0.02


def test_contact_frames_refuses_normals_that_are_not_unit():
    # it returned [[2, 0, 0], [0, 1, 0], [0, 0, 2]] for the normal [2, 0, 0]:
    # no rotation, silently
    with pytest.raises(dg.InvalidContactError, match=r"index \(1,\).*off 1 by 1 "):
        dg.contact_frames([[0.0, 0.0, 1.0], [2.0, 0.0, 0.0]])
    with pytest.raises(dg.InvalidContactError, match="off 1 by 0.5 "):
        dg.contact_frames([0.0, 0.5])
    n = np.array([[1.0, 2.0, 3.0], [0.0, -1.0, 0.0]])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    R = dg.contact_frames(n)
    np.testing.assert_allclose(
        R @ np.swapaxes(R, -1, -2), np.broadcast_to(np.eye(3), R.shape), atol=1e-15
    )
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-15)
    # normals normalised in float32 (about 1e-7 off) are unit vectors
    n32 = (n / np.linalg.norm(n, axis=1, keepdims=True)).astype(np.float32)
    assert dg.contact_frames(n32).shape == (2, 3, 3)
    # the one-normal route normalises
    np.testing.assert_allclose(
        dg.contact_frame([2.0, 0.0, 0.0]), dg.contact_frames([1.0, 0.0, 0.0])
    )


def _frames_by_cross(n):
    """The frames as numpy's own routines build them (the route before 43)."""
    axis = np.argmin(np.abs(n), axis=-1)
    e = np.zeros_like(n)
    np.put_along_axis(e, axis[..., None], 1.0, axis=-1)
    t1 = e - np.sum(e * n, axis=-1, keepdims=True) * n
    t1 /= np.linalg.norm(t1, axis=-1, keepdims=True)
    return np.stack([n, t1, np.cross(n, t1)], axis=-1)


def _hostile_unit_normals(rng, count):
    """Unit normals with ties, zeros of either sign, and scales 1e-300 to 1e300."""
    from drakegrasp.core.validation import unit_vectors

    raw = rng.normal(size=(count, 3)) * 10.0 ** rng.integers(-300, 300, (count, 1))
    raw[: count // 4] = rng.choice([-1.0, -0.0, 0.0, 1.0, 2.0], (count // 4, 3))
    raw[count // 4 : count // 2, 1] = raw[count // 4 : count // 2, 0]  # ties
    raw = raw[np.any(raw != 0.0, axis=1)]
    return unit_vectors("normals", raw)


def test_frames_are_bitwise_those_of_numpys_cross(rng):
    # The frames compute e·n as n's component and n × t1 component by
    # component: the same floating-point operations as np.sum and np.cross,
    # so every bit, signs of zero included, is theirs (d* downstream too).
    from drakegrasp.core.contact import _frames_of

    n = _hostile_unit_normals(rng, 40_000)
    ours, theirs = _frames_of(n), _frames_by_cross(n)
    assert ours.tobytes() == theirs.tobytes()
    assert dg.contact_frames(n).tobytes() == theirs.tobytes()
    for k in range(0, len(n), 997):  # one at a time, as a Contact builds its own
        contact = dg.Contact([0.0, 0.0, 0.0], n[k])  # normalises n[k] again
        expected = _frames_by_cross(contact.normal[None])[0]
        assert contact.frame.tobytes() == expected.tobytes()
