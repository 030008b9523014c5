r"""Grasp quality metrics.

Every metric takes a :class:`~drakegrasp.Grasp` (its contacts, reference point
``p`` and characteristic length ``b``, all in one grasp frame) and follows
``docs/conventions.md``: wrenches ``[f; m]`` with moments about ``p``, planar
wrenches ``[f_x, f_y, m_z]``, contact forces in contact frames with the normal
component first, inscribed polyhedral cones with ``n_g`` generators.

**Torque scaling.**  Metrics that compare forces with moments divide every
moment by a length ``b_s`` (the option ``torque_scale``; default the grasp's
characteristic length ``b``, an explicit ``1.0`` means no scaling).  A scaled
wrench ``[f; m / b_s]`` has the units of a force in every row, so balls and
singular values in wrench space are measured in newtons (per newton of normal
contact force: the metrics below are dimensionless).  Equivalently the metric
is computed with ``S G`` instead of ``G``, where ``S = diag(I, I / b_s)``.
An explicit ``torque_scale`` must keep the grasp's extent (the largest
distance from ``p`` to a contact) over it within ``[1e-4, 1e12]``: beyond,
the scaled moments are below the metrics' resolution or swamp the forces
(ε of a force-closure grasp came out 0), and it is refused.

The metrics:

* :func:`ferrari_canny`: the Ferrari–Canny ε (L1 form with a Qhull hull, L∞
  form through the normal fan of a Minkowski sum);
* :func:`lp2_d_star`: the ``d*`` of the force-closure program LP2, the
  geometric distance of the best internal force (no load) to the cones'
  boundaries; it does not measure the load a grasp carries (that is
  :func:`grasp_forces` and :func:`max_load`);
* :func:`grasp_singular_values` and the indices of ``G`` built from them
  (:func:`min_singular_value`, :func:`isotropy`,
  :func:`wrench_ellipsoid_volume`);
* :func:`hand_object_matrix` ``H = (G^+)^T J`` and its indices
  (:func:`distance_to_singularity`, :func:`uniformity_of_transformation`,
  :func:`manipulability_volume`);
* :func:`max_resistible_wrench`: the largest multiple of a given external
  wrench that bounded contact forces can resist (an LP solved with Clp);
* :func:`grasp_quality`: all of them at once, as a :class:`GraspQuality`;
* :func:`grasp_forces`: contact forces and joint torques that hold a load
  within the cones and the motors' limits (least squeeze, least torque or most
  margin), with a re-checkable certificate when none exist;
* :func:`max_load`: the payload, the largest multiple of a load the hand holds.

Submodules: :mod:`~drakegrasp.quality.epsilon` (primitive wrenches and ε),
:mod:`~drakegrasp.quality.indices` (singular values of ``G`` and ``H``),
:mod:`~drakegrasp.quality.resistible` (the LP) and
:mod:`~drakegrasp.quality.summary` (LP2 margin and :class:`GraspQuality`).
The grasp-force programs live beside the closure programs
(:mod:`~drakegrasp.closure.load_forces`, :mod:`~drakegrasp.closure.payload`),
so that the plant layer can use them; they are re-exported here.
The ε module imports ``scipy`` (Qhull, NNLS); the LPs import
``pydrake.solvers``.  Nothing here touches a plant.
"""

from drakegrasp._lazy import lazy_exports

_SOURCES = {
    "drakegrasp.closure.load_forces": (
        "GraspForceResult",
        "GraspForceVariables",
        "build_grasp_forces_program",
        "grasp_forces",
    ),
    "drakegrasp.closure.payload": (
        "MaxLoadResult",
        "build_max_load_program",
        "max_load",
    ),
    "drakegrasp.quality._common": ("RANK_TOL",),
    "drakegrasp.quality.epsilon": (
        "HULL_TOL",
        "L1_MAX_POINTS",
        "LINF_MAX_CANDIDATES",
        "ferrari_canny",
        "primitive_wrenches",
    ),
    "drakegrasp.quality.indices": (
        "distance_to_singularity",
        "grasp_singular_values",
        "hand_object_matrix",
        "hand_object_singular_values",
        "isotropy",
        "manipulability_volume",
        "min_singular_value",
        "uniformity_of_transformation",
        "wrench_ellipsoid_volume",
    ),
    "drakegrasp.quality.resistible": (
        "MaxWrenchResult",
        "MaxWrenchVariables",
        "build_max_resistible_wrench_program",
        "max_resistible_wrench",
    ),
    "drakegrasp.quality.summary": (
        "GraspQuality",
        "grasp_quality",
        "lp2_d_star",
        "lp2_margin",
    ),
}

_SUBMODULES = (
    "_common",
    "epsilon",
    "indices",
    "resistible",
    "summary",
)

__all__ = [
    "HULL_TOL",
    "L1_MAX_POINTS",
    "LINF_MAX_CANDIDATES",
    "RANK_TOL",
    "GraspForceResult",
    "GraspForceVariables",
    "GraspQuality",
    "MaxLoadResult",
    "MaxWrenchResult",
    "MaxWrenchVariables",
    "build_grasp_forces_program",
    "build_max_load_program",
    "build_max_resistible_wrench_program",
    "distance_to_singularity",
    "ferrari_canny",
    "grasp_forces",
    "grasp_quality",
    "grasp_singular_values",
    "hand_object_matrix",
    "hand_object_singular_values",
    "isotropy",
    "lp2_d_star",
    "lp2_margin",
    "manipulability_volume",
    "max_load",
    "max_resistible_wrench",
    "min_singular_value",
    "primitive_wrenches",
    "uniformity_of_transformation",
    "wrench_ellipsoid_volume",
]

__getattr__, __dir__ = lazy_exports(
    __name__, globals(), _SOURCES, submodules=_SUBMODULES
)
