"""An LP3 "no" says how hard its squeeze presses along the surfaces.

LP3 bounds the normal components only (the chapter's test): two prismatic
fingers whose pads are tilted by a hair from their joint axes have an
uncontrollable squeeze whose tangential forces are ``1 / tan(tilt)`` times
its normal ones, far outside any friction cone.  The "why" said only
"normal forces (1, 1, 1, 1) N", which reads as a squeeze the contacts can
carry.  The second route is the certificate's own forces.
"""

from __future__ import annotations

import numpy as np
import pytest

import drakegrasp as dg


def _tilted_jaw(tilt: float):
    """Two one-joint fingers along ±y, two contacts each, normals tilted about x."""
    contacts = []
    for s in (-1.0, 1.0):  # the left finger, at y = +25 mm, pushes along -y
        for z, t in ((0.01, tilt), (-0.01, -tilt)):
            n = [0.0, s * np.cos(t), np.sin(t)]
            contacts.append(dg.Contact([0.0, -s * 0.025, z], n, mu=0.5))
    grasp = dg.Grasp(contacts)
    J = np.zeros((12, 2))
    for i, c in enumerate(grasp.contacts):
        axis = np.array([0.0, -1.0 if i < 2 else 1.0, 0.0])
        J[3 * i : 3 * i + 3, i // 2] = np.asarray(c.frame).T @ axis
    return grasp, J


@pytest.mark.parametrize("degrees", [0.01, 1.0, 8.0])
def test_the_squeeze_says_how_much_friction_it_needs(degrees):
    grasp, J = _tilted_jaw(np.radians(degrees))
    result = dg.force_closure(grasp, hand_jacobian=J)
    assert result.decided_by == "LP3"
    forces = np.array(result.certificate.contact_forces)
    ratio = np.max(np.linalg.norm(forces[:, 1:], axis=1) / forces[:, 0])
    assert ratio == pytest.approx(1 / np.tan(np.radians(degrees)), rel=1e-3)
    assert f"presses {ratio:.3g} times harder along the surfaces" in result.why()


def test_a_squeeze_within_friction_says_nothing_of_it():
    # three fingers on a sphere's equator, the hand driving none: the squeeze
    # is along the normals (no tangential force)
    contacts = [
        dg.Contact([np.cos(a), np.sin(a), 0.0], [-np.cos(a), -np.sin(a), 0.0], mu=0.5)
        for a in 2 * np.pi * np.arange(3) / 3
    ]
    grasp = dg.Grasp(contacts)
    result = dg.force_closure(grasp, hand_jacobian=np.zeros((9, 1)))
    assert result.decided_by == "LP3"
    assert "along the surfaces" not in result.why()
