"""Report lines that say what decided each verdict, and why a "no" is a no."""

import json

import numpy as np

import drakegrasp as dg
from drakegrasp.cli import main
from drakegrasp.core import examples as ex


def _lines(result):
    return str(result).splitlines()


def test_a_rank_verdict_shows_no_margin():
    r = dg.form_closure(ex.spatial_two_fingers(0.5))
    head = _lines(r)[0]
    assert head.startswith("form closure: no, decided by rank: rank 1/6 < 6")
    assert "margin" not in str(r) and "not used" in head


def test_a_d_star_verdict_shows_its_margin_and_a_no_shows_why():
    yes = dg.force_closure(ex.planar_two_finger_square(0.8))
    assert "decided by d* = 0.234 > tol" in _lines(yes)[0]
    assert "margin +2.34e+05 tol" in _lines(yes)[0] and "why" not in str(yes)
    no = dg.force_closure(ex.planar_two_finger_square(0.2))
    assert "decided by d* = 0 (solver zero) <= tol" in _lines(no)[0]
    assert _lines(no)[1] == "  why: cannot resist a counter-clockwise moment"
    assert no.to_dict()["why"] == "cannot resist a counter-clockwise moment"


def test_the_normal_force_route_says_lp2_did_not_decide():
    g = ex.planar_square_four_contacts().with_friction(
        1e-9, contact_model="hard_finger"
    )
    r = dg.force_closure(g)
    assert r.decided_by == "normal forces"
    assert "did not decide" in _lines(r)[0]


def test_lp3_and_the_null_space_condition_have_two_names():
    # A hand that drives only finger 0 of the equator grasp, along its normal:
    # dim N(G) ∩ N(Jᵀ) = 3 - 1 = 2, but no squeeze with every f_n > 0 escapes
    # it (f_n of finger 0 is what the joint feels), so LP3 passes.
    g = ex.equator_fingers(0.5)
    J = np.zeros((g.num_components, 1))
    J[0, 0] = 1.0
    r = dg.force_closure(g, hand_jacobian=J)
    lp3 = r.internal_forces
    assert lp3.passes and lp3.null_space_dim == 2 and r.is_closure
    text = str(r)
    assert "LP3 (uncontrollable squeezing): passes" in text
    assert "dim N(G) ∩ N(Jᵀ) = 2 (null-space condition: fails" in text
    assert "not used by the verdict" in text
    # the solver's 1e-10 is reported as a zero, not as a value that passed
    assert "d* = 0 (solver zero) <= tol" in text


def test_antipodal_at_mu_zero_says_it_is_on_the_boundary_and_not_sufficient():
    a = dg.is_antipodal(ex.spatial_two_fingers(0.0))
    text = str(a)
    assert "YES" in text and "on the cone boundary" in text
    assert "necessary, not sufficient" in text
    assert "needs mu >=" not in text


def test_analyze_prints_why_and_json_carries_the_certificate(capsys):
    assert main(["analyze"]) == 0
    out = capsys.readouterr().out
    assert "form closure: no, decided by rank" in out
    assert (
        "why: the object can translate along ±x without penetrating any finger" in out
    )
    assert "why: cannot resist a moment about ±y" in out
    assert "LP3 (uncontrollable squeezing)" in out and "dim N(G) ∩ N(Jᵀ)" in out
    assert "re-checked: witness holds" in out
    assert main(["analyze", "three_finger_sphere", "--mu", "0", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    fc = data["force_closure"]
    assert fc["is_closure"] is False and fc["decided_by"] == "rank"
    assert fc["certificate"]["kind"] == "unresisted wrench"
    assert len(fc["certificate"]["direction"]) == 6
    assert fc["why"].startswith("cannot resist a force along ±z through (0, 0, 0) m")
