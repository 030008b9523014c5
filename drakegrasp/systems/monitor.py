r"""Drake Systems: a grasp monitor that checks a grasp while a simulation runs.

:class:`GraspMonitor` is a ``LeafSystem`` that runs :func:`drakegrasp.analyze_grasp`
on the plant's configuration at a declared period (an analysis costs
milliseconds, so not every simulation step) and holds the answer until the next
sample::

    plant state ──────────────▶ ┌──────────────┐ ──▶ verdicts (vector, 7)
    scene graph query ────────▶ │ GraspMonitor │
    contact results (optional) ▶└──────────────┘ ──▶ report (GraspSample)

Wiring: :func:`add_grasp_monitor` adds one to a ``DiagramBuilder`` and
connects it to the plant and the scene graph.

**Its own plant context.**  The analysis reads body poses and Jacobians from a
plant context; the monitor keeps a private one, sets its positions and
velocities from the ``plant_state`` input at each sample, and passes the scene
graph's query object from its ``query_object`` input (the query object of the
same instant, so geometry and kinematics agree).

**Where the contacts come from** (``contacts=``), and what each mode sees:

- ``"geometry"`` (default): signed distances, as :func:`~drakegrasp.find_contacts`
  does outside a simulation: a contact is a pair within ``distance_tolerance``
  (``|ψ| <= tol``) whose points are not moving apart faster than
  ``separation_speed``.  A simulated contact penetrates a little (point
  contact: ~0.1 mm for newtons of squeeze), so choose ``distance_tolerance``
  above that (1e-3 m is a good start) or pass ``allow_penetration=True``.
  *It sees* positions, normals and velocities, hence slip; *it cannot see*
  forces: a finger within the tolerance that carries no load still counts, and
  friction in use is NaN, so a grip is never "at risk", only "slipping" once it
  moves.
- ``"contact_results"``: the contacts the plant's contact model used in the
  last step, read from the ``contact_results`` input
  (:func:`drakegrasp.plant.contacts_from_results`): with hydroelastic contact
  each contact surface becomes a patch polygon, point pairs become point
  contacts.  *It sees* the forces the plant applied, so friction in use
  ``‖f_t‖/(μ f_n)`` with the plant's own μ (read from the geometries' proximity
  properties, not the ``mu`` option), and a grip nearing its friction limit is
  "at risk" before it slips.  *It cannot see* contacts the step did not
  compute (a hydroelastic surface has one net force, not a distribution), and
  it depends on a simulator's context: a fresh context has no results.

**Holding.**  Each sample also judges the grip
(:mod:`drakegrasp.systems.holding`): ``no contact``, ``touching``, ``holding``,
``at risk`` (friction in use above ``risk``), ``slipping`` (a contact slips
faster than ``slip_speed``) or ``dropped``.  A sample without contact after a
grip keeps the last grip's analysis and state for ``hold_samples`` samples
(hysteresis), so one frame without contact is not a drop.  These thresholds
are a :class:`~drakegrasp.systems.holding.HoldingThresholds` (``holding=``).

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
                     says why)
``force_closure``    1 / 0: polyhedral force closure with the hand check LP3
``form_closure``     1 / 0: first-order form closure (LP1)
``antipodal``        1 / 0: two contacts that are antipodal (0 for other counts)
``num_contacts``     number of contacts analysed
``d_star``           LP2's ``d*``, 0 without contact (see "What d* is")
``epsilon``          Ferrari–Canny ε (L1), 0 when not in force closure or not
                     asked for (``compute_epsilon=False``, the default)
``holding``          code of the holding state (index in ``HOLDING_STATES``)
``friction_use``     largest ``‖f_t‖/(μ f_n)``; NaN in geometry mode
``slip_speed``       largest slip speed at a contact, m/s
``relative_speed``   object's centre of mass relative to a touching finger, m/s
``contact_gap``      samples without contact bridged by the hysteresis
===================  ===========================================================

``report`` is an abstract port holding a :class:`GraspSample`: the time, the
status, the full :class:`~drakegrasp.GraspReport` (None without one), ε, the
holding state with the per-finger loads, and the plant state the sample was
computed from.
"""

from __future__ import annotations

import numbers
import time as _time

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import QueryObject, SceneGraph
from pydrake.multibody.plant import ContactResults, MultibodyPlant
from pydrake.systems.framework import (
    Context,
    DiagramBuilder,
    EventStatus,
    LeafSystem,
    State,
)

from drakegrasp.closure.verdicts import force_closure
from drakegrasp.core.contact import Contact, ContactModel
from drakegrasp.core.friction_cone import DEFAULT_NUM_GENERATORS
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.tolerances import DEFAULT_TOL
from drakegrasp.errors import GraspError, InvalidOptionError, NoContactsError
from drakegrasp.plant.analysis import analyze_grasp
from drakegrasp.plant.contact_results import contacts_from_results
from drakegrasp.plant.contacts import (
    DEFAULT_DISTANCE_TOLERANCE,
    HandSpec,
    _scoped_name,
    find_contacts,
    hand_bodies,
    resolve_object_body,
)
from drakegrasp.plant.jacobians import PLANES
from drakegrasp.quality import ferrari_canny
from drakegrasp.systems.holding import (
    FingerLoad,
    HoldingThresholds,
    finger_loads_from_results,
    finger_motion_from_contacts,
    next_holding_state,
    speeds_against,
)
from drakegrasp.systems.sample import (
    VERDICT_NAMES,
    GraspSample,
    analysis_verdicts,
    grip_verdicts,
    verdict_names,
)

__all__ = [
    "MIN_PERIOD",
    "VERDICT_NAMES",
    "GraspMonitor",
    "GraspSample",
    "add_grasp_monitor",
]

_CONTACT_SOURCES = ("geometry", "contact_results")
MIN_PERIOD = 1e-6
"""Shortest sample period (s) accepted: a plant steps at ~1e-3 s."""


def _seconds(name: str, value, *, least: float) -> float:
    """``value`` as finite seconds >= ``least`` (> 0 when least > 0), or refuse."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InvalidOptionError(
            f"{name} must be a real number of seconds, got {value!r} "
            f"({type(value).__name__})"
        )
    value = float(value)
    if not np.isfinite(value) or value < least:
        raise InvalidOptionError(
            f"{name} must be finite and >= {least:g} s, got {value!r}"
        )
    return value


def _flag(name: str, value) -> bool:
    if not isinstance(value, bool | np.bool_):
        raise InvalidOptionError(
            f"{name} must be True or False, got {value!r} ({type(value).__name__})"
        )
    return bool(value)


class GraspMonitor(LeafSystem):
    """Analyse the grasp of a simulated plant every ``period`` seconds.

    Parameters
    ----------
    plant : MultibodyPlant
        The finalized plant of the simulation (registered with a SceneGraph).
    object_body, hand, mu, contact_model, torsional_friction,
    distance_tolerance, plane, characteristic_length, num_generators, tol,
    allow_penetration, patches, check_pose
        As in :func:`drakegrasp.analyze_grasp`.  A pose that the check refuses
        (penetration deeper than ``distance_tolerance`` by any hand body, a
        joint off its limits) gives an ``"invalid"`` sample, not an exception.
        ``mu`` is the analysis's friction coefficient; friction in use is
        computed with the plant's own.
    contacts : {"geometry", "contact_results"}, optional
        Signed distances (default), or the plant's contact results (then the
        ``contact_results`` input port exists and must be connected).  See the
        module docstring for what each can see.
    period : float, optional
        Seconds between samples (default 0.05, at least :data:`MIN_PERIOD`).
    offset : float, optional
        Time of the first periodic sample (default 0); a sample is also taken
        at initialization.
    compute_epsilon : bool, optional
        Compute the Ferrari–Canny ε of force-closure samples (default False:
        it is the costliest part of a sample).
    holding : HoldingThresholds, optional
        Thresholds of the holding state and the hysteresis (default
        ``HoldingThresholds()``).

    Notes
    -----
    Input ports: ``plant_state`` (vector, ``nq + nv``), ``query_object``
    (abstract ``QueryObject``), and with ``contacts="contact_results"``
    ``contact_results`` (abstract ``ContactResults``).  Output ports:
    ``verdicts`` (vector, :attr:`verdict_names`) and ``report`` (abstract
    :class:`GraspSample`).  Both are state: they change only at samples.

    Raises
    ------
    InvalidOptionError
        For an unfinalized plant, a bad period, offset, flag or contact
        source, or options that :func:`drakegrasp.analyze_grasp` would refuse.
    """

    STATUS, FORCE_CLOSURE, FORM_CLOSURE, ANTIPODAL = 0, 1, 2, 3
    NUM_CONTACTS, D_STAR, EPSILON = 4, 5, 6
    HOLDING, FRICTION_USE, SLIP_SPEED, RELATIVE_SPEED, CONTACT_GAP = 7, 8, 9, 10, 11

    def __init__(
        self,
        plant: MultibodyPlant,
        *,
        object_body,
        hand: HandSpec = None,
        mu: float,
        contact_model: ContactModel | str = ContactModel.HARD_FINGER,
        torsional_friction: float | None = None,
        distance_tolerance: float = DEFAULT_DISTANCE_TOLERANCE,
        plane: str | None = None,
        characteristic_length: float | None = None,
        num_generators: int = DEFAULT_NUM_GENERATORS,
        tol: float = DEFAULT_TOL,
        allow_penetration: bool = False,
        patches: str = "vertices",
        check_pose: bool = True,
        contacts: str = "geometry",
        period: float = 0.05,
        offset: float = 0.0,
        compute_epsilon: bool = False,
        holding: HoldingThresholds | None = None,
    ):
        super().__init__()
        if not isinstance(plant, MultibodyPlant) or not plant.is_finalized():
            raise InvalidOptionError(
                f"GraspMonitor needs a finalized pydrake MultibodyPlant, got {plant!r}"
            )
        if not isinstance(contacts, str) or contacts not in _CONTACT_SOURCES:
            raise InvalidOptionError(
                f"contacts must be one of {_CONTACT_SOURCES}, got {contacts!r}"
            )
        period = _seconds("period", period, least=MIN_PERIOD)
        offset = _seconds("offset", offset, least=0.0)
        if plane is not None and plane not in PLANES:
            raise InvalidOptionError(
                f"plane must be one of {sorted(PLANES)} or None, got {plane!r}"
            )
        b = characteristic_length
        if b is not None and (
            isinstance(b, bool)
            or not isinstance(b, numbers.Real)
            or not (np.isfinite(b) and b > 0)
        ):
            raise InvalidOptionError(
                f"characteristic_length must be None or finite and > 0 (metres), "
                f"got {b!r}"
            )
        holding = HoldingThresholds() if holding is None else holding
        if not isinstance(holding, HoldingThresholds):
            raise InvalidOptionError(
                f"holding must be a HoldingThresholds, got {type(holding).__name__}"
            )
        self._thresholds = holding
        self._plant = plant
        body = resolve_object_body(plant, object_body)
        self._body = body
        self._bodies = hand_bodies(plant, body, hand)
        self._object_name = _scoped_name(plant, body)
        self._contacts = contacts
        self._compute_epsilon = _flag("compute_epsilon", compute_epsilon)
        self._num_generators = num_generators
        self._options = {
            "object_body": body,
            "hand": self._bodies,
            "mu": mu,
            "contact_model": ContactModel.parse(contact_model),
            "torsional_friction": torsional_friction,
            "distance_tolerance": distance_tolerance,
            "plane": plane,
            "characteristic_length": None if b is None else float(b),
            "num_generators": num_generators,
            "tol": tol,
            "allow_penetration": _flag("allow_penetration", allow_penetration),
            "patches": patches,
            "check_pose": _flag("check_pose", check_pose),
        }
        self.verdict_names = verdict_names(
            [_scoped_name(plant, f) for f in self._bodies]
        )
        """Names of the ``verdicts`` output's elements."""
        self._plant_context = plant.CreateDefaultContext()
        nx = plant.num_multibody_states()
        self._state_port = self.DeclareVectorInputPort("plant_state", nx)
        self._query_port = self.DeclareAbstractInputPort(
            "query_object", AbstractValue.Make(QueryObject())
        )
        self._results_port = None
        if contacts == "contact_results":
            self._results_port = self.DeclareAbstractInputPort(
                "contact_results", AbstractValue.Make(ContactResults())
            )
        empty = self._sample(
            0.0, "not sampled", "", None, 0.0, np.zeros(nx), 0.0, grip=None
        )
        self._verdict_index = self.DeclareDiscreteState(len(self.verdict_names))
        self._report_index = self.DeclareAbstractState(AbstractValue.Make(empty))
        self.DeclareStateOutputPort("verdicts", self._verdict_index)
        self.DeclareStateOutputPort("report", self._report_index)
        self.DeclareInitializationUnrestrictedUpdateEvent(self._update)
        self.DeclarePeriodicUnrestrictedUpdateEvent(period, offset, self._update)
        self.period = period
        self._check_options()

    def _check_options(self) -> None:
        """Refuse at construction the options that no configuration could fix.

        The core checks them on a probe grasp (three contacts on a unit circle,
        in the analysis plane when there is one), so a bad ``mu``, ``tol``,
        ``num_generators`` or contact model stops here, not in the simulation.
        """
        o = self._options
        model = o["contact_model"]
        if model is ContactModel.SOFT_FINGER and o["plane"] is not None:
            raise InvalidOptionError(
                "a planar analysis has no soft fingers; use 'hard_finger' or "
                "'frictionless'"
            )
        nu = o["torsional_friction"]
        if model is ContactModel.SOFT_FINGER and nu is None:
            raise InvalidOptionError(
                "contact_model='soft_finger' needs torsional_friction > 0"
            )
        tol = o["distance_tolerance"]
        if not isinstance(tol, int | float) or not (np.isfinite(tol) and tol > 0):
            raise InvalidOptionError(
                f"distance_tolerance must be finite and > 0 (metres), got {tol!r}"
            )
        if o["patches"] not in ("vertices", "witness"):
            raise InvalidOptionError(
                f"patches must be 'vertices' or 'witness', got {o['patches']!r}"
            )
        angles = 2 * np.pi * np.arange(3) / 3
        ring = np.column_stack([np.cos(angles), np.sin(angles)])
        if o["plane"] is None:
            ring = np.column_stack([ring, np.zeros(3)])
        probe = Grasp(
            [
                Contact(p, -p, mu=o["mu"], model=model, torsional_friction=nu or 0.0)
                for p in ring
            ]
        )
        force_closure(probe, num_generators=o["num_generators"], tol=o["tol"])

    # Ports ---------------------------------------------------------------
    def get_plant_state_input_port(self):
        """Input: the plant's state ``[q; v]`` (``plant.get_state_output_port()``)."""
        return self._state_port

    def get_query_object_input_port(self):
        """Input: the scene graph's ``QueryObject`` (``get_query_output_port()``)."""
        return self._query_port

    def get_contact_results_input_port(self):
        """Input: the plant's ``ContactResults``; only with contact results."""
        if self._results_port is None:
            raise InvalidOptionError(
                "this monitor reads contacts from geometry; build it with "
                "contacts='contact_results' to have a contact_results port"
            )
        return self._results_port

    def get_verdicts_output_port(self):
        """Output: the verdict vector (named by :attr:`verdict_names`)."""
        return self.GetOutputPort("verdicts")

    def get_report_output_port(self):
        """Output: the latest :class:`GraspSample`."""
        return self.GetOutputPort("report")

    # The evaluation ------------------------------------------------------
    def _no_loads(self) -> tuple[FingerLoad, ...]:
        nan = np.nan if self._results_port is None else 0.0
        return tuple(
            FingerLoad(_scoped_name(self._plant, f), False, nan, nan, np.nan, nan, 0.0)
            for f in self._bodies
        )

    def _sample(self, t, status, message, report, epsilon, x, start, *, grip):
        """A GraspSample; ``grip`` = (holding, loads, speeds, gap, last) or None."""
        if grip is None:
            grip = ("no contact", self._no_loads(), (np.nan, 0.0), 0, "no contact", ())
        holding, loads, (relative, sliding), gap, last, normals = grip
        code = {"ok": 1.0, "no contact": 0.0, "invalid": -1.0, "not sampled": 0.0}
        verdicts = np.concatenate(
            [
                analysis_verdicts(report, code[status], epsilon),
                grip_verdicts(holding, loads, relative, gap),
            ]
        )
        return GraspSample(
            time=float(t),
            status=status,
            message=message,
            report=report,
            epsilon=epsilon,
            holding=holding,
            loads=tuple(loads),
            relative_speed=relative,
            sliding_speed=sliding,
            last_normals=normals,
            contact_gap=gap,
            last_grip=last,
            names=self.verdict_names,
            verdicts=verdicts,
            state=x,
            seconds=_time.perf_counter() - start if start else 0.0,
        )

    def _validate(self, context) -> None:
        if not isinstance(context, Context):
            raise InvalidOptionError(
                f"expected this GraspMonitor's pydrake Context, got "
                f"{type(context).__name__}"
            )
        try:
            self.ValidateContext(context)
        except RuntimeError as e:
            raise InvalidOptionError(
                "this context belongs to another system; pass "
                "monitor.GetMyContextFromRoot(root_context) or "
                f"monitor.CreateDefaultContext() ({e})"
            ) from None

    def _contacts_and_loads(self, context, query):
        """(contacts for the analysis, per-finger loads); NoContactsError if none."""
        if self._results_port is not None:
            results = self._results_port.Eval(context)
            loads = finger_loads_from_results(
                self._plant,
                self._plant_context,
                results,
                query,
                object_body=self._body,
                fingers=self._bodies,
            )
            found = None
            try:
                found = contacts_from_results(
                    self._plant,
                    self._plant_context,
                    results,
                    query,
                    object_body=self._body,
                    hand=self._bodies,
                )
            except NoContactsError as e:
                return None, loads, e
            return found, loads, None
        o = self._options
        try:
            candidates = find_contacts(
                self._plant,
                self._plant_context,
                object_body=self._body,
                hand=self._bodies,
                distance_tolerance=o["distance_tolerance"],
                allow_penetration=o["allow_penetration"],
                patches=o["patches"],
                query_object=query,
            )
        except NoContactsError as e:
            return None, self._no_loads(), e
        found, loads = finger_motion_from_contacts(
            self._plant,
            self._plant_context,
            candidates,
            object_body=self._body,
            fingers=self._bodies,
            separation_speed=self._thresholds.separation_speed,
        )
        if not found:
            return (
                None,
                tuple(loads),
                NoContactsError(
                    f"every hand contact with {self._object_name!r} within the "
                    f"tolerance is separating faster than "
                    f"{self._thresholds.separation_speed:g} m/s"
                ),
            )
        return found, loads, None

    def evaluate(self, context: Context) -> GraspSample:
        """Analyse the grasp at the inputs of ``context`` (one sample).

        The holding state continues from the sample held in ``context``'s
        state (the previous sample).

        Raises
        ------
        InvalidOptionError
            If ``context`` is not a context of this monitor.
        """
        start = _time.perf_counter()
        self._validate(context)
        previous = context.get_abstract_state(self._report_index).get_value()
        t = context.get_time()
        x = np.array(self._state_port.Eval(context), dtype=float)
        if not np.all(np.isfinite(x)):
            bad = np.flatnonzero(~np.isfinite(x))
            return self._sample(
                t,
                "invalid",
                f"the plant state has non-finite entries at indices {bad[:8].tolist()}",
                None,
                0.0,
                x,
                start,
                grip=(
                    previous.holding,
                    previous.loads,
                    (np.nan, 0.0),
                    previous.contact_gap,
                    previous.last_grip,
                    previous.last_normals,
                ),
            )
        self._plant.SetPositionsAndVelocities(self._plant_context, x)
        query = self._query_port.Eval(context)
        status, message, report, epsilon = "ok", "", None, 0.0
        loads = self._no_loads()
        try:
            found, loads, missing = self._contacts_and_loads(context, query)
            if missing is not None:
                raise missing
            report = analyze_grasp(
                self._plant,
                self._plant_context,
                query_object=query,
                contacts=found,
                **self._options,
            )
        except NoContactsError as e:
            status, message = "no contact", str(e)
        except GraspError as e:  # the pose: penetration, a non-planar normal...
            status, message = "invalid", str(e)
        except (ValueError, ArithmeticError) as e:  # degenerate contact data
            status, message = "invalid", f"{type(e).__name__}: {e}"
        touching = tuple(
            (k, load.normal_W) for k, load in enumerate(loads) if load.touching
        )
        against = touching or previous.last_normals  # the last fingers if none now
        relative, sliding = speeds_against(
            self._plant,
            self._plant_context,
            self._body,
            [(self._bodies[k], n_W) for k, n_W in against],
        )
        if not touching:
            relative = np.nan
        uses = [f.friction_use for f in loads if not np.isnan(f.friction_use)]
        holding, gap, last = next_holding_state(
            previous.holding,
            previous.contact_gap,
            touching=bool(touching),
            grasped=report is not None and report.is_force_closure,
            friction_use=max(uses) if uses else np.nan,
            slip_speed=max(f.slip_speed for f in loads),
            sliding_away=sliding,
            last_grip=previous.last_grip,
            thresholds=self._thresholds,
        )
        if gap > 0 and previous.report is not None:  # bridge the gap
            status, report, epsilon = previous.status, previous.report, previous.epsilon
            message = f"no contact in this sample ({message}); the last grip is held"
        elif report is not None and self._compute_epsilon and report.is_force_closure:
            epsilon = float(
                ferrari_canny(report.grasp, num_generators=self._num_generators)
            )
        return self._sample(
            t,
            status,
            message,
            report,
            epsilon,
            x,
            start,
            grip=(holding, loads, (relative, sliding), gap, last, against),
        )

    def _update(self, context: Context, state: State) -> EventStatus:
        sample = self.evaluate(context)
        state.get_mutable_discrete_state(self._verdict_index).set_value(sample.verdicts)
        state.get_mutable_abstract_state(self._report_index).set_value(sample)
        return EventStatus.Succeeded()


def _unique_name(builder: DiagramBuilder, base: str) -> str:
    taken = {s.get_name() for s in builder.GetSystems()}
    if base not in taken:
        return base
    k = 2
    while f"{base}_{k}" in taken:
        k += 1
    return f"{base}_{k}"


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
        If an argument has the wrong type, the builder was already built, or
        the plant or scene graph is not in this builder.
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
    monitor = GraspMonitor(plant, **options)
    monitor.set_name(_unique_name(builder, name))
    builder.AddSystem(monitor)
    builder.Connect(plant.get_state_output_port(), monitor.get_plant_state_input_port())
    builder.Connect(
        scene_graph.get_query_output_port(), monitor.get_query_object_input_port()
    )
    if options.get("contacts", "geometry") == "contact_results":
        builder.Connect(
            plant.get_contact_results_output_port(),
            monitor.get_contact_results_input_port(),
        )
    return monitor
