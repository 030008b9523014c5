"""The grasp monitor System: a ``LeafSystem`` that samples a grasp's analysis.

See :mod:`drakegrasp.systems.monitor` for what the monitor sees in each
contact mode, its timing and its outputs; this module holds the System
itself: its ports, its state and one sample (:meth:`GraspMonitor.evaluate`).
"""

from __future__ import annotations

import dataclasses
import math
import time as _time
import warnings
from collections.abc import Sequence

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import QueryObject, SceneGraph
from pydrake.multibody.plant import ContactResults, MultibodyPlant
from pydrake.multibody.tree import BodyIndex
from pydrake.systems.framework import Context, EventStatus, LeafSystem, State

from drakegrasp.core.calls import checked_call
from drakegrasp.core.contact import ContactModel
from drakegrasp.core.deprecation import outside_stacklevel
from drakegrasp.core.tolerances import (
    DEFAULT_DISTANCE_TOLERANCE,
    DEFAULT_NUM_GENERATORS,
    DEFAULT_TOL,
)
from drakegrasp.core.validation import describe
from drakegrasp.errors import (
    GraspError,
    InvalidOptionError,
    ModelError,
    NoContactsError,
)
from drakegrasp.plant.analysis import analyze_grasp
from drakegrasp.plant.contacts import (
    HandSpec,
    _scoped_name,
    resolve_object_body,
)
from drakegrasp.plant.couplings import coupling_map, plant_couplings
from drakegrasp.plant.friction import (
    FrictionMismatchWarning,
    friction_disagreement,
    plant_friction,
)
from drakegrasp.plant.jacobians import hand_velocity_indices
from drakegrasp.plant.options import AnalysisOptions
from drakegrasp.plant.validation import hand_contact_bodies, plant_context_of
from drakegrasp.quality import ferrari_canny
from drakegrasp.quality.epsilon import L1_MAX_POINTS, primitive_wrenches
from drakegrasp.systems.holding import (
    HoldingMemory,
    HoldingThresholds,
    next_holding_state,
)
from drakegrasp.systems.monitor_options import monitor_settings
from drakegrasp.systems.sample import (
    GraspSample,
    analysis_verdicts,
    grip_verdicts,
    verdict_names,
)
from drakegrasp.systems.sensing import (
    anchor_fingers,
    hand_clearance,
    motion_against,
    no_loads,
    sense_contacts,
)

__all__ = ["GraspMonitor", "epsilon_l1"]


def _one_line(error: BaseException) -> str:
    """An exception's text on one line (Drake's are often several)."""
    return " ".join(str(error).split())


_STATUS_CODE = {"ok": 1.0, "no contact": 0.0, "invalid": -1.0, "not sampled": 0.0}


def epsilon_l1(grasp, *, num_generators: int) -> float:
    """Ferrari–Canny ε (L1) of one grasp, by the batch engine's compiled kernel.

    The same ε as :func:`~drakegrasp.quality.ferrari_canny` (the same primitive
    wrenches, moments divided by the grasp's characteristic length) found by
    the expanding polytope of :mod:`drakegrasp.batch.epsilon.kernel`: only the
    facets near the origin are built, about 1 ms for 8 contacts where Qhull's
    whole hull takes 20-30 ms.  Its answer agrees with Qhull's to about 1e-13
    relative; a grasp the kernel flags (round-off could spoil it), a grasp
    past :data:`~drakegrasp.core.tolerances.L1_MAX_POINTS` wrenches, or an
    install without numba takes :func:`~drakegrasp.quality.ferrari_canny`.
    The kernel compiles on first use unless ``drakegrasp warmup`` ran.
    """
    import drakegrasp.batch.epsilon.kernel as kernel

    W = np.vstack(primitive_wrenches(grasp, num_generators=num_generators))
    if kernel.AVAILABLE and W.shape[0] <= L1_MAX_POINTS:
        eps, status = kernel.epsilon_l1_stack(W[None])
        if status[0] <= kernel.FLAT:  # OK, or a flat set: eps = 0
            return float(eps[0])
    return float(ferrari_canny(grasp, num_generators=num_generators))


def _monitor_couplings(plant: MultibodyPlant, couplings, bodies) -> tuple:
    """The couplings of every sample, checked once against the finalized plant.

    The plant's constraints, the recorded couplings and the hand's joints
    cannot change after ``Finalize``, so couplings that
    :func:`~drakegrasp.analyze_grasp` would refuse at every sample are
    refused here: the plant's with the way out, given ones as they are (a
    joint that both leads and follows, an unknown joint...).
    """
    try:
        resolved = plant_couplings(plant, couplings)
    except InvalidOptionError as e:
        if couplings is not None:  # a bad given value: its own message
            raise
        raise InvalidOptionError(
            f"GraspMonitor cannot analyse this plant, every sample would be "
            f"invalid: {e}"
        ) from None
    # checks every entry against the plant, as each sample's analysis would
    coupling_map(plant, hand_velocity_indices(plant, bodies), resolved)
    return resolved


@checked_call
class GraspMonitor(LeafSystem):
    """Analyse the grasp of a simulated plant every ``period`` seconds.

    Parameters
    ----------
    plant : MultibodyPlant
        The finalized plant of the simulation (registered with a SceneGraph).
    object_body, hand
        As in :func:`drakegrasp.analyze_grasp`, and resolved as it resolves
        them (:func:`~drakegrasp.plant.validation.hand_contact_bodies`): the
        hand's bodies include those welded to the world, so a palm that
        touches the object gives contacts, verdicts and a holding state, as
        in :func:`~drakegrasp.analyze_grasp` on the same state.
    couplings : sequence of (joint_0, joint_1, gear_ratio, offset), optional
        As in :func:`drakegrasp.analyze_grasp`: the joint couplings of the
        hand (``()`` for none).  When not given, the couplings recorded as the
        models entered the plant
        (:func:`~drakegrasp.plant.couplings.plant_couplings`); a plant with a
        constraint that was not recorded (a ``<mimic>`` parsed by a bare
        ``Parser``) is refused here, since every sample's analysis would
        refuse it.
    options : AnalysisOptions, optional
        The analysis options of every sample, validated when they were made;
        give them or the keywords below, not both.  A ``load`` in them (or
        ``load=``) adds the load section to every sample's report, and the
        holding state then judges a grip by it.
    mu : float or "plant"
        Friction coefficient of the analysis, or ``"plant"``: each contact's
        coefficient from its geometries' proximity properties.  Required (here
        or in ``options``) with ``contacts="geometry"``; with
        ``contacts="contact_results"`` (the simulator's own contacts) it is
        ``"plant"`` when not given.  A number that disagrees with the plant's friction
        at the contacts is warned about once per monitor
        (:class:`~drakegrasp.plant.friction.FrictionMismatchWarning`) and kept
        in :attr:`friction_warning`.  Friction in use is always computed with
        the plant's own coefficients.
    contact_model, torsional_friction, distance_tolerance, plane
        As in :func:`drakegrasp.analyze_grasp` (or ``options``).
    characteristic_length, num_generators, tol, allow_penetration, patches
        As in :func:`drakegrasp.analyze_grasp` (or ``options``).
    load, torque_limits : optional
        As in :func:`drakegrasp.analyze_grasp` (or ``options``): the load
        section of every sample (``load="gravity"``, ``torque_limits="plant"``:
        the object's weight and the actuators' effort limits).  With it, a
        grip is ``holding`` when the load section holds (and its contacts
        stick), whatever force closure with the hand check says: LP3 fails for
        fingers that touch at several points each (the Franka hand's pads on
        the YCB soup can), which hold.
    check_pose : bool, optional
        As in :func:`drakegrasp.analyze_grasp`: a pose that the check refuses
        (a joint off its limits; penetration deeper than
        ``distance_tolerance`` by any hand body where ``allow_penetration`` is
        False) gives an ``"invalid"`` sample, not an exception.
    coupling_tolerance : float, optional
        The largest break of a joint coupling (m or rad) a sample's pose may
        have (:class:`~drakegrasp.AnalysisOptions`); default (None)
        :data:`~drakegrasp.core.tolerances.MONITOR_COUPLING_TOL` (1 mrad):
        Drake's coupler constraints give under load (SAP held a three-finger
        hand's ``<mimic>`` distal joints 7 µrad off at 0.5 N·m, and at an
        analysis's 1e-6 every sample of that grip was ``"invalid"``).  Given
        ``options=``, its ``coupling_tolerance`` is used.
    allow_penetration : bool, optional
        As in :func:`drakegrasp.analyze_grasp`; default (None) True: the
        simulator's contacts penetrate to make their force (the WSG-50
        squeezing a box with 20 N sinks 0.145 mm into it in point contact:
        with penetration refused, every sample of that grip was
        ``"invalid"``).  False makes such a sample ``"invalid"``; with
        ``contacts="contact_results"`` penetration is always allowed.  Given
        ``options=``, its ``allow_penetration`` is used (an
        :class:`~drakegrasp.AnalysisOptions` defaults to an analysis's False:
        give it True for a simulation).
    contacts : {"geometry", "contact_results"}, optional
        Signed distances (default), or the plant's contact results (then the
        ``contact_results`` input port exists and must be connected).  See
        :mod:`drakegrasp.systems.monitor` for what each can see.
    period : float, optional
        Seconds between samples (default 0.05, at least
        :data:`~drakegrasp.systems.monitor_options.MIN_PERIOD`).  A sample
        that finds a discrete plant not stepped since the one before (a
        period shorter than its time step) repeats that sample: the
        hysteresis counts plant states.
    offset : float, optional
        Time of the first periodic sample (default 0); a sample is also taken
        at initialization.
    compute_epsilon : bool, optional
        Compute the Ferrari–Canny ε of force-closure samples (default False;
        NaN, and the sample's message says why, where the metric refuses the
        sample's grasp: a ``characteristic_length`` out of scale with its
        contacts, see :data:`~drakegrasp.core.tolerances.MOMENT_ARMS`, or more
        primitive wrenches than it takes), with the batch engine's compiled
        kernel
        (:func:`~drakegrasp.systems.grasp_monitor.epsilon_l1`: about
        1 ms for 8 contacts, compiled when the package was installed; an
        install without those kernels compiles it once, or ``drakegrasp
        warmup`` does up front).
    holding : HoldingThresholds, optional
        Thresholds of the holding state and the hysteresis (default
        ``HoldingThresholds()``).

    Notes
    -----
    Input ports: ``plant_state`` (vector, ``nq + nv``), ``query_object``
    (abstract ``QueryObject``), and with ``contacts="contact_results"``
    ``contact_results`` (abstract ``ContactResults``).  Output ports:
    ``verdicts`` (vector, :attr:`verdict_names`) and ``report`` (abstract
    :class:`~drakegrasp.systems.sample.GraspSample`).  Both are state: they
    change only at samples.

    The monitor is a Python system that holds the plant it analyses, and has
    no scalar conversion: ``Clone()`` and ``ToAutoDiffXd()`` of it, or of a
    diagram that contains it, raise Drake's ``RuntimeError`` ("does not
    support Cloning").  Build the diagram again for each copy (one per
    process in a parallel sweep); a context can be cloned as usual.

    Raises
    ------
    InvalidOptionError
        For an unfinalized plant, a bad period, offset, flag or contact
        source, ``options`` next to a keyword, options that
        :class:`~drakegrasp.AnalysisOptions` refuses, a bad coupling, or,
        without ``couplings``, a plant with constraints that drakegrasp has
        not recorded as couplings.
    ModelError
        For an unknown object or hand body or model instance.
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
        couplings: Sequence[tuple] | None = None,
        options: AnalysisOptions | None = None,
        mu: float | str | None = None,
        contact_model: ContactModel | str = ContactModel.HARD_FINGER,
        torsional_friction: float | None = None,
        distance_tolerance: float = DEFAULT_DISTANCE_TOLERANCE,
        plane: str | None = None,
        characteristic_length: float | None = None,
        num_generators: int = DEFAULT_NUM_GENERATORS,
        tol: float = DEFAULT_TOL,
        allow_penetration: bool | None = None,
        patches: str = "vertices",
        check_pose: bool = True,
        coupling_tolerance: float | None = None,
        load: str | Sequence[float] | None = None,
        torque_limits: str | Sequence[float] | None = None,
        contacts: str = "geometry",
        period: float = 0.05,
        offset: float = 0.0,
        compute_epsilon: bool = False,
        holding: HoldingThresholds | None = None,
    ):
        super().__init__()
        if not isinstance(plant, MultibodyPlant) or not plant.is_finalized():
            raise InvalidOptionError(
                "GraspMonitor needs a finalized pydrake MultibodyPlant, got "
                f"{describe(plant)}"
            )
        if not plant.geometry_source_is_registered():
            raise ModelError(
                "the plant is not registered with a SceneGraph, so it has no "
                "geometry to find contacts in: build it with "
                "AddMultibodyPlantSceneGraph"
            )
        self.settings = monitor_settings(
            options,
            contacts=contacts,
            period=period,
            offset=offset,
            compute_epsilon=compute_epsilon,
            holding=holding,
            mu=mu,
            contact_model=contact_model,
            torsional_friction=torsional_friction,
            distance_tolerance=distance_tolerance,
            plane=plane,
            characteristic_length=characteristic_length,
            num_generators=num_generators,
            tol=tol,
            allow_penetration=allow_penetration,
            patches=patches,
            check_pose=check_pose,
            coupling_tolerance=coupling_tolerance,
            load=load,
            torque_limits=torque_limits,
        )
        """The validated options (a ``MonitorSettings``)."""
        self.period = self.settings.period
        """Seconds between samples."""
        self.friction_warning: str | None = None
        """Why the given ``mu`` is not the plant's friction (None until seen)."""
        self._plant = plant
        self._body = resolve_object_body(plant, object_body)
        if self._body.index() == plant.world_body().index():
            raise ModelError(
                "object_body is the world body: monitor the grasped object's body"
            )
        if not plant.GetCollisionGeometriesForBody(self._body):
            # knowable now: every sample would be invalid for it
            raise ModelError(
                f"object_body {_scoped_name(plant, self._body)} has no collision "
                "geometry, so no hand body can touch it: monitor the body that "
                "carries the object's collision geometry"
            )
        # The hand as analyze_grasp resolves it: a welded palm touches too.
        self._bodies = hand_contact_bodies(plant, self._body, hand)
        self.couplings = _monitor_couplings(plant, couplings, self._bodies)
        """The joint couplings every sample's analysis uses (checked here)."""
        self.verdict_names = verdict_names(
            [_scoped_name(plant, f) for f in self._bodies]
        )
        """Names of the ``verdicts`` output's elements."""
        self._plant_context = plant.CreateDefaultContext()
        self._declare_ports_and_state(plant.num_multibody_states())

    def _declare_ports_and_state(self, nx: int) -> None:
        self._state_port = self.DeclareVectorInputPort("plant_state", nx)
        self._query_port = self.DeclareAbstractInputPort(
            "query_object", AbstractValue.Make(QueryObject())
        )
        self._results_port = None
        if self.settings.contacts == "contact_results":
            self._results_port = self.DeclareAbstractInputPort(
                "contact_results", AbstractValue.Make(ContactResults())
            )
        empty = self._sample(
            0.0, "not sampled", "", None, 0.0, np.zeros(nx), 0.0, grip=None
        )
        self._unsampled = empty  # what a run starts from
        self._verdict_index = self.DeclareDiscreteState(len(self.verdict_names))
        self._report_index = self.DeclareAbstractState(AbstractValue.Make(empty))
        self.DeclareStateOutputPort("verdicts", self._verdict_index)
        self.DeclareStateOutputPort("report", self._report_index)
        self.DeclareInitializationUnrestrictedUpdateEvent(self._update)
        self.DeclarePeriodicUnrestrictedUpdateEvent(
            self.settings.period, self.settings.offset, self._update
        )

    # Ports ---------------------------------------------------------------
    def use_parameters_of(self, plant_context: Context) -> None:
        """Analyse with the parameters (masses, inertias, ...) of a plant context.

        Each sample is analysed in a plant context of the monitor's own, made
        with the model's default parameters: a mass set in the simulation's
        context (``body.SetMass(plant_context, m)``, as mass randomisation
        does) reaches no input port.  Call this with the simulation's plant
        context (or its root context) after changing them, before the next
        sample; only the parameters are copied.  They are the monitor's, not
        a context's: simulators that share one diagram share them too.

        Raises
        ------
        InvalidContextError
            A context that is not of the monitored plant.
        """
        source = plant_context_of(self._plant, plant_context)
        self._plant_context.get_mutable_parameters().SetFrom(source.get_parameters())

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
        """Output: the latest :class:`~drakegrasp.systems.sample.GraspSample`."""
        return self.GetOutputPort("report")

    # One sample ----------------------------------------------------------
    def _no_loads(self):
        return no_loads(
            self._plant, self._bodies, forces_seen=self._results_port is not None
        )

    def _sample(self, t, status, message, report, epsilon, x, start, *, grip):
        """A GraspSample; ``grip`` = (memory, loads, speeds, normals)."""
        if grip is None:
            grip = (HoldingMemory(), self._no_loads(), (np.nan, 0.0), ())
        memory, loads, (relative, sliding), anchors = grip
        gap = memory.bridged(self.settings.thresholds)
        verdicts = np.concatenate(
            [
                analysis_verdicts(report, _STATUS_CODE[status], epsilon),
                grip_verdicts(memory.state, loads, relative, gap),
            ]
        )
        return GraspSample(
            time=float(t),
            status=status,
            message=message,
            report=report,
            epsilon=epsilon,
            holding=memory.state,
            loads=tuple(loads),
            relative_speed=relative,
            sliding_speed=sliding,
            anchors=anchors,
            contact_gap=gap,
            memory=memory,
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
                "monitor.GetMyContextFromRoot(root_context) (the root context of "
                "the diagram that holds the monitor), or a "
                "monitor.CreateDefaultContext() whose input ports were given "
                f"values with FixValue ({_one_line(e)})"
            ) from None
        ports = [self._state_port, self._query_port]
        if self._results_port is not None:
            ports.append(self._results_port)
        missing = [port.get_name() for port in ports if not port.HasValue(context)]
        if missing:
            values = {
                "plant_state": "the plant's [q; v]",
                "query_object": "the scene graph's QueryObject",
                "contact_results": "the plant's ContactResults",
            }
            several = len(missing) > 1
            raise InvalidOptionError(
                f"GraspMonitor {self.get_name()!r}: input port"
                f"{'s' if several else ''} {', '.join(missing)} "
                f"{'are' if several else 'is'} neither connected nor fixed in "
                "this context; connect the monitor in a diagram "
                "(add_grasp_monitor(builder, plant, scene_graph, ...) does) and "
                "pass monitor.GetMyContextFromRoot(root_context), or give "
                f"{'each' if several else 'it'} a value with "
                "port.FixValue(context, value) ("
                + "; ".join(f"{name}: {values[name]}" for name in missing)
                + ")"
            )

    def _pose_problem(self, x: np.ndarray) -> str | None:
        """Why Drake cannot place the bodies at the plant state ``x`` (or None).

        A finite state can still be degenerate: a free body's quaternion of
        zeros has no rotation.  Every body's pose is computed at once, so one
        bad quaternion anywhere makes the whole sample unmeasurable.
        """
        try:
            self._plant.EvalBodyPoseInWorld(self._plant_context, self._body)
        except RuntimeError as e:
            plant = self._plant
            zero = []
            for i in range(plant.num_bodies()):
                body = plant.get_body(BodyIndex(i))
                if body.is_floating_base_body() and body.has_quaternion_dofs():
                    k = body.floating_positions_start()
                    if not np.any(x[k : k + 4]):
                        zero.append(_scoped_name(plant, body))
            which = f" (the quaternion of {', '.join(map(repr, zero))} is zero)"
            return (
                "Drake cannot compute the body poses of this plant state"
                f"{which if zero else ''}: {_one_line(e)}"
            )
        return None

    def _query_problem(self, query) -> str | None:
        """Why the ``query_object`` input cannot serve this plant (or None)."""
        try:  # a default-constructed QueryObject answers no query
            query.GetPoseInWorld(SceneGraph.world_frame_id())
        except RuntimeError as e:
            if "invalid QueryObject" in str(e):
                return (
                    "the query_object input holds no scene graph's query "
                    f"({_one_line(e)}); connect scene_graph.get_query_output_port() "
                    "to it, or fix it to a value of that port"
                )
            return (  # its scene graph's poses: a bad state of the plant it reads
                f"Drake cannot answer the query_object input's queries: {_one_line(e)}"
            )
        source = self._plant.get_source_id()
        if source is not None and not query.inspector().SourceIsRegistered(source):
            return (
                "the query_object input comes from a scene graph that the plant "
                f"{self._plant.get_name()!r} is not registered with; connect the "
                "query output port of the plant's own scene graph"
            )
        return None

    def _check_friction(self, contacts, query) -> None:
        """Warn, once, when the given ``mu`` is not the plant's at ``contacts``."""
        mu = self.settings.analysis.mu
        if self.friction_warning is not None or isinstance(mu, str):
            return
        try:
            mu_plant = plant_friction(
                self._plant, self._plant_context, contacts, query_object=query
            )
        except ModelError:  # a geometry without friction: nothing to compare
            return
        message = friction_disagreement(self._plant, mu, mu_plant)
        if message is not None:
            self.friction_warning = message
            warnings.warn(
                f"GraspMonitor {self.get_name()!r}: {message}",
                FrictionMismatchWarning,
                stacklevel=outside_stacklevel(),
            )

    def _analyse(self, context, query):
        """(status, message, report, loads) of the plant state in the context."""
        sensed = None
        try:
            results = None
            if self._results_port is not None:
                results = self._results_port.Eval(context)
            sensed = sense_contacts(
                self._plant,
                self._plant_context,
                query,
                object_body=self._body,
                fingers=self._bodies,
                analysis=self.settings.analysis,
                thresholds=self.settings.thresholds,
                contact_results=results,
            )
            if sensed.missing is not None:
                return "no contact", str(sensed.missing), None, sensed.loads
            self._check_friction(sensed.contacts, query)
            report = analyze_grasp(
                self._plant,
                self._plant_context,
                self._body,
                hand=self._bodies,
                options=self.settings.analysis,
                query_object=query,
                contacts=sensed.contacts,
                couplings=self.couplings,
            )
            deep = self._too_deep(report)
            if deep:
                return "invalid", deep, None, sensed.loads
            return "ok", "", report, sensed.loads
        except NoContactsError as e:
            status, message = "no contact", str(e)
        except GraspError as e:  # the pose: penetration, a non-planar normal...
            status, message = "invalid", str(e)
        except (ValueError, ArithmeticError) as e:  # degenerate contact data
            status, message = "invalid", f"{type(e).__name__}: {e}"
        except RuntimeError as e:  # Drake refused the sample's inputs
            if type(e) is not RuntimeError:  # NotImplementedError, RecursionError
                raise
            status = "invalid"
            message = f"Drake cannot sense this sample: {_one_line(e)}"
        # None: the contacts were not sensed (a penetration deeper than the
        # tolerance, a Drake error), which says nothing about the grip.
        loads = None if sensed is None else sensed.loads
        return status, message, None, loads

    def _too_deep(self, report) -> str:
        """Why ``report``'s hand sinks too deep to judge, or "".

        Deeper than ``HoldingThresholds.max_penetration`` (where penetration
        is allowed; else the analysis refused it already).
        """
        pose = report.pose
        if pose is None or not pose.penetrations:
            return ""
        deepest = max(pose.penetrations, key=lambda p: p.depth)
        bound = self.settings.thresholds.max_penetration
        if deepest.depth <= bound:
            return ""
        return (
            f"{deepest}: deeper than max_penetration ({bound * 1e3:g} mm), no "
            "grip to judge (raise HoldingThresholds.max_penetration for a "
            "softer contact)"
        )

    def evaluate(self, context: Context) -> GraspSample:
        """Analyse the grasp at the inputs of ``context`` (one sample).

        The holding state continues from the sample held in ``context``'s
        state (the previous sample).  A plant state that Drake cannot place
        (non-finite entries, a free body's quaternion of zeros) or a
        ``query_object`` input that is not the plant's scene graph's gives an
        ``"invalid"`` sample that says why and keeps the holding state before
        it; so does a sample whose contacts cannot be sensed (a penetration
        deeper than the distance tolerance, a Drake error while sensing): a
        finger pressed that deep into the object has not let it go (a re-grip
        of a 1.5 kg box at 147 N read "dropped"), and so does a sample whose
        contacts were sensed but whose analysis failed (a joint off its
        limits): the holding state judges a grip by its analysis, and without
        one it would call every grip "touching" (not in force closure).  So
        the holding state, its loads and its speeds are those of the last
        valid sample, and "no contact" (the initial state) before any.  A
        hand sunk deeper into the object than
        ``HoldingThresholds.max_penetration`` gives an ``"invalid"`` sample
        too, where penetration is allowed.

        A sample that finds a discrete plant not stepped since the sample
        held (no update time of the plant between the two, and the same
        state: a period shorter than the plant's time step, or the periodic
        sample at the time of the initialization one) is that sample again,
        at its own time: the same evidence is judged once, so the hysteresis
        counts plant states, not samples (a period of 0.7 ms on a 1 ms plant
        judged 512 of 1712 states twice, and a single step's evidence turned
        "at risk" into "touching").  A plant that stepped and came to the
        very same state, at rest, is judged again: its rest is evidence.

        A sample earlier than the one held (a simulator restarted at time 0,
        its context's time set back) starts a new run: it continues from
        nothing ("no contact", no anchors), not from the last run's grip,
        which a restart would otherwise keep (a box dropped in one run was
        "dropped" through the next run's approach, untouched).

        Raises
        ------
        InvalidOptionError
            If ``context`` is not a context of this monitor, or one of its
            input ports is neither connected nor fixed in it.
        """
        start = _time.perf_counter()
        self._validate(context)
        previous = context.get_abstract_state(self._report_index).get_value()
        t = context.get_time()
        if t < previous.time:  # the clock went back: a new run, not a continuation
            previous = self._unsampled
        x = np.array(self._state_port.Eval(context), dtype=float)
        # An invalid sample keeps the grip before it: it is no evidence.
        kept = (previous.memory, previous.loads, (np.nan, 0.0), previous.anchors)
        if (
            previous.status != "not sampled"
            and t >= previous.time
            and _plant_steps(self._plant, t) == _plant_steps(self._plant, previous.time)
            and np.array_equal(x, previous.state, equal_nan=True)
        ):  # the plant has not stepped since: the same evidence, judged once
            return dataclasses.replace(
                previous, time=float(t), seconds=_time.perf_counter() - start
            )
        if not np.all(np.isfinite(x)):
            bad = np.flatnonzero(~np.isfinite(x))
            message = (
                f"the plant state has non-finite entries at indices {bad[:8].tolist()}"
            )
            return self._sample(t, "invalid", message, None, 0.0, x, start, grip=kept)
        self._plant.SetPositionsAndVelocities(self._plant_context, x)
        query = self._query_port.Eval(context)
        problem = self._pose_problem(x) or self._query_problem(query)
        if problem is not None:
            return self._sample(t, "invalid", problem, None, 0.0, x, start, grip=kept)
        status, message, report, loads = self._analyse(context, query)
        if status == "invalid" or loads is None:  # kept, neither lost nor judged
            return self._sample(t, status, message, None, 0.0, x, start, grip=kept)
        grip = self._grip(previous, report, loads, query)
        epsilon = 0.0
        if grip[0].bridged(self.settings.thresholds) and previous.report is not None:
            status, report, epsilon = previous.status, previous.report, previous.epsilon
            why = f" ({message})" if message else ""
            message = f"no contact in this sample{why}; the last grip is held"
        elif (
            report is not None
            and self.settings.compute_epsilon
            and report.is_force_closure
        ):
            try:
                epsilon = epsilon_l1(
                    report.grasp, num_generators=self.settings.analysis.num_generators
                )
            except InvalidOptionError as e:  # the metric refuses this grasp
                epsilon = float("nan")
                why = f"epsilon not computed: {_one_line(e)}"
                message = f"{message}; {why}" if message else why
        return self._sample(t, status, message, report, epsilon, x, start, grip=grip)

    @staticmethod
    def _grasped(report, loads) -> bool:
        """A grip that holds, and every analysed finger presses on the object.

        "Holds" is the load section's verdict when the options give a load
        (the motors hold that load at these contacts), else force closure.
        """
        if report is None:
            return False
        holds = report.is_force_closure if report.load is None else report.load.holds
        if not holds:
            return False
        pressing = {load.finger_body for load in loads if load.touching}
        return all(c.finger_body in pressing for c in report.contacts)

    def _grip(self, previous: GraspSample, report, loads, query):
        """The grip after ``previous``: (memory, loads, speeds, anchors)."""
        touching = [(k, load.normal_W) for k, load in enumerate(loads) if load.touching]
        anchors = previous.anchors  # the fingers that touched last, if none now
        if touching:
            anchors = anchor_fingers(
                self._plant, self._plant_context, self._body, self._bodies, touching
            )
        motion = motion_against(
            self._plant, self._plant_context, self._body, self._bodies, anchors
        )
        relative = motion.relative if touching else np.nan
        uses = [f.friction_use for f in loads if not np.isnan(f.friction_use)]
        thresholds = self.settings.thresholds

        def clearance() -> float:  # NaN when unmeasurable: never out of reach
            try:
                return hand_clearance(
                    self._plant,
                    query,
                    object_body=self._body,
                    fingers=self._bodies,
                    horizon=2.0 * thresholds.release_distance,
                )
            except ModelError:
                return np.nan

        memory = next_holding_state(
            previous.memory,
            touching=bool(touching),
            grasped=self._grasped(report, loads),
            friction_use=max(uses) if uses else np.nan,
            slip_speed=max(f.slip_speed for f in loads),
            sliding=motion.along,
            slid=0.0 if touching else motion.slid,
            clearance=clearance,
            thresholds=thresholds,
            relative=0.0 if touching else motion.relative,
        )
        return memory, loads, (relative, motion.sliding), anchors

    def _update(self, context: Context, state: State) -> EventStatus:
        sample = self.evaluate(context)
        state.get_mutable_discrete_state(self._verdict_index).set_value(sample.verdicts)
        state.get_mutable_abstract_state(self._report_index).set_value(sample)
        return EventStatus.Succeeded()


def _plant_steps(plant, t: float) -> float:
    """How many of a discrete plant's updates a sample at ``t`` sees (s).

    A discrete plant updates at ``0, h, 2h, ...``; a sample at ``t`` sees the
    state before the update at ``t`` itself (Drake's discrete updates at one
    time all read the state before them), so those at times below ``t``:
    ``ceil(t / h)``.  A continuous plant (``h = 0``) changes at every time:
    ``t`` itself, so that two samples never count as one.
    """
    h = plant.time_step()
    return math.ceil(t / h - 1e-9) if h > 0 else t
