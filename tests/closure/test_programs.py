"""The build_* functions return programs a user can inspect and extend."""

import numpy as np
from pydrake.solvers import ClpSolver

import drakegrasp as dg
from drakegrasp.core import examples as ex


def test_lp2_program_shape_follows_the_conventions():
    grasp = ex.equator_fingers(0.5)
    prog, v = dg.build_force_closure_program(grasp, num_generators=8)
    assert prog.num_vars() == 9 + 1 and len(v.forces) == 9
    assert np.array_equal(v.columns, np.arange(9))
    # G f = 0 is imposed as V_r^T f = 0: orthonormal rows spanning G's rows.
    A = prog.linear_equality_constraints()[0].evaluator().GetDenseA()
    G = dg.grasp_matrix(grasp)
    assert A.shape == (6, 9) and np.allclose(A @ A.T, np.eye(6))
    assert np.allclose(np.linalg.pinv(A) @ A, np.linalg.pinv(G) @ G)
    ineq = [c.evaluator() for c in prog.linear_constraints()]
    assert sum(c.num_constraints() for c in ineq) == 3 * 8 + 1


def test_mu_zero_contacts_have_no_tangential_variables():
    grasp = ex.equator_fingers(0.0)
    prog, v = dg.build_force_closure_program(grasp)
    assert len(v.forces) == 3 and np.array_equal(v.columns, [0, 3, 6])


def test_a_user_can_extend_and_solve_the_program():
    grasp = ex.equator_fingers(0.5)
    prog, v = dg.build_force_closure_program(grasp)
    base = ClpSolver().Solve(prog)
    prog.AddBoundingBoxConstraint(0, 0.2, v.forces[0])  # limit finger 0's push
    limited = ClpSolver().Solve(prog)
    assert limited.is_success()
    assert limited.GetSolution(v.d) < base.GetSolution(v.d)
    assert limited.GetSolution(v.forces[0]) <= 0.2 + 1e-9


def test_lp1_lp3_and_socp_builders():
    cube = ex.cube_seven_contacts()
    prog, v = dg.build_form_closure_program(cube)
    assert prog.num_vars() == 8 and len(v.forces) == 7
    grasp = ex.equator_fingers(0.5)
    prog, v = dg.build_internal_force_program(grasp, np.eye(9)[:, :3])
    assert len(prog.linear_equality_constraints()) == 1
    prog, v = dg.build_exact_force_closure_program(grasp)
    assert len(prog.lorentz_cone_constraints()) == 3
    soft = ex.spatial_two_fingers(
        0.5, contact_model="soft_finger", torsional_friction=0.2
    )
    prog, v = dg.build_exact_force_closure_program(soft)
    assert len(prog.lorentz_cone_constraints()) == 4  # two per soft finger


def _sphere_grasp(n: int, **contact) -> dg.Grasp:
    p = np.random.default_rng(n).normal(size=(n, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    return dg.Grasp([dg.Contact(x, -x, mu=0.3, **contact) for x in p])


def test_large_programs_keep_sparse_generators_and_the_same_forces():
    # 120 contacts: S has 360 x 960 entries, past the dense limit.  The
    # forces are the product with S, written one contact's block at a time
    # (the whole product took 8.6 s to build at 400 contacts).
    grasp = _sphere_grasp(120)
    _, v = dg.build_force_closure_program(grasp, formulation="generators")
    assert hasattr(v.generators, "tocsr") and v.generators.shape == (360, 960)
    S = v.generators.toarray()
    with np.errstate(invalid="ignore"):
        whole = S @ v.weights
    assert all(a.EqualTo(b) for a, b in zip(whole, v.forces, strict=True))
    facets = dg.force_closure(grasp)
    generators = dg.force_closure(grasp, formulation="generators")
    assert facets.is_closure and generators.is_closure
    assert np.allclose(
        dg.grasp_matrix(grasp) @ np.concatenate(generators.contact_forces), 0
    )
    # Soft fingers: forces = diag(scales) @ weights, entrywise.
    soft = _sphere_grasp(130, contact_model="soft_finger", torsional_friction=0.1)
    _, v = dg.build_force_closure_program(soft)
    D = v.generators
    assert hasattr(D, "tocsr") and D.shape == (520, 520)
    with np.errstate(invalid="ignore"):
        whole = D.toarray() @ v.weights
    assert all(a.EqualTo(b) for a, b in zip(whole, v.forces, strict=True))
    assert dg.force_closure(soft).is_closure
