"""Every default tolerance, cone size and shared size limit of drakegrasp, defined once.

The programs, the batch engine, the plant layer, the monitor and the command
line all read their defaults from here, so a threshold means the same in each
of them.
"""

from __future__ import annotations

import math

__all__ = [
    "COUPLING_TOL",
    "L1_MAX_POINTS",
    "MOMENT_ARMS",
    "DEFAULT_DISTANCE_TOLERANCE",
    "DEFAULT_NUM_GENERATORS",
    "DEFAULT_RANK_TOL",
    "DEFAULT_TOL",
    "MAX_ARRAY_ENTRIES",
    "MAX_COUPLING_TOL",
    "MAX_DISTANCE_TOLERANCE",
    "MAX_ITEMS",
    "MONITOR_COUPLING_TOL",
    "QUERY_POSE_TOL",
    "UNIT_NORMAL_TOL",
    "ZERO_FRACTION",
    "near_threshold",
    "relative_margin",
]

DEFAULT_TOL = 1e-6
"""Default threshold on ``d*``: closure needs ``d* > tol`` (LP3 passes at ``<= tol``).

LP1–LP3 normalise the normal forces to ``Σ f_n <= N``, so ``d*`` is of order 0.1
for a good grasp; the solvers report ``d*`` to about 1e-10 (checked against
closed forms), far below this threshold.
"""

DEFAULT_RANK_TOL = 1e-9
"""Singular values below ``rank_tol * σ_max`` count as zero in rank tests."""

DEFAULT_DISTANCE_TOLERANCE = 1e-4
"""Default ``|ψ|`` (metres) below which a geometry pair counts as a contact."""

MAX_DISTANCE_TOLERANCE = 0.01
"""Largest ``distance_tolerance`` accepted: 0.01 m (10 mm).

Bodies that far apart count as touching: above it a palm 15 mm below a box
became four contacts and turned the verdict to force closure, "pose: valid"
(``distance_tolerance: 0.02``, a user thinking in millimetres).  The unit is
metres; the widest tolerance drakegrasp uses itself, in its tests, tutorials
and benchmarks, is 2 mm (a point cloud's spacing), most 1 mm or the default
0.1 mm.
"""

COUPLING_TOL = 1e-6
"""A configuration breaks ``q_0 = ρ q_1 + Δq`` by more than this (m or rad),
as :func:`~drakegrasp.close_hand` refuses a pre-shape; an analysis's default
``coupling_tolerance``."""

MONITOR_COUPLING_TOL = 1e-3
"""A :class:`~drakegrasp.GraspMonitor`'s default ``coupling_tolerance`` (m or
rad): a simulation's coupler constraints give under load, as its contacts
penetrate.  Drake's SAP held a three-finger hand's ``<mimic>`` distal joints
7 µrad off their leaders at 0.5 N·m, and every sample of that grip was
"invalid" at :data:`COUPLING_TOL`; 1 mrad moves a fingertip 0.1 m from its
joint by the default distance tolerance."""

MAX_COUPLING_TOL = 0.1
"""Largest ``coupling_tolerance`` accepted (m or rad): beyond it the hand the
analysis assumes (its joints on their couplings) is not the plant's."""

UNIT_NORMAL_TOL = 1e-6
"""How far from 1 the length of a normal given to ``contact_frames`` may be.

The function builds frames from the normals as they are; every other entry
point normalises them first (to within a few units in the last place).  1e-6
admits normals normalised in float32 (about 1e-7 off) or read from six-digit
text, and refuses a normal that was never normalised.
"""

QUERY_POSE_TOL = 1e-9
"""How far a body may stand in a ``QueryObject`` from where the plant's context
puts it: each entry of its pose's ``[R | p]`` (p in metres), times the body's
distance from the world origin where that is past 1 m.  Both compute the same
kinematics from the same state, so they agree to rounding
(:func:`drakegrasp.plant.validation.checked_query_object`)."""

DEFAULT_NUM_GENERATORS = 8
"""Default generators ``n_g`` of each polyhedral (inscribed) spatial Coulomb cone."""

ZERO_FRACTION = 1e-3
"""``d*`` below ``ZERO_FRACTION * tol`` is the solver's zero, not a near miss."""


MAX_ARRAY_ENTRIES = 2**30
"""Most entries of one array argument read in memory (8 GiB as float64).

A broadcast array (``np.broadcast_to(0.0, (10**9, 3))``) costs nothing to make
and took 22 GiB to read as floats, or minutes to check; beyond this it is
refused before it is read.  A larger batch streams from a file chunk by chunk
(``drakegrasp.batch.stream_file``), whose chunks are far below it."""


MAX_ITEMS = 10**7
"""Most items of one sequence argument read into a list (contacts, grasps,
forces, bodies...).  ``list()`` of a 10**9-row array made a view per row
(about 100 GB), and of an endless generator never returned; more items than
this are refused as they are counted.  A larger batch is given as arrays."""


L1_MAX_POINTS = 2_000
"""Most primitive wrenches whose hull the L1 ε may build.

A 6-D hull's facets grow about linearly with its points here: 2,000 points
(250 spatial hard fingers with 8 generators) make about 230,000 facets and
take about 9 s; 8,000 points (1,000 fingers) took 150 s, and a facet check on
them once asked for 57 GiB.  Beyond this bound ε is refused, not attempted.
"""


MOMENT_ARMS = (1e-4, 1e12)
"""Range of a grasp's extent over the length its moments are divided by (m / m).

That length is an explicit ``torque_scale`` or the grasp's characteristic
length (``characteristic_lengths`` in the batch engine).

Below it the moments, divided by ``torque_scale``, are too small for the LPs'
tolerances, and weight capacities came out wrong without a word (by 5e-5 at a
ratio of 2.4e-5, by 0.66 at 2.4e-7, on random grasps); far above it Clp fails
(at 2.4e21), and the quality metrics swamp the forces: on the three equator
fingers (extent 1 m) ``ferrari_canny(..., torque_scale=1e-15)`` returned 0 and
``grasp_singular_values(..., torque_scale=1e-50)`` a ``σ_min`` of 1.04e19 (1.73
at 1e-12).  The planner (``planning.checks``, its extent the largest absolute
coordinate of a contact in the object's frame), the quality metrics
(``quality._common``) and the batch engine's metrics (``batch.metrics``, both
with the largest distance from the reference point to a contact) check against
this one range, through :func:`drakegrasp.core.validation.outside_moment_arms`.
The closure verdicts take any length.
"""


def relative_margin(value: float, tol: float) -> float:
    """``(value - tol) / tol``: positive above the threshold, ``|m| < 1`` within tol."""
    if not math.isfinite(value):
        return -math.inf
    return (value - tol) / tol


def near_threshold(margin: float) -> bool:
    """True when ``d*`` lies in ``(ZERO_FRACTION tol, 2 tol)``: not certain."""
    return ZERO_FRACTION - 1.0 < margin < 1.0
