r"""Drake Systems: a grasp monitor that checks a grasp while a simulation runs.

:class:`GraspMonitor` is a ``LeafSystem`` that runs :func:`drakegrasp.analyze_grasp`
on the plant's configuration at a declared period (an analysis costs
milliseconds, so not every simulation step) and holds the answer until the next
sample::

    plant state ──────────────▶ ┌──────────────┐ ──▶ verdicts (vector, 12 + 2 n)
    scene graph query ────────▶ │ GraspMonitor │
    contact results (optional) ▶└──────────────┘ ──▶ report (GraspSample)

where ``n`` is the number of hand bodies: 18 entries for the parallel jaw's
palm and two fingers, named by ``monitor.verdict_names`` (see "Outputs").  The
hand bodies are those :func:`~drakegrasp.analyze_grasp` resolves from the same
``hand`` (:func:`~drakegrasp.plant.validation.hand_contact_bodies`): a palm
welded to the world is one, and its contacts count as the fingers' do.

Wiring: :func:`add_grasp_monitor` adds one to a ``DiagramBuilder`` and
connects it to the plant and the scene graph.  This module is the monitor's
overview and its wiring; the System is in
:mod:`~drakegrasp.systems.grasp_monitor`, its options (checked once, at
construction) in :mod:`~drakegrasp.systems.monitor_options`, its contact
sources in :mod:`~drakegrasp.systems.sensing`, the holding state in
:mod:`~drakegrasp.systems.holding` and one sample in
:mod:`~drakegrasp.systems.sample`.

**Options.**  The analysis of every sample takes the options of
:func:`~drakegrasp.analyze_grasp`: one :class:`~drakegrasp.AnalysisOptions`
(``options=``) or the same keywords one by one, not both, and its
``couplings=`` (checked when the monitor is built: a plant with a constraint
drakegrasp did not record, such as a ``<mimic>`` loaded by a bare ``Parser``,
is refused there, not reported invalid at every sample).  ``mu="plant"``
reads each contact's friction from the plant's proximity properties; a number
that disagrees with them is warned about once
(:class:`~drakegrasp.plant.friction.FrictionMismatchWarning`).

**Its own plant context.**  The analysis reads body poses and Jacobians from a
plant context; the monitor keeps a private one, sets its positions and
velocities from the ``plant_state`` input at each sample, and passes the scene
graph's query object from its ``query_object`` input (the query object of the
same instant, so geometry and kinematics agree).  Its parameters are the
model's defaults: a mass set in the simulation's context (mass
randomisation) reaches no port, so call
:meth:`~drakegrasp.GraspMonitor.use_parameters_of` with that context after
setting it (the gravity load otherwise weighs the model's mass).

**Where the contacts come from** (``contacts=``), and what each mode sees:

- ``"geometry"`` (default): signed distances, as :func:`~drakegrasp.find_contacts`
  does outside a simulation: a contact is a pair within ``distance_tolerance``
  (``|ψ| <= tol``) whose points are not moving apart faster than
  ``separation_speed``.  A simulated contact penetrates a little (point
  contact: ~0.1 mm for newtons of squeeze; the WSG-50 at 20 N: 0.145 mm), so
  the monitor allows penetration by default (``allow_penetration=None``:
  True), up to ``HoldingThresholds.max_penetration`` (5 mm: deeper, the
  sample is ``"invalid"``, no grip to judge); ``allow_penetration=False``
  makes a sample that penetrates deeper than ``distance_tolerance``
  ``"invalid"``.
  *It sees* positions, normals and velocities, hence slip, and whether a
  finger's geometry touches the object's (``ψ <= 0``: the plant pushes only
  there); *it cannot see* forces.  So the analysis counts a finger within the
  tolerance that carries no load (the contact geometry is there), but the
  holding state counts only fingers that touch: fingers stopped 0.5 mm short
  of a box are analysed in force closure and are ``no contact``, never
  ``holding``.  Friction in use is NaN, so a grip is never "at risk", only
  "slipping" once it moves.
- ``"contact_results"``: the contacts the plant's contact model used in the
  last step, read from the ``contact_results`` input
  (:func:`drakegrasp.plant.contacts_from_results`): with hydroelastic contact
  each contact surface becomes a patch polygon, point pairs become point
  contacts.  *It sees* the forces the plant applied, so friction in use
  ``‖f_t‖/(μ f_n)`` with the plant's own μ (read from the geometries' proximity
  properties, :func:`~drakegrasp.plant.friction.pair_friction`, not the ``mu``
  option), and a grip nearing its friction limit is
  "at risk" before it slips.  These contacts penetrate to make their force
  (point contact: 0.2 mm at 20 N between the WSG-50's tips and a box), so
  the analysis allows penetration whatever ``distance_tolerance`` is (a pose
  is invalid only for a joint off its limits, or a hand sunk deeper than
  ``HoldingThresholds.max_penetration``): at the default 0.1 mm a firm
  grip was "invalid", shown as "touching", until it slipped.  *It cannot see*
  contacts the step did not
  compute (a hydroelastic surface has one net force, not a distribution), nor
  a contact between two steps: a finger chattering along the object is in
  the results only at some samples (the WSG-50's pads sliding up a box: about
  one 10 ms sample in eight), which the holding state's hysteresis and its
  out-of-reach test bridge.  It depends on a simulator's context: a fresh
  context has no results.

In both modes, once contact is lost the holding state follows the object in
the frames of the fingers that touched it last, and, while it slides along
them, measures its distance from every hand body (Drake's signed distances, up
to twice ``release_distance``), to tell a grip that is merely missing a frame
from an object that has left the hand.

**Holding.**  Each sample also judges the grip
(:mod:`drakegrasp.systems.holding`, where the rules are in full):
``no contact``, ``touching``, ``holding`` (a grip that holds, by force closure
or, when the options give a load, by the load section), ``at risk`` (friction
in use above ``risk``), ``slipping`` (a contact slips faster than ``slip_speed``, or the
object moves along the fingers without contact) or ``dropped`` (the object has
left the fingers that last held it, along them: no contact for
``hold_samples + 1`` samples, and either still sliding along them and farther
than ``release_distance`` from every hand body, or at rest displaced along them
by more than ``release_distance`` since the last contact; a hand that opens
around an object at rest moves its fingers away along their normals: a
release, ``no contact``).  The hysteresis: a more alarming state is shown at
once (``dropped`` only through its own gate), a less alarming one only after
``hold_samples + 1`` consecutive samples whose evidence is less alarming, and
for up to ``hold_samples`` samples without contact the last grip's analysis is
kept.  So one frame without contact is not a drop, and the state does not
flicker between ``slipping``, ``dropped`` and ``holding`` on consecutive
samples.  These thresholds are a
:class:`~drakegrasp.systems.holding.HoldingThresholds` (``holding=``).  An
``invalid`` sample is no evidence: the grip is judged from its analysis, so
a sample without one keeps the last valid sample's holding state (the
initial ``no contact`` before any) instead of calling a grip it could not
analyse ``touching``.

**What d* is.**  LP2's ``d*`` is the geometric distance of the best internal
force to the boundaries of the friction cones: it depends on the contacts'
positions, normals and μ, not on the load, the squeeze or the motors.  A flat
``d*`` says the contact geometry did not change; the holding state and friction
in use say whether the hand carries the object.

**Timing.**  Samples are unrestricted updates at ``offset + k * period`` (and
one at initialization); outputs are state, held between samples.  As with
any Drake discrete update, a logger publishing at a sample time ``t_k`` sees
the value held *before* the update at ``t_k``: the verdict logged at
``t_{k+1}`` is the analysis of the plant state logged at ``t_k``
(``GraspSample.time`` and ``GraspSample.state`` say exactly which).
A sample that finds a discrete plant not stepped since the sample held (no
update time of the plant between them, and the same state: a period shorter
than the plant's time step) repeats that sample at its own time, so the
hysteresis of the holding state counts plant states, not samples.
A sample at a time earlier than the one held (a simulator restarted with its
context's time set back) starts a new run, from ``no contact``: the holding
state of the run before is no evidence about this one.
A discrete plant's contact results are those of its last step; they exist in
the simulator's context, not in a fresh context where only ``q`` and ``v``
were set.

**Outputs.**  ``verdicts`` is a vector named by ``monitor.verdict_names``:
:data:`~drakegrasp.systems.sample.VERDICT_NAMES` (index constants
``GraspMonitor.STATUS`` ... ``GraspMonitor.EPSILON``), then
:data:`~drakegrasp.systems.sample.HOLDING_NAMES` (``GraspMonitor.HOLDING`` ...
``GraspMonitor.CONTACT_GAP``), then per hand body its friction in use and slip
speed:

===================  ===========================================================
``status``           1 analysed, 0 no contact, −1 invalid pose (e.g. penetration
                     deeper than the tolerance, a non-finite state; the report
                     says why); an invalid sample judges no grip: its holding
                     columns are the last valid sample's
``force_closure``    1 / 0: polyhedral force closure with the hand check LP3
``form_closure``     1 / 0: first-order form closure (LP1)
``antipodal``        1 / 0: two contacts that are antipodal (0 for other counts)
``num_contacts``     number of contacts analysed
``d_star``           LP2's ``d*``, 0 without contact (see "What d* is")
``epsilon``          Ferrari–Canny ε (L1), 0 when not in force closure or not
                     asked for (``compute_epsilon=False``, the default; when
                     asked, the batch engine's compiled kernel computes it,
                     about 1 ms on 8 contacts); NaN where the metric
                     refuses the grasp (a ``characteristic_length`` out of
                     scale with the contacts; the sample's message says why)
``holding``          code of the holding state (index in ``HOLDING_STATES``)
``friction_use``     largest ``‖f_t‖/(μ f_n)``; NaN in geometry mode
``slip_speed``       largest slip speed at a contact, m/s
``relative_speed``   object's centre of mass relative to a touching finger, m/s
``contact_gap``      samples without contact over which the hysteresis kept a
                     grip (the analysis shown is then the last one with
                     contact)
===================  ===========================================================

``report`` is an abstract port holding a :class:`GraspSample`: the time, the
status, the full :class:`~drakegrasp.GraspReport` (None without one), ε, the
holding state with the per-finger loads, and the plant state the sample was
computed from.
"""

from __future__ import annotations

from pydrake.geometry import SceneGraph
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import DiagramBuilder

from drakegrasp.core.calls import checked_call
from drakegrasp.errors import InvalidOptionError
from drakegrasp.systems.grasp_monitor import GraspMonitor
from drakegrasp.systems.monitor_options import MIN_PERIOD
from drakegrasp.systems.sample import VERDICT_NAMES, GraspSample

__all__ = [
    "MIN_PERIOD",
    "VERDICT_NAMES",
    "GraspMonitor",
    "GraspSample",
    "add_grasp_monitor",
]


def _unique_name(builder: DiagramBuilder, base: str) -> str:
    taken = {s.get_name() for s in builder.GetSystems()}
    if base not in taken:
        return base
    k = 2
    while f"{base}_{k}" in taken:
        k += 1
    return f"{base}_{k}"


@checked_call
def add_grasp_monitor(
    builder: DiagramBuilder,
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    *,
    name: str = "grasp_monitor",
    **options,
) -> GraspMonitor:
    """Add a :class:`GraspMonitor` to ``builder`` and connect its inputs.

    Parameters
    ----------
    builder : DiagramBuilder
        Holds ``plant`` and ``scene_graph`` (e.g. from
        ``AddMultibodyPlantSceneGraph``); not built yet.
    plant : MultibodyPlant
        Finalized.
    scene_graph : SceneGraph
    name : str, optional
        The system's name; ``_2``, ``_3`` ... is appended when the builder
        already holds a system of that name (two monitors in one diagram).
    **options
        Keyword arguments of :class:`GraspMonitor`.

    Returns
    -------
    GraspMonitor
        Connected to the plant's state, the scene graph's query output and, with
        ``contacts="contact_results"``, the plant's contact results.

    Raises
    ------
    InvalidOptionError
        If an argument has the wrong type, the builder was already built,
        the plant or scene graph is not in this builder, or the plant is not
        registered with this scene graph (two plants and scene graphs in one
        builder: pass the pair that ``AddMultibodyPlantSceneGraph`` returned);
        and as :class:`GraspMonitor` raises, e.g. for a plant with a
        constraint drakegrasp has not recorded as a coupling.
    """
    for arg, value, kind in (
        ("builder", builder, DiagramBuilder),
        ("plant", plant, MultibodyPlant),
        ("scene_graph", scene_graph, SceneGraph),
        ("name", name, str),
    ):
        if not isinstance(value, kind):
            raise InvalidOptionError(
                f"add_grasp_monitor: {arg} must be a {kind.__name__}, got "
                f"a {type(value).__name__}"
            )
    if builder.already_built():
        raise InvalidOptionError("add_grasp_monitor: this builder was already built")
    systems = builder.GetSystems()
    for arg, value in (("plant", plant), ("scene_graph", scene_graph)):
        if not any(s is value for s in systems):
            raise InvalidOptionError(
                f"add_grasp_monitor: the {arg} {value.get_name()!r} is not in this "
                "builder; pass the builder that holds the plant and scene graph"
            )
    source = plant.get_source_id()
    if source is None or not scene_graph.model_inspector().SourceIsRegistered(source):
        raise InvalidOptionError(
            f"add_grasp_monitor: the plant {plant.get_name()!r} is not registered "
            f"with the scene graph {scene_graph.get_name()!r}, so that scene "
            "graph's queries know none of its geometries; pass the plant's own "
            "scene graph (the pair AddMultibodyPlantSceneGraph returned)"
        )
    monitor = GraspMonitor(plant, **options)
    monitor.set_name(_unique_name(builder, name))
    builder.AddSystem(monitor)
    builder.Connect(plant.get_state_output_port(), monitor.get_plant_state_input_port())
    builder.Connect(
        scene_graph.get_query_output_port(), monitor.get_query_object_input_port()
    )
    if monitor.settings.contacts == "contact_results":
        builder.Connect(
            plant.get_contact_results_output_port(),
            monitor.get_contact_results_input_port(),
        )
    return monitor
