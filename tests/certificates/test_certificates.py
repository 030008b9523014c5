"""Certificates of every verdict, re-verified by routes that share no code with them.

Escape twists are checked by evaluating ``G_nᵀ v`` directly; unresisted wrenches
by a separate LP (scipy's HiGHS, written here) that maximises ``wᵀ G f`` over the
polyhedral cones, or by the closed-form support of the exact cones written here;
LP3's forces by their residuals.
"""

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

import drakegrasp as dg
from drakegrasp.certificates.certificate import ESCAPE_TWIST, UNRESISTED_WRENCH
from drakegrasp.certificates.witness import unresisted_wrench
from drakegrasp.core import examples as ex

SPATIAL_MODELS = [
    ("frictionless", 0.5, 0.0),
    ("hard_finger", 0.0, 0.0),
    ("hard_finger", 0.3, 0.0),
    ("soft_finger", 0.3, 0.2),
    ("soft_finger", 0.0, 0.2),
]
PLANAR_MODELS = [("frictionless", 0.5, 0.0), ("hard_finger", 0.2, 0.0)]


def _random_grasps(rng, make_contacts, count):
    """Seeded random grasps of every model, spatial and planar, mostly failing."""
    out = []
    for k in range(count):
        planar = k % 3 == 0
        models = PLANAR_MODELS if planar else SPATIAL_MODELS
        model, mu, nu = models[k % len(models)]
        num = int(rng.integers(2, 5 if planar else 6))
        contacts = make_contacts(
            rng, num, 2 if planar else 3, mu=mu, model=model, nu=nu, tilt=0.6 * 1.5
        )
        # a reference point away from the contacts exercises the frame mapping
        p = rng.normal(size=2 if planar else 3) * 0.7
        out.append(dg.Grasp(contacts, reference_point=p))
    return out


def _stacked_G(grasp, num_generators=8):
    """``G S`` over every contact's generators, with the generators' f_n = 1."""
    blocks, normals = [], []
    G = dg.grasp_matrix(grasp)
    b = grasp.characteristic_length
    for s, c in zip(grasp.component_slices(), grasp.contacts, strict=True):
        S = dg.friction_cone_generators(c, num_generators, characteristic_length=b)
        blocks.append(G[:, s] @ S)
        normals.append(np.ones(S.shape[1]))
    return np.hstack(blocks), np.concatenate(normals)


def _lp_max_power(grasp, w, num_generators=8):
    """Independent LP: max wᵀ G f over the polyhedral cones with Σ f_n <= 1."""
    GS, normals = _stacked_G(grasp, num_generators)
    res = linprog(
        -(w @ GS), A_ub=normals[None, :], b_ub=[1.0], bounds=(0, None), method="highs"
    )
    assert res.status == 0
    return -res.fun


def _exact_support(grasp, w):
    """Closed-form max of wᵀ G_i f_i over each exact cone with f_n = 1."""
    G = dg.grasp_matrix(grasp)
    b = grasp.characteristic_length
    out = []
    for s, c in zip(grasp.component_slices(), grasp.contacts, strict=True):
        a = G[:, s].T @ w
        if (
            c.contact_model is dg.ContactModel.FRICTIONLESS
            or c.mu == 0.0
            and len(a) < 4
        ):
            out.append(a[0])
        elif len(a) == 2:  # planar: the two edges of the cone
            out.append(a[0] + c.mu * abs(a[1]))
        elif len(a) == 3:
            out.append(a[0] + c.mu * np.linalg.norm(a[1:]))
        else:
            out.append(
                a[0]
                + max(
                    c.mu * np.linalg.norm(a[1:3]), b * c.torsional_friction * abs(a[3])
                )
            )
    return np.array(out)


def _pairs(cert):
    """(hyperplane normal, unresisted wrench) pairs of a wrench certificate."""
    ys = [cert.separating_twist, *cert.separating_basis.T]
    ws = [cert.direction, *cert.null_basis.T]
    return list(zip(ys, ws, strict=True))


def _scale(grasp, w):
    return np.linalg.norm(dg.grasp_matrix(grasp), 2) * np.linalg.norm(w)


def test_every_no_carries_a_witness_that_an_independent_route_confirms(
    rng, make_contacts
):
    grasps = _random_grasps(rng, make_contacts, 600)
    checked = {"form": 0, "facets": 0, "generators": 0, "exact": 0}
    worst = 0.0
    for g in grasps:
        r = dg.form_closure(g)
        if not r.is_closure:
            cert = r.certificate
            assert cert is not None and cert.kind == ESCAPE_TWIST
            G_n = dg.normal_grasp_matrix(g)
            for v in [cert.direction, *cert.null_basis.T]:
                rates = G_n.T @ v / _scale(g, v)
                assert np.linalg.norm(v) > 0
                worst = max(worst, -rates.min())
                if cert.two_sided:
                    worst = max(worst, np.abs(rates).max())
            assert cert.check(g).holds
            checked["form"] += 1
        for formulation in ("facets", "generators"):
            r = dg.force_closure(g, formulation=formulation)
            if r.is_closure:
                continue
            cert = r.certificate
            assert cert is not None and cert.kind == UNRESISTED_WRENCH
            for y, w in _pairs(cert):
                assert y @ w > 0  # the unresisted wrench is beyond the plane
                signs = (y, -y) if cert.two_sided else (y,)
                for x in signs:
                    worst = max(worst, _lp_max_power(g, x) / _scale(g, x))
            assert cert.check(g).holds
            checked[formulation] += 1
        r = dg.force_closure_exact(g)
        if not r.is_closure:
            cert = r.certificate
            assert cert is not None and cert.cones == "exact"
            for y, w in _pairs(cert):
                assert y @ w > 0
                signs = (y, -y) if cert.two_sided else (y,)
                for x in signs:
                    worst = max(worst, _exact_support(g, x).max() / _scale(g, x))
            assert cert.check(g).holds
            checked["exact"] += 1
    print("witnesses checked:", checked, "largest relative violation:", worst)
    assert min(checked.values()) >= 300
    assert sum(checked.values()) >= 500
    assert worst < 1e-7


def test_every_yes_certificate_balances_inside_the_cones(rng, make_contacts):
    count = 0
    for mu in (0.4, 0.8):
        for _ in range(60):
            g = dg.Grasp(make_contacts(rng, 4, 3, mu=mu, tilt=0.6 * 0.3))
            for fn in (dg.force_closure, dg.force_closure_exact):
                r = fn(g)
                if not r.is_closure:
                    continue
                count += 1
                chk = r.certificate.check(g)
                assert chk.holds and chk.slack > 0
                f = r.certificate.stacked_forces()
                assert np.allclose(dg.grasp_matrix(g) @ f, 0, atol=1e-8)
                basis = r.certificate.internal_basis
                # the basis spans N(G) over the allowed components: G B = 0, and f in it
                assert np.allclose(dg.grasp_matrix(g) @ basis, 0, atol=1e-8)
                coef = np.linalg.lstsq(basis, f, rcond=None)[0]
                assert np.allclose(basis @ coef, f, atol=1e-8)
                # and no separating direction exists (Stiemke's other side)
                cones = "exact" if fn is dg.force_closure_exact else "polyhedral"
                assert unresisted_wrench(g, r.rank, cones=cones) is None
    assert count > 50


def test_the_normal_force_route_certificate_holds_where_g_n_is_short():
    # equator fingers with almost no friction: the normals balance, G has full
    # rank through the (tiny) friction, G_n has rank 2
    g = ex.equator_fingers(1e-8)
    for fn in (dg.force_closure, dg.force_closure_exact):
        r = fn(g)
        assert r.is_closure and r.decided_by == "normal forces"
        chk = r.certificate.check(g)
        assert chk.holds and chk.slack > 0, chk


def test_a_wrong_witness_fails_the_check():
    g = ex.planar_two_finger_square(0.2)
    cert = dg.force_closure(g).certificate
    flipped = dataclasses.replace(cert, direction=-cert.direction)
    assert cert.check(g).holds and not flipped.check(g).holds
    tilted = dataclasses.replace(cert, separating_twist=-cert.separating_twist)
    assert not tilted.check(g).holds
    fc = dg.form_closure(g).certificate
    # a twist that pushes the object into the left finger
    bad = dataclasses.replace(
        fc, direction=np.array([-1.0, 0.0, 0.0]), null_basis=np.zeros((3, 0))
    )
    assert not bad.check(g).holds


def test_a_disc_always_rotates_about_its_centre():
    centre = np.array([0.3, -0.2])
    angles = np.array([0.1, 2.0, 4.0])
    contacts = [
        dg.Contact(
            centre + 0.05 * np.array([np.cos(a), np.sin(a)]),
            -np.array([np.cos(a), np.sin(a)]),
            contact_model="frictionless",
        )
        for a in angles
    ]
    g = dg.Grasp(contacts)
    r = dg.form_closure(g)
    assert not r.is_closure and r.decided_by == "rank"
    cert = r.certificate
    assert cert.two_sided and cert.null_basis.shape[1] == 1
    v = cert.direction
    from drakegrasp.certificates.text import screw_point

    assert np.allclose(screw_point(g.reference_point, v[:2], v[2:]), centre)
    assert "rotate" in cert.describe() and "(0.3, -0.2)" in cert.describe()
    assert cert.sliding().all()
    # spatial: a sphere held by four frictionless fingers turns about its centre
    sphere = dg.Grasp(
        [
            dg.Contact(c, -np.asarray(c, float), contact_model="frictionless")
            for c in ([1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, 0, 1])
        ],
        reference_point=[0.5, 0.5, 0.5],
    )
    cert = dg.form_closure(sphere).certificate
    assert cert.null_basis.shape[1] >= 3
    for v in cert.null_basis.T:  # every escape is a rotation about the centre
        w_part = v[3:]
        v_centre = v[:3] + np.cross(w_part, np.zeros(3) - sphere.reference_point)
        assert np.allclose(v_centre, 0, atol=1e-9)


def test_a_box_between_two_frictionless_fingers_slides_in_their_face_plane():
    g = ex.spatial_two_fingers(0.0, contact_model="frictionless")
    r = dg.form_closure(g)
    cert = r.certificate
    assert not r.is_closure and cert.two_sided
    B = cert.null_basis
    for t in ([0, 1, 0, 0, 0, 0], [0, 0, 1, 0, 0, 0]):  # slide along y and z
        coef = np.linalg.lstsq(B, np.array(t, float), rcond=None)[0]
        assert np.allclose(B @ coef, t, atol=1e-9)
    assert "translate along ±y" in cert.describe()  # axis directions come first
    # pushing along x is not an escape: it penetrates a finger
    coef = np.linalg.lstsq(B, np.eye(6)[0], rcond=None)[0]
    assert not np.allclose(B @ coef, np.eye(6)[0], atol=1e-3)


def test_full_rank_escape_reports_which_contacts_separate():
    # a box on two supports with one finger on its left side: it can lift off
    g = dg.Grasp(
        [
            dg.Contact([-1, 0], [0, 1], contact_model="frictionless"),
            dg.Contact([1, 0], [0, 1], contact_model="frictionless"),
            dg.Contact([-1, 0.5], [1, 0], contact_model="frictionless"),
        ]
    )
    r = dg.form_closure(g)
    assert r.rank == 3 and not r.is_closure and r.decided_by == "d*"
    cert = r.certificate
    assert not cert.two_sided and cert.separating().any()
    assert "separate" in cert.describe()
    rates = dg.normal_grasp_matrix(g).T @ cert.direction
    assert np.array_equal(cert.separating(), rates > 1e-9)


def test_lp3_failure_carries_the_uncontrollable_squeeze():
    g = ex.equator_fingers(0.5)
    J = np.zeros((g.num_components, g.num_contacts))
    for i, s in enumerate(g.component_slices()):
        J[s, i] = [0.0, 1.0, 0.0]  # joints only slide the tips tangentially
    r = dg.force_closure(g, hand_jacobian=J)
    assert r.frictional_closure and not r.is_closure and r.decided_by == "LP3"
    cert = r.certificate
    assert cert is r.internal_forces.certificate
    chk = cert.check(g, hand_jacobian=J)
    assert chk.holds and chk.slack > 0.1
    f = cert.stacked_forces()
    assert np.allclose(J.T @ f, 0) and np.allclose(dg.grasp_matrix(g) @ f, 0)
    with pytest.raises(dg.GraspError, match="hand_jacobian"):
        cert.check(g)
    with pytest.raises(TypeError, match="decided_by"):
        _ = cert == "normal forces"


def test_two_hard_fingers_cannot_resist_a_moment_about_their_line():
    g = dg.Grasp(ex.spatial_two_fingers(0.5).contacts, reference_point=[0.3, -0.2, 0.1])
    r = dg.force_closure(g)
    assert r.decided_by == "rank" and r.certificate.two_sided
    w = r.certificate.direction
    assert np.allclose(w[:3], 0, atol=1e-12)  # a pure moment, wherever p is
    assert abs(abs(w[3]) - np.linalg.norm(w[3:])) < 1e-12  # about x
    assert "cannot resist a moment about ±x" in r.certificate.describe()


def test_certificates_are_invariant_to_units_and_reference_point(rng, make_contacts):
    for _ in range(20):
        contacts = make_contacts(rng, 3, 3, mu=0.3, tilt=0.6 * 1.5)
        g = dg.Grasp(contacts)
        r = dg.force_closure(g)
        if r.is_closure:
            continue
        scaled = dg.Grasp(
            [c.with_(position=1e3 * c.position) for c in contacts],
            reference_point=[1e3, 0, 0],
        )
        r2 = dg.force_closure(scaled)
        assert not r2.is_closure and r2.certificate.check(scaled).holds
        assert r.certificate.check(g).holds


def _adjoint(R, t):
    """Map a twist [v_p; ω] about p to the moved frame (p moves to R p + t)."""
    A = np.zeros((6, 6))
    A[:3, :3] = A[3:, 3:] = R
    return A


@settings(max_examples=40, deadline=None, derandomize=True)
@given(seed=st.integers(0, 10**6))
def test_a_witness_moves_with_the_grasp(seed):
    """Rigidly moving the grasp (and p) rotates its witnesses, nothing else."""
    rng = np.random.default_rng(seed)
    contacts = []
    for _ in range(int(rng.integers(2, 5))):
        c = rng.normal(size=3)
        c /= np.linalg.norm(c)
        contacts.append(dg.Contact(c, -c + rng.normal(size=3), mu=0.3))
    p = rng.normal(size=3)
    g = dg.Grasp(contacts, reference_point=p)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    R = q * np.sign(np.linalg.det(q))
    t = rng.normal(size=3)
    moved = dg.Grasp(
        [x.with_(position=R @ x.position + t, normal=R @ x.normal) for x in contacts],
        reference_point=R @ p + t,
    )
    A = _adjoint(R, t)
    for fn in (dg.form_closure, dg.force_closure, dg.force_closure_exact):
        cert = fn(g).certificate
        if cert is None or cert.kind == "balancing internal force":
            continue
        changes = {
            "direction": A @ cert.direction,
            "null_basis": A @ cert.null_basis,
            "reference_point": R @ p + t,
        }
        if cert.separating_twist is not None:
            changes["separating_twist"] = A @ cert.separating_twist
            changes["separating_basis"] = A @ cert.separating_basis
        assert dataclasses.replace(cert, **changes).check(moved).holds
