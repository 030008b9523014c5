"""Grasps to test on and independent reference routes, shared by test folders.

The closure tests (payloads, grasp forces) and the quality tests build the same
grasps and check against the same brute-force routes; the ``helpers`` fixture
of ``tests/conftest.py`` hands these functions to a test.
"""

import itertools

import numpy as np

import drakegrasp as dg


def equator_grasp(mu=0.5, *, radius=1.0, model="hard_finger", **kwargs):
    """Three contacts 120° apart on a sphere's equator, normals to the centre."""
    contacts = []
    for t in np.deg2rad([0.0, 120.0, 240.0]):
        c = radius * np.array([np.cos(t), np.sin(t), 0.0])
        contacts.append(dg.Contact(c, -c, mu=mu, contact_model=model, **kwargs))
    return dg.Grasp(contacts)


def random_grasp(rng, num, dim=3, *, mu=0.5, spread=0.5, model="hard_finger", nu=None):
    """Contacts on the unit sphere/circle, normals tilted from the inward radial.

    A soft finger without ``nu`` gets ``nu = 0`` (it acts as a hard finger).
    """
    contacts = []
    for _ in range(num):
        p = rng.normal(size=dim)
        p /= np.linalg.norm(p)
        n = -p + spread * rng.normal(size=dim)
        if nu is None and model == "soft_finger":
            nu = 0.0
        contacts.append(
            dg.Contact(p, n, mu=mu, contact_model=model, torsional_friction=nu)
        )
    return dg.Grasp(contacts)


def brute_force_ball_radius(points, tol=1e-9):
    """ε of conv(points) by enumerating every hyperplane through D points.

    A hyperplane through D affinely independent points with every point on one
    side is a facet's; ε is the smallest distance from the origin to such a
    hyperplane (0 if the origin is not strictly inside).  Exponential, exact,
    and shares no code with Qhull.
    """
    P = np.asarray(points, dtype=float)
    K, D = P.shape
    idx = np.array(list(itertools.combinations(range(K), D)))
    diffs = P[idx[:, 1:]] - P[idx[:, :1]]  # (S, D-1, D)
    _, s, vt = np.linalg.svd(diffs)
    ok = s[:, -1] > 1e-9 * max(1.0, s[:, 0].max())
    normals = vt[ok, -1, :]  # unit, orthogonal to the D-1 differences
    offsets = np.einsum("sd,sd->s", normals, P[idx[ok, 0]])
    values = P @ normals.T - offsets  # (K, S)
    scale = np.abs(P).max()
    below = np.all(values <= tol * scale, axis=0)
    above = np.all(values >= -tol * scale, axis=0)
    dists = np.concatenate([offsets[below], -offsets[above]])
    if dists.size == 0:
        return 0.0
    return max(0.0, float(dists.min()))


def signed_permutation_rotations():
    """The 24 rotations that map coordinate axes onto coordinate axes."""
    out = []
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product([1.0, -1.0], repeat=3):
            R = np.zeros((3, 3))
            R[np.arange(3), perm] = signs
            if np.linalg.det(R) > 0:
                out.append(R)
    return out


def moved_grasp(grasp, R, t):
    """The grasp rigidly moved by x -> R x + t, reference point moved along."""
    contacts = [
        c.with_(position=R @ c.position + t, normal=R @ c.normal)
        for c in grasp.contacts
    ]
    return dg.Grasp(
        contacts,
        reference_point=R @ grasp.reference_point + t,
        characteristic_length=grasp.characteristic_length,
    )


def two_pads(rng, K, half):
    """``K`` grasps of two pads of ``half`` contacts each across x = ±0.03 m.

    Returns ``(P, Nrm, F)``: (K, 2 half, 3) points drawn from ``rng`` on the
    faces x = ∓0.03 of a 6 cm cube, their inward normals, and finger labels
    0 and 1.
    """
    y = rng.uniform(-0.02, 0.02, (K, 2 * half))
    z = rng.uniform(-0.02, 0.02, (K, 2 * half))
    x = np.where(np.arange(2 * half) < half, -0.03, 0.03) * np.ones((K, 1))
    P = np.stack([x, y, z], axis=-1)
    Nrm = np.zeros_like(P)
    Nrm[..., 0] = -np.sign(x)
    F = np.repeat((np.arange(2 * half) >= half)[None].astype(int), K, axis=0)
    return P, Nrm, F


def generator_matrix(grasp, num_generators=8):
    """``S``: the contacts' cone generators block by block, ``f = S λ``, λ >= 0.

    Rows the grasp's contact components, columns each contact's generators
    (:func:`drakegrasp.core.friction_cone.friction_cone_generators`).
    """
    from drakegrasp.core.friction_cone import friction_cone_generators

    blocks = [friction_cone_generators(c, num_generators) for c in grasp.contacts]
    S = np.zeros((sum(b.shape[0] for b in blocks), sum(b.shape[1] for b in blocks)))
    r = c = 0
    for b in blocks:
        S[r : r + b.shape[0], c : c + b.shape[1]] = b
        r, c = r + b.shape[0], c + b.shape[1]
    return S
