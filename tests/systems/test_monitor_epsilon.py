"""The monitor's ε: the batch engine's compiled kernel gives ferrari_canny's value.

Two routes to the same number: Qhull's whole hull of the primitive wrenches
(:func:`drakegrasp.ferrari_canny`) and the expanding polytope the monitor uses
(:func:`drakegrasp.systems.grasp_monitor.epsilon_l1`), on random grasps of 2
to 8 contacts (force closure or not, hard and soft fingers, planar and
spatial) and on the coplanar patch corners of flat pads.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import drakegrasp as dg
from drakegrasp.systems.grasp_monitor import epsilon_l1


def _grasp(seed, num, dim, model, mu):
    rng = np.random.default_rng(seed)
    contacts = []
    for _ in range(num):
        p = rng.normal(size=dim)
        p /= np.linalg.norm(p)
        n = -p + 0.5 * rng.normal(size=dim)
        nu = 0.05 if model == "soft_finger" else None
        contacts.append(
            dg.Contact(p, n, mu=mu, contact_model=model, torsional_friction=nu)
        )
    return dg.Grasp(contacts)


@settings(max_examples=60, derandomize=True, deadline=None)
@given(
    seed=st.integers(0, 2**31),
    num=st.integers(2, 8),
    dim=st.sampled_from([2, 3]),
    model=st.sampled_from(["hard_finger", "soft_finger"]),
    mu=st.sampled_from([0.2, 0.5, 1.0]),
)
def test_kernel_epsilon_is_ferrari_canny(seed, num, dim, model, mu):
    if dim == 2 and model == "soft_finger":
        model = "hard_finger"  # no torsion in the plane
    grasp = _grasp(seed, num, dim, model, mu)
    expected = dg.ferrari_canny(grasp, num_generators=8)
    assert epsilon_l1(grasp, num_generators=8) == pytest.approx(
        expected, rel=1e-9, abs=1e-12
    )


def test_flat_pads_with_eight_coplanar_corners():
    # Two square patches, four corners each, on opposite faces of a 5 cm box:
    # many coplanar wrenches, the degenerate case of the monitor's flat pads.
    corners = [(y, z) for y in (-0.01, 0.01) for z in (-0.01, 0.01)]
    contacts = [
        dg.Contact([s * 0.025, y, z], [-s, 0.0, 0.0], mu=1.0)
        for s in (1.0, -1.0)
        for y, z in corners
    ]
    grasp = dg.Grasp(contacts)
    expected = dg.ferrari_canny(grasp)
    assert expected > 0
    assert epsilon_l1(grasp, num_generators=8) == pytest.approx(expected, rel=1e-9)
