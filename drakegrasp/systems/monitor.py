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

**Where the contacts come from** (``contacts=``):

- ``"geometry"`` (default): signed distances, as :func:`~drakegrasp.find_contacts`
  does outside a simulation (contact when ``|ψ| <= distance_tolerance``).  A
  simulated contact penetrates a little (point contact: ~0.1 mm for newtons of
  squeeze), so choose ``distance_tolerance`` above that (1e-3 m is a good start)
  or pass ``allow_penetration=True``.
- ``"contact_results"``: the contacts the plant's contact model used in the
  last step, read from the ``contact_results`` input
  (:func:`drakegrasp.plant.contacts_from_results`): with hydroelastic contact
  each contact surface becomes a patch polygon, point pairs become point
  contacts.

**Timing.**  Samples are unrestricted updates at ``offset + k * period`` (and
one at initialization); outputs are state, held between samples.  As with
any Drake discrete update, a logger publishing at a sample time ``t_k`` sees
the value held *before* the update at ``t_k``: the verdict logged at
``t_{k+1}`` is the analysis of the plant state logged at ``t_k``
(``GraspSample.time`` and ``GraspSample.state`` say exactly which).
A discrete plant's contact results are those of its last step; they exist in
the simulator's context, not in a fresh context where only ``q`` and ``v``
were set.

**Outputs.**  ``verdicts`` is a vector of :data:`VERDICT_NAMES` (index
constants ``GraspMonitor.STATUS`` ... ``GraspMonitor.EPSILON``):

=================  ===========================================================
``status``         1 analysed, 0 no contact, −1 invalid pose (e.g. penetration
                   deeper than the tolerance; the report says why)
``force_closure``  1 / 0: polyhedral force closure with the hand check LP3
``form_closure``   1 / 0: first-order form closure (LP1)
``antipodal``      1 / 0: two contacts that are antipodal (0 for other counts)
``num_contacts``   number of contacts analysed
``d_star``         LP2's ``d*`` (the force-closure margin), 0 without contact
``epsilon``        Ferrari–Canny ε (L1), 0 when not in force closure
=================  ===========================================================

``report`` is an abstract port holding a :class:`GraspSample`: the time, the
status, the full :class:`~drakegrasp.GraspReport` (None without one), ε, and
the plant state the sample was computed from.
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass

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
from drakegrasp.plant.analysis import GraspReport, analyze_grasp
from drakegrasp.plant.contact_results import contacts_from_results
from drakegrasp.plant.contacts import (
    DEFAULT_DISTANCE_TOLERANCE,
    HandSpec,
    _scoped_name,
    hand_bodies,
    resolve_object_body,
)
from drakegrasp.plant.jacobians import PLANES
from drakegrasp.quality import ferrari_canny

__all__ = [
    "VERDICT_NAMES",
    "GraspMonitor",
    "GraspSample",
    "add_grasp_monitor",
]

VERDICT_NAMES = (
    "status",
    "force_closure",
    "form_closure",
    "antipodal",
    "num_contacts",
    "d_star",
    "epsilon",
)
"""Names of the elements of :class:`GraspMonitor`'s ``verdicts`` output."""

_CONTACT_SOURCES = ("geometry", "contact_results")


@dataclass(frozen=True, eq=False)
class GraspSample:
    """One evaluation of the monitor.

    Attributes
    ----------
    time : float
        Simulation time of the sample, seconds.
    status : str
        ``"ok"``, ``"no contact"``, ``"invalid"`` (a pose the analysis refuses,
        e.g. deep penetration; see ``message``) or ``"not sampled"`` (before the
        first sample).
    message : str
        Why there is no report (the error's message), else ``""``.
    report : GraspReport or None
        The full analysis when ``status == "ok"``.
    epsilon : float
        Ferrari–Canny ε (L1 norm, moments divided by ``b``); 0 when not in
        force closure.
    verdicts : (7,) float
        The vector output, in :data:`VERDICT_NAMES` order.
    state : (nq + nv,) float
        The plant state the sample analysed.
    seconds : float
        Wall time the evaluation took.
    """

    time: float
    status: str
    message: str
    report: GraspReport | None
    epsilon: float
    verdicts: np.ndarray
    state: np.ndarray
    seconds: float

    def __deepcopy__(self, memo) -> GraspSample:
        # Drake copies abstract state values (by deepcopy for Python objects)
        # whenever it clones a context; a sample is never mutated, so sharing
        # it is safe and avoids copying Drake ids that cannot be pickled.
        return self

    @property
    def is_force_closure(self) -> bool:
        """Force closure (with LP3) in this sample."""
        return self.report is not None and self.report.is_force_closure

    def to_dict(self) -> dict:
        """JSON-ready dictionary (the report's own ``to_dict`` nested)."""
        return {
            "time": self.time,
            "status": self.status,
            "message": self.message,
            "verdicts": dict(
                zip(VERDICT_NAMES, (float(x) for x in self.verdicts), strict=True)
            ),
            "epsilon": self.epsilon,
            "state": self.state.tolist(),
            "seconds": self.seconds,
            "report": None if self.report is None else self.report.to_dict(),
        }

    def __str__(self) -> str:
        v = dict(zip(VERDICT_NAMES, self.verdicts, strict=True))
        if self.report is None:
            return f"t = {self.time:.4g} s: {self.status}" + (
                f" ({self.message})" if self.message else ""
            )
        yes = {True: "YES", False: "no"}
        return (
            f"t = {self.time:.4g} s: {int(v['num_contacts'])} contacts, force "
            f"closure {yes[bool(v['force_closure'])]}, form closure "
            f"{yes[bool(v['form_closure'])]}, d* = {v['d_star']:.4g}, "
            f"eps = {v['epsilon']:.4g}"
        )


def _verdicts(report: GraspReport | None, status: float, epsilon: float):
    if report is None:
        return np.array([status, 0, 0, 0, 0, 0, 0], dtype=float)
    antipodal = report.antipodal is not None and report.antipodal.is_antipodal
    return np.array(
        [
            status,
            float(report.force_closure.is_closure),
            float(report.form_closure.is_closure),
            float(antipodal),
            float(report.grasp.num_contacts),
            float(report.force_closure.d_star),
            epsilon,
        ]
    )


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
    contacts : {"geometry", "contact_results"}, optional
        Signed distances (default), or the plant's contact results (then the
        ``contact_results`` input port exists and must be connected).
    period : float, optional
        Seconds between samples (default 0.05).
    offset : float, optional
        Time of the first periodic sample (default 0); a sample is also taken
        at initialization.
    compute_epsilon : bool, optional
        Compute the Ferrari–Canny ε of force-closure samples (default True).

    Notes
    -----
    Input ports: ``plant_state`` (vector, ``nq + nv``), ``query_object``
    (abstract ``QueryObject``), and with ``contacts="contact_results"``
    ``contact_results`` (abstract ``ContactResults``).  Output ports:
    ``verdicts`` (vector, :data:`VERDICT_NAMES`) and ``report`` (abstract
    :class:`GraspSample`).  Both are state: they change only at samples.

    Raises
    ------
    InvalidOptionError
        For an unfinalized plant, a bad period or contact source, or options
        that :func:`drakegrasp.analyze_grasp` would refuse.
    """

    STATUS, FORCE_CLOSURE, FORM_CLOSURE, ANTIPODAL = 0, 1, 2, 3
    NUM_CONTACTS, D_STAR, EPSILON = 4, 5, 6

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
        compute_epsilon: bool = True,
    ):
        super().__init__()
        if not isinstance(plant, MultibodyPlant) or not plant.is_finalized():
            raise InvalidOptionError(
                f"GraspMonitor needs a finalized pydrake MultibodyPlant, got {plant!r}"
            )
        if contacts not in _CONTACT_SOURCES:
            raise InvalidOptionError(
                f"contacts must be one of {_CONTACT_SOURCES}, got {contacts!r}"
            )
        period, offset = float(period), float(offset)
        if not (np.isfinite(period) and period > 0):
            raise InvalidOptionError(f"period must be finite and > 0 s, got {period}")
        if not (np.isfinite(offset) and offset >= 0):
            raise InvalidOptionError(f"offset must be finite and >= 0 s, got {offset}")
        if plane is not None and plane not in PLANES:
            raise InvalidOptionError(
                f"plane must be one of {sorted(PLANES)} or None, got {plane!r}"
            )
        self._plant = plant
        body = resolve_object_body(plant, object_body)
        self._bodies = hand_bodies(plant, body, hand)
        self._object_name = _scoped_name(plant, body)
        self._contacts = contacts
        self._compute_epsilon = bool(compute_epsilon)
        self._num_generators = num_generators
        self._options = {
            "object_body": body,
            "hand": self._bodies,
            "mu": mu,
            "contact_model": ContactModel.parse(contact_model),
            "torsional_friction": torsional_friction,
            "distance_tolerance": distance_tolerance,
            "plane": plane,
            "characteristic_length": characteristic_length,
            "num_generators": num_generators,
            "tol": tol,
            "allow_penetration": allow_penetration,
            "patches": patches,
            "check_pose": bool(check_pose),
        }
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
        empty = GraspSample(
            time=0.0,
            status="not sampled",
            message="",
            report=None,
            epsilon=0.0,
            verdicts=_verdicts(None, 0.0, 0.0),
            state=np.zeros(nx),
            seconds=0.0,
        )
        self._verdict_index = self.DeclareDiscreteState(len(VERDICT_NAMES))
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
        """Output: the verdict vector (:data:`VERDICT_NAMES`)."""
        return self.GetOutputPort("verdicts")

    def get_report_output_port(self):
        """Output: the latest :class:`GraspSample`."""
        return self.GetOutputPort("report")

    # The evaluation ------------------------------------------------------
    def evaluate(self, context: Context) -> GraspSample:
        """Analyse the grasp at the inputs of ``context`` (one sample)."""
        start = _time.perf_counter()
        x = np.array(self._state_port.Eval(context), dtype=float)
        self._plant.SetPositionsAndVelocities(self._plant_context, x)
        query = self._query_port.Eval(context)
        status, message, report, epsilon = "ok", "", None, 0.0
        try:
            found = None
            if self._results_port is not None:
                found = contacts_from_results(
                    self._plant,
                    self._plant_context,
                    self._results_port.Eval(context),
                    query,
                    object_body=self._options["object_body"],
                    hand=self._bodies,
                )
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
        if report is not None and self._compute_epsilon and report.is_force_closure:
            epsilon = float(
                ferrari_canny(report.grasp, num_generators=self._num_generators)
            )
        code = {"ok": 1.0, "no contact": 0.0, "invalid": -1.0}[status]
        return GraspSample(
            time=float(context.get_time()),
            status=status,
            message=message,
            report=report,
            epsilon=epsilon,
            verdicts=_verdicts(report, code, epsilon),
            state=x,
            seconds=_time.perf_counter() - start,
        )

    def _update(self, context: Context, state: State) -> EventStatus:
        sample = self.evaluate(context)
        state.get_mutable_discrete_state(self._verdict_index).set_value(sample.verdicts)
        state.get_mutable_abstract_state(self._report_index).set_value(sample)
        return EventStatus.Succeeded()


def add_grasp_monitor(
    builder: DiagramBuilder,
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
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
    **options
        Keyword arguments of :class:`GraspMonitor`.

    Returns
    -------
    GraspMonitor
        Connected to the plant's state, the scene graph's query output and, with
        ``contacts="contact_results"``, the plant's contact results.
    """
    for name, value, kind in (
        ("builder", builder, DiagramBuilder),
        ("plant", plant, MultibodyPlant),
        ("scene_graph", scene_graph, SceneGraph),
    ):
        if not isinstance(value, kind):
            raise InvalidOptionError(
                f"add_grasp_monitor: {name} must be a pydrake {kind.__name__}, got "
                f"a {type(value).__name__}"
            )
    monitor = builder.AddSystem(GraspMonitor(plant, **options))
    monitor.set_name("grasp_monitor")
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
