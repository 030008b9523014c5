"""GraspQuality / grasp_quality and LP2's d* as a metric."""

import json

import numpy as np
import pytest
from scipy.optimize import linprog

import drakegrasp as dg
from drakegrasp.closure.verdicts import force_closure
from drakegrasp.quality import (
    GraspQuality,
    ferrari_canny,
    grasp_quality,
    grasp_singular_values,
    hand_object_singular_values,
    lp2_d_star,
    lp2_margin,
)


def _lp2_by_linprog(grasp, n_g=8):
    """LP2 (docs/conventions.md) written out for scipy/HiGHS, facets form."""
    G = dg.grasp_matrix(grasp)
    blocks = [dg.friction_cone_facets(c, n_g) for c in grasp.contacts]
    F = np.zeros((sum(b.shape[0] for b in blocks), G.shape[1]))
    r = 0
    for b, sl in zip(blocks, grasp.component_slices(), strict=True):
        F[r : r + b.shape[0], sl] = b
        r += b.shape[0]
    m = G.shape[1]
    normal = np.zeros(m)
    normal[grasp.normal_indices()] = 1.0
    c = np.zeros(m + 1)
    c[-1] = -1.0
    A_ub = np.vstack(
        [np.hstack([-F, np.ones((F.shape[0], 1))]), np.append(normal, 0.0)[None]]
    )
    b_ub = np.append(np.zeros(F.shape[0]), grasp.num_contacts)
    A_eq = np.hstack([G, np.zeros((G.shape[0], 1))])
    res = linprog(
        c,
        A_ub=A_ub,
        b_ub=b_ub,
        A_eq=A_eq,
        b_eq=np.zeros(G.shape[0]),
        bounds=[(None, None)] * m + [(0, None)],
        method="highs",
    )
    assert res.status == 0
    return res.x[-1]


def test_lp2_d_star_against_scipy(helpers, rng):
    grasps = [helpers.equator_grasp(0.5)] + [
        helpers.random_grasp(rng, 3, 3, mu=0.6, spread=0.3) for _ in range(4)
    ]
    for g in grasps:
        assert lp2_d_star(g) == pytest.approx(_lp2_by_linprog(g), abs=1e-7)


def test_lp2_d_star_grows_with_mu(helpers):
    g = helpers.equator_grasp(0.5)
    values = [lp2_d_star(g.with_friction(mu)) for mu in (0.0, 0.2, 0.5, 1.0)]
    # μ = 0: frictionless, LP2 is LP1, and the three normals balance with
    # f_n = 1 each, so d* = 1.  For μ > 0, d* is the distance to the cone
    # boundaries (0 at μ -> 0+) and grows with μ.
    assert values[0] == pytest.approx(1.0, abs=1e-9)
    assert np.all(np.diff(values[1:]) > 0)


def test_summary_matches_individual_metrics(helpers):
    g = helpers.equator_grasp(0.5)
    q = grasp_quality(g, linf=True)
    assert isinstance(q, GraspQuality)
    assert q.ferrari_canny_l1 == pytest.approx(ferrari_canny(g))
    assert q.ferrari_canny_linf == pytest.approx(ferrari_canny(g, norm="Linf"))
    assert q.lp2_d_star == pytest.approx(force_closure(g).d_star)
    assert q.is_force_closure
    assert np.allclose(q.singular_values, grasp_singular_values(g))
    assert q.min_singular_value == pytest.approx(np.sqrt(1.5))
    assert q.isotropy == pytest.approx(np.sqrt(0.5))
    assert q.wrench_ellipsoid_volume == pytest.approx(13.5)
    assert q.torque_scale == g.characteristic_length
    assert q.hand_singular_values is None and q.distance_to_singularity is None
    # L∞ by default only when cheap (planar, or at most three spatial contacts).
    assert grasp_quality(g).ferrari_canny_linf == q.ferrari_canny_linf
    assert grasp_quality(g, linf=False).ferrari_canny_linf is None
    four = dg.Grasp([*g.contacts, dg.Contact([0, 0, 1.0], [0, 0, -1.0], mu=0.5)])
    assert grasp_quality(four).ferrari_canny_linf is None


def test_summary_with_hand_and_json(helpers, rng):
    g = helpers.random_grasp(rng, 3, 3, mu=0.8, spread=0.3)
    J = rng.normal(size=(g.num_components, 7))
    q = grasp_quality(g, hand_jacobian=J, torque_scale=0.5)
    sh = hand_object_singular_values(g, J, torque_scale=0.5)
    assert np.allclose(q.hand_singular_values, sh)
    assert q.distance_to_singularity == pytest.approx(sh[-1])
    assert q.uniformity_of_transformation == pytest.approx(sh[0] / sh[-1])
    assert q.manipulability_volume == pytest.approx(np.prod(sh))
    assert q.is_force_closure == force_closure(g, hand_jacobian=J).is_closure
    d = json.loads(json.dumps(q.to_dict()))
    assert d["torque_scale"] == 0.5
    assert len(d["singular_values"]) == 6
    text = str(q)
    assert "Ferrari-Canny" in text and "H:" in text


def test_summary_of_a_singular_hand_is_json_ready(helpers):
    g = helpers.equator_grasp(0.5)
    J = np.zeros((g.num_components, 2))
    J[0, 0] = 1.0
    q = grasp_quality(g, hand_jacobian=J)
    assert q.uniformity_of_transformation == np.inf
    assert q.to_dict()["uniformity_of_transformation"] is None
    with pytest.raises(AttributeError):
        q.isotropy = 1.0


def test_summary_bad_inputs(helpers):
    g = helpers.equator_grasp(0.5)
    with pytest.raises(dg.InvalidGraspError, match="hand_jacobian"):
        grasp_quality(g, hand_jacobian=np.ones((3, 3)))
    with pytest.raises(dg.InvalidOptionError, match="torque_scale"):
        grasp_quality(g, torque_scale=0.0)
    with pytest.raises(dg.InvalidGraspError):
        lp2_d_star("not a grasp")


def test_lp2_margin_is_a_warning_name_of_lp2_d_star(helpers):
    """It returns ``d*``, while a result's ``margin`` is ``(d* - tol) / tol``."""
    g = helpers.equator_grasp(0.5)
    q = grasp_quality(g)
    with pytest.warns(DeprecationWarning, match="lp2_d_star"):
        assert lp2_margin(g) == lp2_d_star(g) == q.lp2_d_star
    with pytest.warns(DeprecationWarning, match="lp2_d_star"):
        assert q.lp2_margin == q.lp2_d_star
    assert "lp2_d_star" in q.to_dict() and "lp2_margin" not in q.to_dict()
    assert q.lp2_d_star != force_closure(g).margin
