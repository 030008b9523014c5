"""Batch ε L1: invariances, the Qhull fallback, the entry point's input checks."""

from __future__ import annotations

import numpy as np
import pytest
from batch_support import make_grasp, random_grasps
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from drakegrasp import GraspError, InvalidContactError, InvalidOptionError
from drakegrasp.batch import batch_epsilon_l1, batch_force_closure
from drakegrasp.batch.build.construction import batched_characteristic_lengths
from drakegrasp.batch.build.wrenches import batched_primitive_wrenches
from drakegrasp.batch.epsilon import kernel as epsilon_kernel
from drakegrasp.batch.epsilon import polytope
from drakegrasp.batch.epsilon.routes import epsilon_l1_routes
from drakegrasp.quality import ferrari_canny

pytestmark = pytest.mark.skipif(
    not epsilon_kernel.AVAILABLE, reason="the compiled ε kernel needs numba"
)

SETTINGS = settings(
    derandomize=True,
    deadline=None,
    max_examples=25,
    suppress_health_check=[HealthCheck.too_slow],
)
seeds = st.integers(min_value=0, max_value=2**32 - 1)


def _grasps(seed, K=40, N=4, d=3, spread=0.4):
    rng = np.random.default_rng(seed)
    P, Nrm = random_grasps(rng, K, N, d, spread=spread)
    return rng, P, Nrm


def _cube_rotation(rng):
    """A random rotation of the cube (signed permutation, det +1).

    The linearised cones' tangent ``t1`` follows the coordinate axes
    (:func:`drakegrasp.contact_frames`), so a general rotation moves the
    generators around the cone and changes the polyhedral ε; these rotations
    map each ring of ``n_g = 8`` generators onto the rotated ring.
    """
    R = np.eye(3)[rng.permutation(3)] * rng.choice([-1.0, 1.0], size=3)
    if np.linalg.det(R) < 0:
        R[0] *= -1.0
    return R


def _hard_wrenches(P, Nrm, mu):
    """Primitive wrenches of spatial hard fingers about the origin, (K, 8 N, 6)."""
    Nn = Nrm / np.linalg.norm(Nrm, axis=-1, keepdims=True)
    K, N, _ = P.shape
    return batched_primitive_wrenches(
        P, Nn, np.full((K, N), mu), np.zeros((K, N)), np.zeros((K, 3)),
        batched_characteristic_lengths(P, np.zeros((K, 3))),
        contact_model="hard_finger", num_generators=8,
    )  # fmt: skip


def _close(a, b):
    np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-12)


@SETTINGS
@given(seed=seeds, N=st.integers(3, 6))
def test_contact_order_does_not_matter(seed, N):
    rng, P, Nrm = _grasps(seed, N=N)
    mu = rng.uniform(0.1, 1.0, size=(40, N))
    perm = rng.permutation(N)
    _close(
        batch_epsilon_l1(P[:, perm], Nrm[:, perm], mu=mu[:, perm]),
        batch_epsilon_l1(P, Nrm, mu=mu),
    )


@SETTINGS
@given(seed=seeds)
def test_rigid_motion_does_not_matter(seed):
    """Rotating and translating contacts and reference point together keeps ε.

    The wrench set rotates by ``diag(R, R)``, an isometry, so every distance
    from the origin to a facet is kept.
    """
    rng, P, Nrm = _grasps(seed)
    p = 0.3 * rng.normal(size=(40, 3))
    R, t = _cube_rotation(rng), rng.normal(size=3)
    eps = batch_epsilon_l1(P, Nrm, mu=0.5, reference_points=p)
    moved = batch_epsilon_l1(
        P @ R.T + t, Nrm @ R.T, mu=0.5, reference_points=p @ R.T + t
    )
    _close(moved, eps)


@SETTINGS
@given(seed=seeds, scale=st.floats(1e-3, 1e3))
def test_length_and_force_scaling(seed, scale):
    """Scaling lengths keeps ε (moments over b); scaling wrenches scales ε."""
    rng, P, Nrm = _grasps(seed, N=5)
    eps = batch_epsilon_l1(P, Nrm, mu=0.5)
    _close(batch_epsilon_l1(scale * P, Nrm, mu=0.5), eps)
    W = _hard_wrenches(P, Nrm, 0.5)
    e1, s1 = epsilon_kernel.epsilon_l1_stack(W)
    e2, s2 = epsilon_kernel.epsilon_l1_stack(scale * W)
    assert (s1 <= epsilon_kernel.FLAT).all() and (s2 == s1).all()
    _close(e2, scale * e1)


@SETTINGS
@given(seed=seeds, mu=st.floats(0.05, 1.5), factor=st.floats(1.0, 3.0))
def test_more_friction_never_lowers_epsilon(seed, mu, factor):
    """The μ ring's hull contains the smaller ring's (same angles, same axis)."""
    _, P, Nrm = _grasps(seed, N=4)
    low = batch_epsilon_l1(P, Nrm, mu=mu)
    high = batch_epsilon_l1(P, Nrm, mu=mu * factor)
    assert (high >= low - 1e-12).all()


def test_thin_cones_are_flagged_and_answered_by_qhull():
    """μ = 1e-9 makes the wrench set 1e-9 thin: the kernel hands it to Qhull."""
    rng = np.random.default_rng(0)
    V = np.vstack([np.eye(3), -np.eye(3)])  # six contacts, an octahedron
    K = 6
    P = np.broadcast_to(V, (K, 6, 3)) + 1e-3 * rng.normal(size=(K, 6, 3))
    Nrm = -P / np.linalg.norm(P, axis=-1, keepdims=True)
    mu, nu = np.full((K, 6), 1e-9), np.zeros((K, 6))
    p, b = np.zeros((K, 3)), batched_characteristic_lengths(P, np.zeros((K, 3)))
    W = batched_primitive_wrenches(
        P, Nrm, mu, nu, p, b, contact_model="hard_finger", num_generators=8
    )
    _, status = epsilon_kernel.epsilon_l1_stack(W)
    assert (status == epsilon_kernel.ILL).all()
    eps, qhull = epsilon_l1_routes(
        P, Nrm, mu, nu, p, b, contact_model="hard_finger", num_generators=8
    )
    assert qhull.all()
    want = [ferrari_canny(make_grasp(P[k], Nrm[k], 1e-9)) for k in range(K)]
    # The same Qhull route, on normals normalised once more by Contact.
    np.testing.assert_allclose(eps, want, rtol=1e-9, atol=0.0)
    assert (eps > 0).all()


def test_a_full_facet_store_is_retried_with_more_room():
    rng, P, Nrm = _grasps(3, K=60, N=6)
    W = _hard_wrenches(P, Nrm, 0.5)
    eps, status, info = epsilon_kernel.epsilon_l1_stack(W, return_info=True)
    assert info[:, 1].max() > 16  # so 16 facets cannot hold them
    small, small_status = epsilon_kernel.epsilon_l1_stack(W, capacity=16)
    np.testing.assert_array_equal(small, eps)
    np.testing.assert_array_equal(small_status, status)


def test_metric_of_batch_force_closure_is_the_batch_epsilon():
    _, P, Nrm = _grasps(9, K=300, N=4)
    res = batch_force_closure(P, Nrm, mu=0.6, metrics=["epsilon_l1"])
    eps = batch_epsilon_l1(P, Nrm, mu=0.6)
    np.testing.assert_array_equal(res.metrics["epsilon_l1"], eps)
    # ε > 0 exactly when the polyhedral cones give force closure.
    assert ((eps > 0) == res.is_closure).mean() > 0.99
    ref = batch_epsilon_l1(P, Nrm, mu=0.6, kernel="numpy")
    _close(eps, ref)


def test_workers_and_chunks_give_the_same_answer():
    _, P, Nrm = _grasps(4, K=90, N=3)
    eps = batch_epsilon_l1(P, Nrm, mu=0.5)
    np.testing.assert_array_equal(batch_epsilon_l1(P, Nrm, mu=0.5, chunk_size=7), eps)
    np.testing.assert_array_equal(
        batch_epsilon_l1(P, Nrm, mu=0.5, chunk_size=30, workers=2), eps
    )
    assert not eps.flags.writeable


def test_soft_finger_needs_torsion_and_planar_rejects_it():
    _, P, Nrm = _grasps(5, K=4, N=3)
    with pytest.raises(InvalidContactError, match="torsional_friction"):
        batch_epsilon_l1(P, Nrm, mu=0.5, contact_model="soft_finger")
    with pytest.raises(InvalidContactError, match="spatial only"):
        batch_epsilon_l1(
            P[:, :, :2],
            Nrm[:, :, :2],
            mu=0.5,
            contact_model="soft_finger",
            torsional_friction=1,
        )


@pytest.mark.parametrize(
    ("change", "error", "match"),
    [
        (lambda a: a.update(positions=a["positions"][:, :, 0]), InvalidContactError,
         "shape"),
        (lambda a: a["positions"].__setitem__((1, 0, 0), np.nan), InvalidContactError,
         "grasp 1, contact 0"),
        (lambda a: a["normals"].__setitem__((2, 1, 1), np.inf), InvalidContactError,
         "grasp 2, contact 1"),
        (lambda a: a["normals"].__setitem__((0, 2), 0.0), InvalidContactError,
         "non-zero"),
        (lambda a: a.update(normals=a["normals"][:, :2]), InvalidContactError,
         "shape"),
        (lambda a: a.update(mu=-0.5), InvalidContactError, "mu"),
        (lambda a: a.update(mu=np.full((4, 2), 0.5)), InvalidContactError, "mu"),
        (lambda a: a.update(mu=float("nan")), InvalidContactError, "mu"),
        (lambda a: a.update(num_generators=2), InvalidOptionError, "num_generators"),
        (lambda a: a.update(kernel="fortran"), InvalidOptionError, "kernel"),
        (lambda a: a.update(contact_model="glue"), GraspError, "model"),
        (lambda a: a.update(reference_points=np.ones(2)), GraspError, "reference"),
        (lambda a: a.update(characteristic_lengths=-1.0), GraspError,
         "characteristic"),
        (lambda a: a.update(chunk_size=0), InvalidOptionError, "chunk_size"),
    ],
)  # fmt: skip
def test_hostile_input_raises_grasp_errors(change, error, match):
    _, P, Nrm = _grasps(6, K=4, N=3)
    args = {"positions": P.copy(), "normals": Nrm.copy(), "mu": 0.5}
    change(args)
    kwargs = {k: v for k, v in args.items() if k not in ("positions", "normals", "mu")}
    with pytest.raises(error, match=match):
        batch_epsilon_l1(args["positions"], args["normals"], mu=args["mu"], **kwargs)


def test_without_numba_every_grasp_takes_the_qhull_route(monkeypatch):
    _, P, Nrm = _grasps(8, K=30, N=3)
    eps = batch_epsilon_l1(P, Nrm, mu=0.5)
    monkeypatch.setattr(epsilon_kernel, "AVAILABLE", False)
    Nn = Nrm / np.linalg.norm(Nrm, axis=-1, keepdims=True)
    K = P.shape[0]
    p = np.zeros((K, 3))
    slow, qhull = epsilon_l1_routes(
        P, Nn, np.full((K, 3), 0.5), np.zeros((K, 3)), p,
        batched_characteristic_lengths(P, p), contact_model="hard_finger",
        num_generators=8,
    )  # fmt: skip
    assert qhull.all()
    _close(slow, eps)


def test_more_primitive_wrenches_than_qhull_takes_are_refused():
    """The limit of ferrari_canny (L1_MAX_POINTS) holds here too, before any work."""
    rng = np.random.default_rng(1)
    P, Nrm = random_grasps(rng, 1, 251, 3)  # 251 × 8 = 2008 wrenches
    with pytest.raises(InvalidOptionError, match="L1_MAX_POINTS"):
        batch_epsilon_l1(P, Nrm, mu=0.5)
    # Without friction, 251 wrenches: computed (form closure of 251 contacts).
    _close(
        batch_epsilon_l1(P, Nrm, mu=0.0),
        batch_epsilon_l1(P, Nrm, mu=0.0, kernel="numpy"),
    )


def _stitched(ridges, D=3, point=9):
    """Run the kernel's sub-ridge matching on new facets ``ridge + point``."""
    count = len(ridges)
    verts = np.array([[*r, point] for r in ridges], dtype=np.int64)
    nbr = np.full((count, D), -1, dtype=np.int64)
    size = 64
    table = (np.zeros(size, dtype=np.int64), np.zeros(size, dtype=np.int64),
             np.zeros(size, dtype=np.int64), np.zeros(size, dtype=np.int8))  # fmt: skip
    ok = polytope._stitch(verts, nbr, 0, count, epsilon_kernel._hashes(10),
                                *table)  # fmt: skip
    return ok, nbr


def test_horizon_matching_links_a_cycle_and_rejects_a_branch():
    """In 3-D each horizon vertex must join exactly two ridges (a closed loop)."""
    ok, nbr = _stitched([(0, 1), (1, 2), (2, 0)])
    assert ok
    # Across slot q lies the facet sharing the other ridge vertex (and the point).
    assert nbr[:, :2].tolist() == [[1, 2], [2, 0], [0, 1]]
    ok, _ = _stitched([(0, 1), (0, 2), (0, 3)])  # vertex 0 in three ridges
    assert not ok
    ok, _ = _stitched([(0, 1), (1, 2)])  # an open chain
    assert not ok
