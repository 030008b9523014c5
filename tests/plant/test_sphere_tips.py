"""The vectorised contacts of spherical tips equal the scalar exact route's.

:func:`drakegrasp.plant.sphere_tips.sphere_tip_pairs` is the ``"core"`` route
of :func:`drakegrasp.plant.exact_contact.closest_pair` (a sphere's core is its
centre) written over arrays; each pair here is also run through the scalar
route, on faces, edges, corners, rims and caps, separated and penetrating,
and the two must agree to 1e-12 (points, normals, ψ), in the certificate and
in the normal's source.  A pair's result must not depend on the other pairs
in its batch.
"""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.geometry import Box, Convex, Cylinder, Sphere
from scipy.spatial.transform import Rotation

from drakegrasp.plant import models_dir
from drakegrasp.plant._shapes import surface_pieces
from drakegrasp.plant.contact_normals import clean_unit, normal_source
from drakegrasp.plant.exact_contact import closest_pair
from drakegrasp.plant.shape_queries import PosedShape
from drakegrasp.plant.sphere_tips import SOURCES, shape_key, sphere_tip_pairs

SHAPES = {
    "box": Box(0.06, 0.09, 0.17),
    "cylinder": Cylinder(0.033, 0.1),
    "sphere": Sphere(0.04),
    "hull": Convex(str(models_dir() / "objects" / "hex_prism.obj"), 1.3),
}
TIP = 0.002


def _cases(shape, rng, n=300):
    """Tip centres (frame O) near the posed shape, its pose, radii and ψ."""
    R = Rotation.random(random_state=rng).as_matrix()
    t = rng.normal(scale=0.3, size=3)
    A = PosedShape(shape, R, t)
    extent = 0.12
    centres, psis = [], []
    # points anywhere (faces, edges, corners, rims, caps), and snapped to
    # features: corners and edges exactly
    X = rng.uniform(-extent, extent, size=(n, 3))
    if isinstance(shape, Box):
        h = 0.5 * np.array([shape.width(), shape.depth(), shape.height()])
        X[: n // 3] = np.sign(X[: n // 3]) * (h + rng.uniform(0, 0.05, (n // 3, 3)))
    if isinstance(shape, Cylinder):
        X[: n // 4, 2] = np.sign(X[: n // 4, 2]) * 0.05  # on the caps' planes
    for x in X:
        sd, q, m = A.project(A.to_O(x))
        if abs(sd) < 1e-6:  # outward direction of a point on the surface
            m = A.R @ surface_pieces(shape, x, tol=1e-9)[0].normal_G
        # touching, within the tolerance, or the centre inside (deep overlap)
        psi = float(rng.choice([0.0, rng.uniform(-1e-4, 1e-4), -TIP - 3e-3]))
        centres.append(q + (TIP + psi) * m)
        psis.append(A.project(centres[-1])[0] - TIP)  # Drake's: the true ψ
    return R, t, np.array(centres), np.array(psis)


def _scalar(shape, R, t, c, psi_drake):
    A = PosedShape(shape, R, t)
    B = PosedShape(Sphere(TIP), np.eye(3), c)
    exact = closest_pair(A, B, p_a=c, p_b=c, nhat=np.array([0, 0, 1.0]), psi=psi_drake)
    if exact is None:
        return None
    source = normal_source(
        obj=surface_pieces(shape, A.to_G(exact.p_OCa), tol=1e-9),
        fin=surface_pieces(B.shape, B.to_G(exact.p_OCb), tol=1e-9),
    )
    return exact, clean_unit(exact.nhat_O), source


@pytest.mark.parametrize("name", sorted(SHAPES))
def test_tips_equal_the_scalar_exact_route(name):
    shape = SHAPES[name]
    rng = np.random.default_rng(18)
    R, t, c, psi = _cases(shape, rng)
    P = len(c)
    kind, dims = shape_key(shape)
    ok, psi_v, p_a, p_b, n, source = sphere_tip_pairs(
        kind, dims, np.repeat(R[None], P, 0), np.repeat(t[None], P, 0), c,
        np.full(P, TIP), psi,
    )  # fmt: skip
    sources = set()
    for k in range(P):
        ref = _scalar(shape, R, t, c[k], psi[k])
        assert ok[k] == (ref is not None), k
        if ref is None:
            continue
        exact, n_ref, src = ref
        assert abs(psi_v[k] - exact.psi) <= 1e-12
        np.testing.assert_allclose(p_a[k], exact.p_OCa, rtol=0, atol=1e-12)
        np.testing.assert_allclose(p_b[k], exact.p_OCb, rtol=0, atol=1e-12)
        np.testing.assert_allclose(clean_unit(n[k]), n_ref, rtol=0, atol=1e-12)
        assert SOURCES[source[k]] == src, k
        sources.add(src)
    assert ok.mean() > 0.9  # the cases are contacts, which certify
    assert (psi < -TIP).sum() > 50  # centres inside: the inside branches
    expected = {"sphere": {"object"}, "cylinder": {"object", "edge"}}
    assert sources >= expected.get(name, {"object", "edge", "corner"})


def test_a_pair_does_not_depend_on_its_batch():
    shape = SHAPES["box"]
    R, t, c, psi = _cases(shape, np.random.default_rng(3), n=60)
    kind, dims = shape_key(shape)
    P = len(c)
    whole = sphere_tip_pairs(
        kind, dims, np.repeat(R[None], P, 0), np.repeat(t[None], P, 0), c,
        np.full(P, TIP), psi,
    )  # fmt: skip
    for k in (0, 17, P - 1):
        one = sphere_tip_pairs(
            kind, dims, R[None], t[None], c[k : k + 1], np.full(1, TIP), psi[k : k + 1]
        )
        for a, b in zip(whole, one, strict=True):
            assert np.array_equal(a[k], b[0])


def test_a_far_drake_distance_is_not_certified():
    # the certificate asks ψ to agree with Drake's within 1 mm, as the scalar
    shape = SHAPES["cylinder"]
    R, t, c, psi = _cases(shape, np.random.default_rng(5), n=10)
    kind, dims = shape_key(shape)
    ok = sphere_tip_pairs(
        kind, dims, np.repeat(R[None], 10, 0), np.repeat(t[None], 10, 0), c,
        np.full(10, TIP), psi + 0.01,
    )[0]  # fmt: skip
    assert not ok.any()
    assert all(_scalar(shape, R, t, c[k], psi[k] + 0.01) is None for k in range(10))


def test_a_large_hull_is_taken_in_chunks(monkeypatch):
    from drakegrasp.plant import sphere_tips

    shape = SHAPES["hull"]
    R, t, c, psi = _cases(shape, np.random.default_rng(9), n=40)
    kind, dims = shape_key(shape)
    args = (np.repeat(R[None], 40, 0), np.repeat(t[None], 40, 0), c, np.full(40, TIP))
    whole = sphere_tip_pairs(kind, dims, *args, psi)
    monkeypatch.setattr(sphere_tips, "_CHUNK", 7 * len(dims.EA))  # 7 pairs a chunk
    chunked = sphere_tip_pairs(kind, dims, *args, psi)
    for a, b in zip(whole, chunked, strict=True):
        assert np.array_equal(a, b)


def test_other_shapes_have_no_closed_form_here():
    from pydrake.geometry import Capsule, Ellipsoid

    assert shape_key(Capsule(0.1, 0.2)) is None
    assert shape_key(Ellipsoid(0.1, 0.2, 0.3)) is None
    with pytest.raises(ValueError, match="Capsule"):
        sphere_tip_pairs(
            "Capsule", (0.1, 0.2), np.eye(3)[None], np.zeros((1, 3)),
            np.ones((1, 3)), np.ones(1), np.zeros(1),
        )  # fmt: skip
