"""One validator for every plant-layer function: plant, context, bodies, hand.

Every function of :mod:`drakegrasp.plant` that takes ``(plant, plant_context)``
accepts either the plant's own context or the **root context** of the diagram
that holds the plant (what a simulation hands its user), and resolves it with
:func:`plant_context_of`.  Indices and names are checked here, before Drake
sees them: Drake aborts the interpreter (``SystemExit``) on an out-of-range
``ModelInstanceIndex``.

**Argument order.**  Everywhere in the plant layer ``object_body`` may be given
positionally, right after the essential arguments
(``find_contacts(plant, plant_context, object_body)``,
``signed_distance_jacobian(plant, plant_context, contacts, object_body)``) or
by keyword; every option after it is keyword-only.
"""

from __future__ import annotations

import contextlib
import reprlib
from collections.abc import Iterable, Iterator
from contextvars import ContextVar

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import BodyIndex, JointIndex, ModelInstanceIndex, RigidBody
from pydrake.systems.framework import Context

from drakegrasp.core.calls import checked_call
from drakegrasp.core.deferred import WeakMemo
from drakegrasp.core.tolerances import QUERY_POSE_TOL
from drakegrasp.core.validation import (
    describe,
    integer_or_none,
    items_of,
    plain_str,
)
from drakegrasp.errors import (
    GraspError,
    InvalidContextError,
    InvalidOptionError,
    InvalidPoseError,
    ModelError,
    type_name,
)
from drakegrasp.plant.attachment import joined

__all__ = [
    "ROTATION_TOL",
    "HandSpec",
    "check_bodies",
    "check_plant",
    "checked_context",
    "checked_query_object",
    "check_rigid_transform",
    "check_velocity_indices",
    "hand_bodies",
    "hand_contact_bodies",
    "hand_model_instances",
    "model_instance",
    "pair_distance",
    "plant_context_of",
    "query_object_of",
    "resolve_body",
    "resolve_grasped_body",
    "resolve_object_body",
    "scoped_name",
]

HandSpec = ModelInstanceIndex | str | Iterable[RigidBody] | None

ROTATION_TOL = 1e-6
"""Largest entry of ``RᵀR − I`` of a pose's rotation (a proper rotation)."""

_CHECKED: ContextVar[tuple[MultibodyPlant, Context] | None] = ContextVar(
    "drakegrasp_checked_context", default=None
)
"""The (plant, plant context) pair that :func:`checked_context` has checked."""

_TOPOLOGY = WeakMemo()
"""Per finalized plant: answers that depend on its bodies, welds and instances."""


def _per_plant(plant: MultibodyPlant, key: tuple, compute):
    """``compute()``, once per finalized plant and ``key``.

    A finalized plant's bodies, model instances and joints never change (Drake
    refuses to add any after ``Finalize``), so what is computed from them alone
    is kept while the plant lives; nothing that reads a context, and nothing
    Drake lets change after ``Finalize`` (joint limits), is.  Before
    ``Finalize`` nothing is kept.  Values hold indices, never bodies (a body
    keeps its plant alive).
    """
    if not plant.is_finalized():
        return compute()
    return _TOPOLOGY.value(plant, key, compute)


def check_plant(plant, *, finalized: bool = True) -> MultibodyPlant:
    """``plant`` itself, once it is known to be a (finalized) ``MultibodyPlant``.

    Raises
    ------
    ModelError
        If ``plant`` is not a ``MultibodyPlant``, or (``finalized``) is not
        finalized.
    """
    if not isinstance(plant, MultibodyPlant):
        raise ModelError(
            f"plant must be a pydrake MultibodyPlant, got {type(plant).__name__}"
        )
    if finalized and not plant.is_finalized():
        raise ModelError(
            "the plant is not finalized; call plant.Finalize() before analysing it"
        )
    return plant


def check_rigid_transform(
    name: str, X, *, error: type = InvalidOptionError
) -> RigidTransform:
    """A pose Drake may be given: a finite translation and a proper rotation.

    pydrake builds a ``RigidTransform`` from NaN or from a scaled matrix
    without complaint, and Drake then ends the program (``SystemExit``) or
    fills the state with NaN.

    Parameters
    ----------
    name : str
        Name of the pose, for the message.
    X : RigidTransform
    error : type, optional
        The :class:`~drakegrasp.GraspError` subclass to raise.

    Returns
    -------
    RigidTransform
        ``X`` itself.

    Raises
    ------
    GraspError
        Of type ``error``: ``X`` is not a ``RigidTransform``, or its
        translation is not finite, or its rotation ``R`` is not proper
        (``RᵀR = I`` within :data:`ROTATION_TOL`, ``det R = +1``).
    """
    if not isinstance(X, RigidTransform):
        raise error(f"{name} must be a pydrake RigidTransform, got {type(X).__name__}")
    R = X.rotation().matrix()
    if not (
        np.all(np.isfinite(X.translation()))
        and np.all(np.isfinite(R))
        and np.max(np.abs(R.T @ R - np.eye(3))) <= ROTATION_TOL
        and np.linalg.det(R) > 0
    ):
        raise error(
            f"{name} must be a pose with a finite translation and a proper "
            f"rotation, got {reprlib.repr(X.GetAsMatrix4().tolist())}"
        )
    return X


def plant_context_of(plant, context) -> Context:
    """The plant's context, given the plant's own context or the diagram's root.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized.
    context : Context
        The plant's context, or the root context of the diagram that contains
        the plant (resolved with ``plant.GetMyContextFromRoot``).

    Returns
    -------
    Context
        The plant's context (the same object the caller holds, or the
        subcontext inside the root context: writes go to the caller's state).

    Raises
    ------
    ModelError
        If the plant is not a finalized ``MultibodyPlant``.
    InvalidContextError
        If ``context`` is not a Context, or belongs to another system.
    InvalidPoseError
        If the plant's positions in it are not all finite (the message names
        the joints: a free body's is its floating joint).
    """
    checked = _CHECKED.get()
    if checked is not None and checked[0] is plant and checked[1] is context:
        return _finite_positions(plant, context)  # set since: written back later
    check_plant(plant)
    if not isinstance(context, Context):
        raise InvalidContextError(
            "plant_context must be a pydrake Context (the plant's or the root "
            f"context of its diagram), got {type(context).__name__}"
        )
    try:
        plant.ValidateContext(context)
        return _finite_positions(plant, context)
    except RuntimeError:
        pass
    try:
        sub = plant.GetMyContextFromRoot(context)
        plant.ValidateContext(sub)
    except RuntimeError as e:
        msg = " ".join(str(e).split())
        raise InvalidContextError(
            "plant_context belongs neither to this plant nor to the diagram that "
            f"holds it (pass plant.GetMyContextFromRoot(root) or the root); "
            f"Drake says: {msg}"
        ) from None
    return _finite_positions(plant, sub)


def _finite_positions(plant: MultibodyPlant, context: Context) -> Context:
    """``context``, once its positions are all finite.

    Drake aborts the process (no exception) when positions that are not are
    written back, as every planner and pose check does when it is done.
    """
    q = plant.GetPositions(context)
    if np.all(np.isfinite(q)):
        return context
    bad = []
    for j in plant.GetJointIndices():
        joint = plant.get_joint(j)
        start = joint.position_start()
        at = slice(start, start + joint.num_positions())
        if not np.all(np.isfinite(q[at])):
            bad.append(f"{scoped_name(plant, joint)!r} at {q[at].tolist()}")
    raise InvalidPoseError(
        "plant_context holds positions that are not finite: joint "
        + ", joint ".join(bad)
        + " (set the plant's positions to finite values)"
    )


@contextlib.contextmanager
def checked_context(plant: MultibodyPlant, context: Context) -> Iterator[Context]:
    """Check ``plant`` and ``context`` once for every step of one analysis.

    Inside the ``with`` block, :func:`plant_context_of` returns the checked
    plant context at once when given it again with the same plant (the
    contacts, Jacobians, friction and curvatures of one
    :func:`~drakegrasp.analyze_grasp` call each ask for it), its positions
    checked finite again (positions set in the block are written back by
    planners).  Any other plant
    or context is checked as usual.  The pair is held in a ``ContextVar``: other
    threads and tasks do not see it.

    Parameters
    ----------
    plant : MultibodyPlant
    context : Context
        The plant's context or its diagram's root context.

    Yields
    ------
    Context
        The plant's context (:func:`plant_context_of`).
    """
    plant_context = plant_context_of(plant, context)
    token = _CHECKED.set((plant, plant_context))
    try:
        yield plant_context
    finally:
        _CHECKED.reset(token)


def checked_query_object(
    plant: MultibodyPlant,
    query_object,
    plant_context: Context | None = None,
    bodies: Iterable[RigidBody] | None = None,
):
    """``query_object``'s inspector, once it is known to serve ``plant``.

    Parameters
    ----------
    plant : MultibodyPlant
        Registered with a ``SceneGraph``.
    query_object : pydrake.geometry.QueryObject
        A value of that scene graph's query output port.
    plant_context : Context, optional
        The context (the plant's or its diagram's: :func:`plant_context_of`)
        that the query's distances are read with: then each of ``bodies``
        must stand in the query where the context puts it.
    bodies : iterable of RigidBody, optional
        The bodies whose geometry the query is asked about (a hand's and the
        object), checked against ``plant_context``; None (default): every
        body of the plant with geometry.

    Returns
    -------
    pydrake.geometry.SceneGraphInspector

    Raises
    ------
    InvalidOptionError
        Not a ``QueryObject``, one that holds no scene graph's query
        (default-constructed), one of a scene graph the plant is not
        registered with (another diagram's), or one evaluated at another
        state, or with other kinematic parameters, than ``plant_context``
        (another context of the same diagram: its distances and the context's
        Jacobians would describe two poses).
    InvalidPoseError
        Drake cannot compute its geometries' poses (a bad state of the plant).
    ModelError
        The plant has no scene graph.
    """
    from pydrake.geometry import QueryObject, SceneGraph

    if not isinstance(query_object, QueryObject):
        raise InvalidOptionError(
            "query_object must be a pydrake.geometry.QueryObject or None, got "
            f"{type(query_object).__name__}"
        )
    source = plant.get_source_id()
    if source is None:
        raise ModelError("the plant is not registered with a SceneGraph; no geometry")
    try:  # a default-constructed QueryObject answers no query
        query_object.GetPoseInWorld(SceneGraph.world_frame_id())
    except RuntimeError as e:
        text = " ".join(str(e).split())
        if "invalid QueryObject" in text:
            raise InvalidOptionError(
                f"query_object holds no scene graph's query ({text}); pass the "
                "value of scene_graph.get_query_output_port()"
            ) from None
        raise InvalidPoseError(  # its poses: a bad state of the plant it reads
            f"Drake cannot compute the geometry poses of query_object: {text}"
        ) from None
    inspector = query_object.inspector()
    if not inspector.SourceIsRegistered(source):
        raise InvalidOptionError(
            "query_object comes from a scene graph that the plant "
            f"{plant.get_name()!r} is not registered with; pass the query of the "
            "plant's own scene graph"
        )
    if plant_context is not None:
        if bodies is None:
            bodies = [plant.get_body(BodyIndex(b)) for b in range(plant.num_bodies())]
        plant_context = plant_context_of(plant, plant_context)
        _check_same_state(plant, query_object, plant_context, bodies)
    return inspector


def _check_same_state(
    plant: MultibodyPlant,
    query_object,
    plant_context: Context,
    bodies: Iterable[RigidBody],
) -> None:
    """Refuse a query whose bodies stand elsewhere than ``plant_context`` puts them.

    Each body's pose in the world, ``[R | p]`` (p in metres), from the query
    and from the context, entry by entry within
    :data:`~drakegrasp.core.tolerances.QUERY_POSE_TOL` (times the body's
    distance from the origin past 1 m); a body without geometry is let be.
    """
    for body in bodies:
        frame = plant.GetBodyFrameIdIfExists(body.index())
        if frame is None:
            continue
        X_context = plant.EvalBodyPoseInWorld(plant_context, body)
        X_query = query_object.GetPoseInWorld(frame)
        scale = max(1.0, float(np.linalg.norm(X_context.translation())))
        gap = X_context.GetAsMatrix34() - X_query.GetAsMatrix34()
        if not np.max(np.abs(gap)) <= QUERY_POSE_TOL * scale:
            moved = np.linalg.norm(X_context.translation() - X_query.translation())
            turned = X_context.rotation().inverse().multiply(X_query.rotation())
            angle = np.degrees(turned.ToAngleAxis().angle())
            raise InvalidOptionError(
                "query_object was evaluated at another state (or with other "
                f"parameters) than plant_context: body {scoped_name(plant, body)!r} "
                f"stands {moved * 1e3:.3g} mm and {angle:.3g} deg from where the "
                "context puts it; pass the query of the same context (or none: "
                "it is read from plant_context; a GraspMonitor takes its "
                "diagram's parameters with use_parameters_of)"
            )


def query_object_of(plant: MultibodyPlant, plant_context: Context):
    """The scene graph's ``QueryObject`` seen through the plant's context.

    Parameters
    ----------
    plant : MultibodyPlant
        Finalized, registered with a ``SceneGraph``.
    plant_context : Context
        The plant's context (already resolved by :func:`plant_context_of`).

    Returns
    -------
    pydrake.geometry.QueryObject

    Raises
    ------
    ModelError
        The plant is not registered with a ``SceneGraph`` (it has no geometry).
    InvalidContextError
        The plant's geometry query port is not connected in this context:
        ``plant.CreateDefaultContext()`` of a plant inside a diagram is a
        context of the plant alone, with no scene graph behind it.  The
        message names the fix: the plant's part of the diagram's context.
    """
    if not plant.geometry_source_is_registered():
        raise ModelError("the plant is not registered with a SceneGraph; no geometry")
    port = plant.get_geometry_query_input_port()
    if not port.HasValue(plant_context):
        raise InvalidContextError(
            "the plant's geometry_query input port is not connected in this "
            "context: a context made by plant.CreateDefaultContext() holds the "
            "plant alone, without its SceneGraph. Use the diagram's context: "
            "diagram_context = diagram.CreateDefaultContext(), then pass it or "
            "plant.GetMyContextFromRoot(diagram_context)"
        )
    return port.Eval(plant_context)


def scoped_name(plant: MultibodyPlant, body: RigidBody) -> str:
    """``"model::body"`` of a body."""
    return f"{plant.GetModelInstanceName(body.model_instance())}::{body.name()}"


def pair_distance(query, inspector, go, gh) -> float | None:
    """Drake's signed distance ψ (m) between two geometries; None if filtered.

    Parameters
    ----------
    query : QueryObject
        The scene graph's query object.
    inspector : SceneGraphInspector
        ``query.inspector()``.
    go, gh : GeometryId
        An object geometry and a hand geometry.

    Raises
    ------
    ModelError
        If Drake cannot compute the distance of this pair of shapes.
    """
    if inspector.CollisionFiltered(go, gh):
        return None
    try:
        return query.ComputeSignedDistancePairClosestPoints(go, gh).distance
    except RuntimeError as e:
        raise ModelError(
            "Drake cannot compute the signed distance between "
            f"{inspector.GetName(go)!r} and {inspector.GetName(gh)!r}: {e}"
        ) from None


def _instance_names(plant: MultibodyPlant) -> list[str]:
    return [
        plant.GetModelInstanceName(ModelInstanceIndex(i))
        for i in range(plant.num_model_instances())
    ]


def model_instance(
    plant: MultibodyPlant,
    spec,
    *,
    argument: str = "hand",
    error: type[GraspError] = ModelError,
) -> ModelInstanceIndex:
    """A model instance given by index or name, checked before Drake sees it.

    ``argument`` names the caller's parameter in the message of a bad index,
    and ``error`` is what an unknown name or index raises.

    Raises
    ------
    ModelError
        For an unknown name or an index outside ``[0, num_model_instances)``
        (or ``error``); the message lists the plant's instances.
    InvalidOptionError
        For a ``spec`` that is neither an index nor a name.
    """
    if issubclass(type(spec), str):  # not isinstance: __class__ may claim str
        spec = plain_str(spec)
        if not _drake_name(spec) or not plant.HasModelInstanceNamed(spec):
            raise error(
                f"no model instance named {describe(spec)}; instances are "
                f"{_instance_names(plant)}" + _body_hint(plant, spec)
            )
        return plant.GetModelInstanceByName(spec)
    if isinstance(spec, ModelInstanceIndex):
        n = plant.num_model_instances()
        if not spec.is_valid() or not 0 <= int(spec) < n:
            shown = int(spec) if spec.is_valid() else "an invalid index"
            raise error(
                f"{argument}=ModelInstanceIndex({shown}) is not a model instance of "
                f"the plant: valid indices are 0..{n - 1} ({_instance_names(plant)})"
            )
        return spec
    raise InvalidOptionError(
        "a model instance must be a ModelInstanceIndex or a name, got "
        f"{type(spec).__name__}"
    )


def _drake_name(name: str) -> bool:
    """Whether pybind11 can pass ``name`` to Drake (UTF-8 can encode it).

    A lone surrogate (U+D800 alone) cannot be: Drake's name lookups raised a
    bare TypeError for it.  No body, joint or model instance has such a name.
    """
    try:
        name.encode("utf-8")
    except UnicodeError:
        return False
    return True


def _body_hint(plant: MultibodyPlant, name: str) -> str:
    """A hint when a model-instance name is a body's scoped name instead."""
    if not _drake_name(name):
        return ""
    model, _, body = name.rpartition("::")
    if not (model and plant.HasModelInstanceNamed(model)):
        return ""
    if not plant.HasBodyNamed(body, plant.GetModelInstanceByName(model)):
        return ""
    return (
        f" ({describe(name)} is a body: a hand of bodies is a list of them, "
        f"[{describe(name)}, ...], and its model instance is {model!r})"
    )


def resolve_body(plant: MultibodyPlant, name: str) -> RigidBody:
    """The body called ``"model::body"`` (or an unscoped name used once).

    Raises
    ------
    ModelError
        If no (or more than one) body has that name; the message lists the
        plant's bodies.
    InvalidOptionError
        If ``name`` is not a string.
    """
    name = plain_str(name)
    if type(name) is not str:
        raise InvalidOptionError(
            "a body name must be a string such as 'model::body', got a "
            f"{type_name(name)}"
        )
    try:
        if not _drake_name(name):
            pass  # no body has it: refused below with the plant's bodies
        elif "::" in name:
            model, body = name.rsplit("::", 1)
            if plant.HasModelInstanceNamed(model):
                instance = plant.GetModelInstanceByName(model)
                if plant.HasBodyNamed(body, instance):
                    return plant.GetBodyByName(body, instance)
        elif plant.HasBodyNamed(name):
            return plant.GetBodyByName(name)
    except RuntimeError as e:  # the name is used by several model instances
        raise ModelError(f"body name {describe(name)} is ambiguous: {e}") from None
    bodies = [
        scoped_name(plant, plant.get_body(BodyIndex(i)))
        for i in range(1, plant.num_bodies())
    ]
    raise ModelError(
        f"no body named {describe(name)} in the plant; bodies are {bodies}"
    )


def resolve_object_body(
    plant: MultibodyPlant, object_body, *, what: str = "object_body"
) -> RigidBody:
    """A body given as a ``RigidBody`` (of this plant), a ``BodyIndex`` or a name.

    ``what`` names the argument in the messages (``"hand[1]"`` for an item of
    a hand given as bodies).

    Raises
    ------
    ModelError
        For an unknown name, a ``BodyIndex`` out of range, or a body of
        another plant.
    InvalidOptionError
        For any other type.
    """
    if isinstance(object_body, RigidBody):
        return _own_body(plant, object_body, "body" if what == "object_body" else what)
    if isinstance(object_body, BodyIndex):
        n = plant.num_bodies()
        if not object_body.is_valid() or not 0 <= int(object_body) < n:
            raise ModelError(
                f"BodyIndex({int(object_body) if object_body.is_valid() else '?'}) "
                f"is not a body of the plant: valid indices are 0..{n - 1}"
            )
        return plant.get_body(object_body)
    if isinstance(object_body, str):
        return resolve_body(plant, object_body)
    raise InvalidOptionError(
        f"{what} must be a RigidBody, a BodyIndex or a 'model::body' name, "
        f"got {type(object_body).__name__}"
    )


def _own_body(plant: MultibodyPlant, body: RigidBody, what: str) -> RigidBody:
    """``body``, once it is a body of ``plant`` (``what`` names it in the message)."""
    if body.GetParentPlant() is not plant:
        raise ModelError(f"{what} {body.name()!r} does not belong to this plant")
    return body


def check_bodies(
    plant: MultibodyPlant, bodies, *, argument: str = "bodies"
) -> list[RigidBody]:
    """``bodies`` as a list, once each is a ``RigidBody`` of ``plant``.

    Parameters
    ----------
    plant : MultibodyPlant
    bodies : iterable of RigidBody
    argument : str, optional
        The caller's parameter, for the message.

    Raises
    ------
    InvalidOptionError
        ``bodies`` is not an iterable (a string is none), or holds something
        that is not a ``RigidBody`` (the message names its place).
    ModelError
        A body of another plant (the message names it).
    """
    if isinstance(bodies, str | bytes | dict) or not isinstance(bodies, Iterable):
        raise InvalidOptionError(
            f"{argument} must be an iterable of the plant's RigidBody objects, "
            f"got {describe(bodies)}"
        )
    out = []
    bodies = items_of(argument, bodies, "an iterable of the plant's RigidBody objects")
    for k, body in enumerate(bodies):
        if not isinstance(body, RigidBody):
            raise InvalidOptionError(
                f"{argument}[{k}] must be a RigidBody of the plant, got "
                f"{type(body).__name__} {describe(body)}"
            )
        out.append(_own_body(plant, body, f"{argument}[{k}], body"))
    return out


def check_velocity_indices(
    plant: MultibodyPlant, indices, *, argument: str = "velocity_indices"
) -> np.ndarray:
    """Indices into the plant's velocities ``v``, each once, checked.

    numpy would wrap a negative index, truncate ``0.5`` to 0 and raise a bare
    ``IndexError`` past the end; a velocity named twice would be two columns
    (two motors) for one velocity.

    Parameters
    ----------
    plant : MultibodyPlant
    indices : sequence of int
        One-dimensional; empty is a hand without velocities.
    argument : str, optional
        The caller's parameter, for the message.

    Returns
    -------
    (n,) int
        The indices, in the order given.

    Raises
    ------
    InvalidOptionError
        For what is not a one-dimensional sequence, an entry that is not an
        integer (bools are not) or lies outside ``[0, nv)``, and an index
        given more than once; the message names the entries and their places.
    """
    nv = plant.num_velocities()
    must = (
        f"a one-dimensional sequence of plant velocity indices (integers in "
        f"0..{nv - 1})"
    )
    if isinstance(indices, np.ndarray) and indices.ndim == 1 and indices.size > nv:
        # read as objects, 10**9 broadcast rows would be 8 GB: no sequence of
        # distinct indices is longer than the plant's velocities
        raise InvalidOptionError(
            f"{argument} must be {must}, each once; got {indices.size} of them "
            f"for a plant of {nv} velocities"
        )
    try:
        if isinstance(indices, np.ndarray) and indices.ndim != 1:
            items = None  # refused by its shape, never read
        else:
            read = items_of(argument, indices, must)
            items = np.empty(len(read), dtype=object)
            items[:] = read
            if any(_nested(x) for x in read):
                items = None
    except GraspError:  # items_of's own words: too many, or what reading raised
        raise
    except (TypeError, ValueError):
        items = None
    if isinstance(indices, str | bytes | dict) or items is None or items.ndim != 1:
        raise InvalidOptionError(
            f"{argument} must be a one-dimensional sequence of plant velocity "
            f"indices (integers in 0..{nv - 1}), got {describe(indices)}"
        )
    values = [integer_or_none(x) for x in items]
    bad = [
        f"{describe(x)} at [{k}]"
        for k, (x, i) in enumerate(zip(items, values, strict=True))
        if i is None or not 0 <= i < nv
    ]
    if bad:
        raise InvalidOptionError(
            f"{argument} must be integers in 0..{nv - 1} (the plant has {nv} "
            f"velocities), got {', '.join(bad)}"
        )
    first: dict[int, int] = {}
    for k, i in enumerate(values):
        if i in first:
            raise InvalidOptionError(
                f"{argument} names velocity {i} more than once (at [{first[i]}] "
                f"and [{k}]); each velocity is one column"
            )
        first[i] = k
    return np.array(values, dtype=int)


def resolve_grasped_body(plant: MultibodyPlant, object_body) -> RigidBody:
    """:func:`resolve_object_body`, refusing the world body: it is no object.

    For what only means something for an object a hand can touch and hold
    (the friction of its pairs with the hand, grasp planning).

    Raises
    ------
    InvalidOptionError
        For the world body (``"world"``, ``BodyIndex(0)``,
        ``plant.world_body()``), and for a value of another type.
    ModelError
        As :func:`resolve_object_body`.
    """
    body = resolve_object_body(plant, object_body)
    if int(body.index()) == 0:
        bodies = [
            scoped_name(plant, plant.get_body(BodyIndex(i)))
            for i in range(1, min(plant.num_bodies(), 9))
        ]
        more = ", ..." if plant.num_bodies() > 9 else ""
        raise InvalidOptionError(
            "object_body is the world body ('world'), which is not an object; "
            f"name the body to grasp (bodies are {str(bodies)[:-1]}{more}])"
        )
    return body


def _welded_to_world(plant: MultibodyPlant) -> frozenset[int]:
    return _per_plant(
        plant,
        ("welded to world",),
        lambda: frozenset(
            int(b.index()) for b in plant.GetBodiesWeldedTo(plant.world_body())
        ),
    )


@checked_call
def hand_bodies(
    plant: MultibodyPlant, object_body: RigidBody, hand: HandSpec = None
) -> list[RigidBody]:
    """The bodies of the hand that can move.

    Parameters
    ----------
    plant : MultibodyPlant
    object_body : RigidBody
    hand : ModelInstanceIndex, str, iterable of RigidBody (or scoped names), or None
        A model instance, given by index or name (all its bodies that are not
        welded to the world, with those of the models nested in it, named
        ``name::...``), an explicit list of bodies, or None: every body
        that is not the object, not welded to the world and not in the object's
        model instance.

    Returns
    -------
    list of RigidBody
        In body-index order.

    Raises
    ------
    ModelError
        For an unknown instance or body, or a hand left with no body that can
        move (for instance a list of bodies all welded to the world).
    """
    check_plant(plant, finalized=False)  # a plant being built is read too
    object_body = resolve_object_body(plant, object_body)
    hand = plain_str(hand)  # a key of the memo: its own __hash__ may raise or lie
    if type(hand) is str or isinstance(hand, ModelInstanceIndex) or hand is None:
        obj = (int(object_body.index()), int(object_body.model_instance()))
        spec = ("index", int(hand)) if isinstance(hand, ModelInstanceIndex) else hand
        key = ("hand bodies", obj, spec)

        # body indices, not bodies: a body keeps its plant alive, and the memo
        # must not (it holds the plant weakly)
        def compute():
            return tuple(int(b.index()) for b in _hand_bodies(plant, object_body, hand))

        indices = _per_plant(plant, key, compute)
        return [plant.get_body(BodyIndex(i)) for i in indices]
    return _hand_bodies(plant, object_body, hand)


def _listed(hand) -> Iterable:
    """A hand given as bodies, or a clear error for what is no spec at all (99)."""
    if isinstance(hand, bytes | dict) or not isinstance(hand, Iterable):
        raise InvalidOptionError(
            "hand must be a model instance (ModelInstanceIndex or name), an "
            f"iterable of bodies or scoped body names, or None; got {describe(hand)}"
        )
    return items_of(
        "hand",
        hand,
        "a model instance (ModelInstanceIndex or name), an iterable of bodies "
        "or scoped body names, or None",
    )


def _nested(x) -> bool:
    """Whether ``x`` is a sequence (an item of a nest), asked without reading it."""
    return isinstance(x, list | tuple) or (isinstance(x, np.ndarray) and x.ndim > 0)


def _listed_bodies(plant: MultibodyPlant, hand) -> list[RigidBody]:
    """A hand given as bodies, each resolved, read once (a generator is spent).

    A wrong item is named by its place, ``hand[i]``; the messages that show
    the hand afterwards show this list, not the spent iterable.
    """
    bodies = []
    for i, b in enumerate(_listed(hand)):
        try:
            bodies.append(resolve_object_body(plant, b, what=f"hand[{i}]"))
        except ModelError as e:  # an unknown name or index: which item it was
            if str(e).startswith(f"hand[{i}]"):
                raise
            raise ModelError(f"hand[{i}]: {e}") from None
    return bodies


def _hand_repr(plant: MultibodyPlant, hand) -> str:
    """``hand`` as a message shows it: an instance by name, bodies by scoped name."""
    if isinstance(hand, ModelInstanceIndex):
        return repr(plant.GetModelInstanceName(hand))
    if isinstance(hand, str) or hand is None:
        return describe(hand)
    return repr(
        [scoped_name(plant, b) if isinstance(b, RigidBody) else b for b in hand]
    )


def _check_apart(
    plant: MultibodyPlant, object_body: RigidBody, hand, bodies: list[RigidBody]
) -> None:
    """Refuse an object that is one of the hand's bodies.

    ``bodies`` are every body ``hand`` names (a model instance's, or the
    listed ones).  An object listed in the hand, or joined by joints to another
    body of the hand's model instance (a finger, a palm), is part of it; an
    object that only shares the hand's model instance (one model file holding
    a hand and a free object) is not.
    """
    obj = int(object_body.index())
    if obj == 0 or all(int(b.index()) != obj for b in bodies):
        return
    name = scoped_name(plant, object_body)
    if not isinstance(hand, str | ModelInstanceIndex):
        raise InvalidOptionError(
            f"object_body {name} is also listed as a body of the hand "
            f"(hand={_hand_repr(plant, hand)}); the object and the hand must be "
            "apart: leave it out of the hand"
        )
    others = [b for b in bodies if int(b.index()) != obj]
    partner = next((b for b in others if joined(plant, object_body, b)), None)
    if partner is not None:
        raise InvalidOptionError(
            f"object_body {name} is part of the hand {_hand_repr(plant, hand)}: "
            f"it is joined to the hand's {scoped_name(plant, partner)}; name the "
            "body to grasp, apart from the hand"
        )


def _hand_bodies(plant, object_body, hand) -> list[RigidBody]:
    welded = _welded_to_world(plant)
    if isinstance(hand, str | ModelInstanceIndex):
        bodies = _instance_bodies(plant, hand)
        _check_apart(plant, object_body, hand, bodies)
        bodies = [b for b in bodies if int(b.index()) not in welded]
    elif hand is None:
        bodies = [
            plant.get_body(BodyIndex(i))
            for i in range(plant.num_bodies())
            if i not in welded
        ]
        bodies = [
            b for b in bodies if b.model_instance() != object_body.model_instance()
        ]
    else:
        listed = hand = _listed_bodies(plant, hand)
        _check_apart(plant, object_body, hand, listed)
        bodies = [b for b in listed if int(b.index()) not in welded]
        if listed and not bodies:
            raise ModelError(
                "every body listed as the hand is welded to the world, so none can "
                f"move: {[scoped_name(plant, b) for b in listed]}; list the "
                "fingers' bodies or name the hand's model instance"
            )
    bodies = [b for b in bodies if b.index() != object_body.index()]
    if not bodies:
        raise _no_bodies(plant, object_body, hand, " that can move")
    return sorted(bodies, key=lambda b: int(b.index()))


def _instance_bodies(plant, hand) -> list[RigidBody]:
    """Every body of the model instance ``hand`` names and of those nested in it."""
    instance = model_instance(plant, hand)
    return [
        plant.get_body(i)
        for nested in _with_nested(plant, instance)
        for i in plant.GetBodyIndices(nested)
    ]


def _with_nested(plant, instance) -> list:
    """``instance`` and the model instances nested in it (``name::...``).

    An SDFormat model's nested ``<model>`` s (and ``<include>`` s) become model
    instances of their own, named under it: a hand whose fingers are nested
    models is all of them.  Only those joined to it count: a scene's
    ``model_namespace`` names other models ``name::...`` too (a free object,
    a fixture), which are no part of it.
    """
    name = plant.GetModelInstanceName(instance) + "::"
    nested = [
        ModelInstanceIndex(k)
        for k in range(plant.num_model_instances())
        if plant.GetModelInstanceName(ModelInstanceIndex(k)).startswith(name)
    ]
    if not nested:
        return [instance]
    parent = {}  # body -> the body its joint hangs from
    for k in range(plant.num_joints()):
        joint = plant.get_joint(JointIndex(k))
        parent[int(joint.child_body().index())] = int(joint.parent_body().index())
    own = {int(b) for b in plant.GetBodyIndices(instance)}

    def joined(other) -> bool:
        for b in plant.GetBodyIndices(other):
            seen, i = set(), int(b)
            while i in parent and i not in seen:  # up the tree to the world
                seen.add(i)
                i = parent[i]
                if i in own:
                    return True
        return False

    return [instance, *(n for n in nested if joined(n))]


def _no_bodies(plant, object_body, hand, which: str) -> ModelError:
    """The error of a hand left with no body (``which``: " that can move", "")."""
    shown = _hand_repr(plant, hand)
    if (
        isinstance(hand, str | ModelInstanceIndex)
        and model_instance(plant, hand) == object_body.model_instance()
    ):
        return ModelError(
            f"hand={shown} is the model instance of the object "
            f"{scoped_name(plant, object_body)}, which holds no other body"
            f"{which}; name the hand's own model instance or list its bodies"
        )
    return ModelError(
        f"the hand has no bodies{which} (hand={shown}); name its model "
        "instance or list its bodies"
    )


def hand_contact_bodies(
    plant: MultibodyPlant, object_body: RigidBody, hand: HandSpec = None
) -> list[RigidBody]:
    """Every body of the hand that can touch the object, welded ones included.

    A palm welded to the world cannot move, but it touches: its contacts
    belong in ``G``, and its rows of the hand Jacobian are zero.

    Parameters
    ----------
    plant : MultibodyPlant
    object_body : RigidBody
    hand : ModelInstanceIndex, str, iterable of RigidBody (or scoped names), or None
        A model instance (all its bodies), an explicit list of bodies (all of
        them, welded or not), or None: the movable bodies of
        :func:`hand_bodies` and every body of their model instances (so the
        welded palm of a hand, but not a table welded to the world in a model
        instance of its own).

    Returns
    -------
    list of RigidBody
        In body-index order; never the object nor the world body.

    Raises
    ------
    ModelError
        For an unknown instance or body, or a hand with no body at all.
    """
    obj = int(object_body.index())
    hand = plain_str(hand)  # its own methods may raise or lie
    if hand is None:
        movable = hand_bodies(plant, object_body, None)
        return hand_model_instances(plant, movable, object_body)
    if isinstance(hand, str | ModelInstanceIndex):
        bodies = _instance_bodies(plant, hand)
    else:
        bodies = hand = _listed_bodies(plant, hand)
    _check_apart(plant, object_body, hand, bodies)
    bodies = [b for b in bodies if int(b.index()) not in (0, obj)]
    if not bodies:
        raise _no_bodies(plant, object_body, hand, "")
    unique = {int(b.index()): b for b in bodies}
    return [unique[i] for i in sorted(unique)]


def hand_model_instances(
    plant: MultibodyPlant, bodies: Iterable[RigidBody], object_body: RigidBody
) -> list[RigidBody]:
    """Every body of the model instances the hand's bodies belong to.

    This is what a pose check looks at: the moving fingers *and* the palm,
    even when the palm is welded to the world.  The object and the world
    body are left out.

    Returns
    -------
    list of RigidBody
        In body-index order.
    """
    instances = frozenset(int(b.model_instance()) for b in bodies)
    obj = int(object_body.index())

    def compute():  # indices only: a body would keep the plant alive
        return tuple(
            i
            for i in range(1, plant.num_bodies())
            if int(plant.get_body(BodyIndex(i)).model_instance()) in instances
            and i != obj
        )

    found = _per_plant(plant, ("hand instances", instances, obj), compute)
    return [plant.get_body(BodyIndex(i)) for i in found]
