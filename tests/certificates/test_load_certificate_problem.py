"""Review r22: a load certificate is checked against the caller's problem.

A payload bound is a claim about a load and limits.  ``check`` proved it about
the certificate's own copies of them, so a certificate whose limits were edited
"proved" a payload ten times too low for this grasp.  The caller can now pass
the problem's load and limits (the same multipliers price any limits), the
detail line states which load and limits the proof is about, and a certificate
read back from its JSON (``inf`` written as None) checks as the original.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

import drakegrasp as dg
from drakegrasp.certificates.load import LoadCertificate

W = np.array([0.0, 0.0, -9.81, 0.0, 0.0, 0.0])


@pytest.fixture(scope="module")
def pinch():
    g = dg.Grasp(
        [
            dg.Contact([-0.05, 0, 0], [1, 0, 0], mu=0.5),
            dg.Contact([0.05, 0, 0], [-1, 0, 0], mu=0.5),
        ]
    )
    r = dg.max_load(g, W, max_normal_force=10)
    # Independent route: two fingers of 10 N with mu = 0.5 carry 2 x 5 N.
    assert r.alpha == pytest.approx(10 / 9.81, rel=1e-6)
    return g, r.certificate


def test_edited_limits_fail_against_the_callers_limits(pinch):
    g, cert = pinch
    forged = dataclasses.replace(
        cert, max_normal_force=np.array([1.0, 1.0]), bound=cert.bound / 10
    )
    assert forged.check(g).holds  # true of the edited limits, and it says so
    assert "f_max = 1 (x2)" in forged.check(g).detail
    mine = forged.check(g, max_normal_force=10)
    assert not mine.holds and mine.violation == pytest.approx(0.9, rel=1e-6)
    assert "the caller's where given" in mine.detail
    assert "f_max = 10 (x2)" in mine.detail
    # The genuine certificate holds against the same limits.
    assert cert.check(g, max_normal_force=[10, 10], wrench=W).holds


def test_an_edited_load_fails_against_the_callers_load(pinch):
    g, cert = pinch
    forged = dataclasses.replace(cert, wrench=10 * W, bound=cert.bound / 10)
    assert forged.check(g).holds
    assert not forged.check(g, wrench=W).holds


def test_looser_limits_of_the_caller_refute_the_bound(pinch):
    # The multipliers price any limits: with 20 N the proven bound doubles,
    # so the certificate's bound (for 10 N) is not proven for 20 N ...
    g, cert = pinch
    assert not cert.check(g, max_normal_force=20).holds
    # ... and tighter limits (5 N) keep it proven (a lower payload is implied).
    assert cert.check(g, max_normal_force=5).holds


def test_a_certificate_read_back_from_json_checks_as_the_original(pinch):
    g, cert = pinch
    back = LoadCertificate(**json.loads(json.dumps(cert.to_dict())))
    assert back.max_squeeze is None  # inf was written as None
    assert back.check(g).holds == cert.check(g).holds is True
    # A limit with an entry of inf, and a squeeze bound.
    r = dg.max_load(g, W, max_normal_force=[10, np.inf], max_squeeze=15)
    d = json.loads(json.dumps(r.certificate.to_dict()))
    assert d["max_normal_force"] == [10.0, None]
    back = LoadCertificate(**d)
    original, read = r.certificate.check(g), back.check(g)
    assert original.holds and read.holds
    assert read.violation == original.violation and read.slack == original.slack


def test_a_failed_check_states_no_negative_reach(pinch):
    g, cert = pinch
    # LOAD_NOT_HELD for a load that is held: the power does not exceed the
    # budget, and the caveat printed a negative total normal force.
    wrong = dataclasses.replace(cert, kind="load not held", bound=0.5)
    got = wrong.check(g)
    assert not got.holds
    assert "Σ f_n < -" not in got.detail


def test_hostile_problem_arguments_are_named(pinch):
    g, cert = pinch
    with pytest.raises(dg.InvalidOptionError, match="max_normal_force"):
        cert.check(g, max_normal_force=[1.0, 2.0, 3.0])
    with pytest.raises(dg.InvalidOptionError, match="wrench"):
        cert.check(g, wrench=[1.0, 2.0])
    with pytest.raises(dg.InvalidOptionError, match="max_squeeze"):
        cert.check(g, max_squeeze="a lot")
