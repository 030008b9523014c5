"""One options object for reading a grasp from a plant and judging it.

:class:`AnalysisOptions` holds every choice of :func:`~drakegrasp.analyze_grasp`
and :func:`~drakegrasp.grasp_from_plant` besides the plant, its context, the
object and the hand: friction, contact model, tolerances, the plane of a
planar analysis, how flat patches are reported and whether the pose is
checked.  It is frozen and validated once, when it is made; the analysis, the
grasp monitor, scene files, the Dask driver and the command line all take or
give one, and the command line reads its defaults and help from
:data:`OPTION_HELP`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from drakegrasp.core.calls import checked_fields
from drakegrasp.core.contact import ContactModel, missing_torsional_friction
from drakegrasp.core.deprecation import renamed_keyword
from drakegrasp.core.serialize import jsonable
from drakegrasp.core.tolerances import (
    COUPLING_TOL,
    DEFAULT_DISTANCE_TOLERANCE,
    DEFAULT_NUM_GENERATORS,
    DEFAULT_TOL,
    MAX_COUPLING_TOL,
)
from drakegrasp.core.validation import (
    check_coefficient,
    check_distance_tolerance,
    check_flag,
    check_length,
    check_num_generators,
    check_tol,
    describe,
    plain_str,
    real_array,
    real_scalar,
)
from drakegrasp.errors import InvalidOptionError

__all__ = [
    "OPTION_HELP",
    "PATCH_MODES",
    "PLANES",
    "AnalysisOptions",
    "check_object_mass",
    "check_plane",
    "checked_options",
    "resolve_options",
]

PLANES = {"xy": (0, 1), "yz": (1, 2), "zx": (2, 0)}
"""Planes of the object frame for a planar analysis: name -> the two axes.

Each pair is ordered so that the plane's normal (the moment axis) is the third
axis of a right-handed frame: ``"yz"`` gives wrenches ``[f_y, f_z, m_x]``.
"""


def check_plane(plane: Any) -> str | None:
    """``plane`` as a plain ``str``, once it is a key of :data:`PLANES`, or None.

    Raises
    ------
    InvalidOptionError
        For any other value (the message lists the planes).
    """
    if plane is None:
        return None
    plane = plain_str(plane)
    if type(plane) is not str or plane not in PLANES:
        raise InvalidOptionError(
            f"plane must be one of {sorted(PLANES)} (object-frame axes) or "
            f"None, got {describe(plane)}"
        )
    return str(plane)  # numpy.str_ and other subclasses


PATCH_MODES = ("vertices", "witness")
"""How a flat contact patch is reported: its corners, or Drake's witness point."""

OPTION_HELP = {
    "mu": "Coulomb friction coefficient of every contact (dimensionless, >= 0), "
    "or 'plant': each pair's friction from its geometries' proximity properties",
    "contact_model": "contact model: frictionless, hard_finger or soft_finger",
    "torsional_friction": "soft-finger torsional friction nu (>= 0; soft_finger "
    "needs it)",
    "distance_tolerance": "signed distance below which a pair touches (metres, "
    "> 0 and at most 0.01, i.e. 10 mm)",
    "plane": "planar analysis in this plane of the object frame (xy, yz or zx)",
    "characteristic_length": "length b that makes moments comparable with "
    "forces and sets a soft finger's torsion limit b nu f_n (metres)",
    "num_generators": "generators of each polyhedral Coulomb cone",
    "tol": "threshold on d*: closure needs d* > tol",
    "allow_penetration": "analyse a penetrating pose anyway (contacts still "
    "found within the tolerance)",
    "patches": "how a flat contact patch is reported: vertices or witness",
    "check_pose": "refuse an impossible pose (penetration, joints beyond limits)",
    "coupling_tolerance": "largest break of a joint coupling (m or rad) that "
    "the pose check accepts",
    "load": "an external wrench on the object (frame O about its origin), or "
    "'gravity' (its weight): adds the load section",
    "object_mass": "the object's mass (kg, > 0) that load 'gravity' weighs, "
    "instead of the model's (needs load 'gravity')",
    "torque_limits": "motor limits of the load section: 'plant' (the actuators' "
    "effort limits), one per hand velocity (a coupled hand: per actuated joint "
    "or per independent coordinate), or one for all",
}
"""One line per option: the docstring below and the command line's help."""


@renamed_keyword("model", "contact_model")
@checked_fields("analysis option")
@dataclass(frozen=True)
class AnalysisOptions:
    """How a grasp is read from a plant and judged (validated when made).

    Attributes
    ----------
    mu : float, "plant" or None
        Coulomb friction coefficient of every contact (dimensionless), or
        ``"plant"``: each pair's coefficient from its geometries' proximity
        properties; None until given (an analysis needs it).
    contact_model : ContactModel
        ``frictionless``, ``hard_finger`` (default) or ``soft_finger``.
    torsional_friction : float or None
        Soft-finger torsional friction ``ν`` (the moment about the normal is
        bounded by ``b ν f_n``); a soft-finger analysis needs it, 0 otherwise.
    distance_tolerance : float
        A pair closer than this (metres) touches (default
        :data:`~drakegrasp.core.tolerances.DEFAULT_DISTANCE_TOLERANCE`);
        ``> 0`` and at most
        :data:`~drakegrasp.core.tolerances.MAX_DISTANCE_TOLERANCE` (0.01 m).
    plane : {"xy", "yz", "zx"} or None
        Planar analysis in this plane of the object frame O.
    characteristic_length : float or None
        Length ``b`` (metres) scaling moments and setting a soft finger's
        torsion limit ``b ν f_n``; None: the farthest contact from the reference
        point (the object's origin), so it moves with that point.
    num_generators : int
        Generators of each polyhedral Coulomb cone (default 8).
    tol : float
        Threshold on ``d*`` (dimensionless).
    allow_penetration : bool
        Analyse a penetrating pose anyway.
    patches : {"vertices", "witness"}
        How a flat contact patch is reported.
    check_pose : bool
        Refuse an impossible pose (penetration, joints beyond their limits).
    coupling_tolerance : float
        The largest ``|q_0 - (ρ q_1 + Δq)|`` (m or rad) of a coupling that the
        pose check accepts; finite, ``> 0`` and at most
        :data:`~drakegrasp.core.tolerances.MAX_COUPLING_TOL`.  Default
        :data:`~drakegrasp.core.tolerances.COUPLING_TOL`; a
        :class:`~drakegrasp.GraspMonitor`'s
        :data:`~drakegrasp.core.tolerances.MONITOR_COUPLING_TOL`, since a
        simulation's coupler constraints give under load.
    load : None, "gravity" or tuple of float
        An external wrench on the object, (6,) or planar (3,), in frame O about
        its origin, or the object's weight: the report then has a load section.
    object_mass : float or None
        The mass (kg, finite and > 0) that ``load="gravity"`` weighs, at the
        model's centre of mass; None: the model's own.  It needs
        ``load="gravity"`` (a wrench has no mass to replace).
    torque_limits : None, "plant" or tuple of float
        Motor limits of the load section (N·m or N per hand velocity; ``inf``
        for none); one number (``100`` or ``[100]``, kept as ``(100.0,)``) is
        every actuator's, except on a hand with one independent coordinate
        (a one-motor jaw), where it is that coordinate's (a ``<mimic>``
        follower without a motor of its own must not count one).
        ``"plant"`` reads the actuators' effort limits, a free hand
        base's velocities unbounded
        (:func:`~drakegrasp.plant.load.plant_torque_limits`).
    """

    mu: float | None = None
    contact_model: ContactModel = ContactModel.HARD_FINGER
    torsional_friction: float | None = None
    distance_tolerance: float = DEFAULT_DISTANCE_TOLERANCE
    plane: str | None = None
    characteristic_length: float | None = None
    num_generators: int = DEFAULT_NUM_GENERATORS
    tol: float = DEFAULT_TOL
    allow_penetration: bool = False
    patches: str = "vertices"
    check_pose: bool = True
    coupling_tolerance: float = COUPLING_TOL
    load: str | tuple[float, ...] | None = None
    object_mass: float | None = None
    torque_limits: str | tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        def put(name: str, value: Any) -> None:
            object.__setattr__(self, name, value)

        if isinstance(self.mu, str):  # read as the plain str it holds, if any
            if plain_str(self.mu) != "plant":
                raise InvalidOptionError(
                    f"mu must be a number or 'plant', got {describe(self.mu)}"
                )
            put("mu", "plant")  # a plain str, whatever str subclass came in
        elif self.mu is not None:
            put("mu", check_coefficient("mu", self.mu))
        model = ContactModel.parse(self.contact_model)
        put("contact_model", model)
        put("plane", check_plane(self.plane))
        if self.plane is not None and model is ContactModel.SOFT_FINGER:
            raise InvalidOptionError(
                "a planar analysis has no soft fingers (no moment about an in-plane "
                "normal); use 'hard_finger' or 'frictionless'"
            )
        if self.torsional_friction is not None:
            put(
                "torsional_friction",
                check_coefficient("torsional_friction", self.torsional_friction),
            )
        put("distance_tolerance", check_distance_tolerance(self.distance_tolerance))
        if self.characteristic_length is not None:
            put(
                "characteristic_length",
                check_length(
                    "characteristic_length",
                    self.characteristic_length,
                    error=InvalidOptionError,
                ),
            )
        put("num_generators", check_num_generators(self.num_generators))
        put("tol", check_tol(self.tol))
        put(
            "allow_penetration", check_flag("allow_penetration", self.allow_penetration)
        )
        put("check_pose", check_flag("check_pose", self.check_pose))
        put("coupling_tolerance", _coupling_tolerance(self.coupling_tolerance))
        put("patches", plain_str(self.patches))
        if type(self.patches) is not str or self.patches not in PATCH_MODES:
            raise InvalidOptionError(
                f"patches must be one of {list(PATCH_MODES)}, got "
                f"{describe(self.patches)}"
            )
        put("load", _named_or_values("load", self.load, "gravity"))
        dim = 6 if self.plane is None else 3
        if isinstance(self.load, tuple) and len(self.load) != dim:
            where = "a spatial" if self.plane is None else "a planar"
            raise InvalidOptionError(
                f"load must be 'gravity' or {where} wrench [f; m] of {dim} numbers "
                f"(frame O about its origin), got {len(self.load)}: {list(self.load)}"
            )
        put(
            "torque_limits",
            _named_or_values("torque_limits", self.torque_limits, "plant", limits=True),
        )
        if self.object_mass is not None:
            put("object_mass", check_object_mass(self.object_mass))
            if self.load != "gravity":
                raise InvalidOptionError(
                    f"object_mass ({self.object_mass:g} kg) is the mass that load "
                    f"'gravity' weighs: it needs load 'gravity', got {self.load!r}"
                )

    def replace(self, **changes: Any) -> AnalysisOptions:
        """A copy with ``changes`` (validated again); unknown names are refused.

        The constructor refuses them (``checked_fields``), naming the closest
        option; ``model=`` (deprecated) reaches it too, which warns and
        renames it.
        """
        return dataclasses.replace(self, **changes)

    def require_friction(self) -> AnalysisOptions:
        """``self`` when ``mu`` (and a soft finger's ``ν``) are given; else an error."""
        if self.mu is None:
            raise InvalidOptionError(
                "the analysis needs mu, the friction coefficient of every contact "
                "(AnalysisOptions(mu=...), mu=..., or --mu on the command line)"
            )
        if (
            self.contact_model is ContactModel.SOFT_FINGER
            and self.torsional_friction is None
        ):
            raise missing_torsional_friction(InvalidOptionError)
        return self

    def to_dict(self) -> dict:
        """JSON-ready dictionary (the contact model by its name)."""
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        out["contact_model"] = self.contact_model.value
        return jsonable(out)


def check_object_mass(value: Any) -> float:
    """``object_mass`` (kg) as a float, once it is finite and > 0."""
    m = real_scalar("object_mass", value, error=InvalidOptionError)
    if not (0.0 < m < np.inf):
        raise InvalidOptionError(
            f"object_mass must be a finite mass > 0 (kg), got {describe(value)}"
        )
    return m


def _named_or_values(name: str, value: Any, word: str, *, limits: bool = False):
    """None, ``word``, or a finite 1-D sequence of numbers as a tuple.

    With ``limits``, ``+inf`` is allowed too (a joint with no limit), and one
    real number is one limit for every actuator: ``x`` gives ``(x,)``, as
    ``[x]`` does.
    """
    value = plain_str(value)  # a str subclass's own __eq__ may raise or lie
    if value is None or (type(value) is str and value == word):
        return None if value is None else word  # a plain str
    if isinstance(value, str):
        raise InvalidOptionError(
            f"{name} must be {word!r}, numbers or None, got {describe(value)}"
        )
    try:  # real numbers only: not "1.0" or True read as numbers
        values = real_array(name, value, error=InvalidOptionError)
    except InvalidOptionError:
        raise InvalidOptionError(
            f"{name} must be {word!r}, numbers or None, got {describe(value)}"
        ) from None
    if limits:  # a motor's limit is a magnitude: >= 0, inf for none
        if values.ndim == 0:  # one number: every actuator's limit, as [x] is
            values = values.reshape(1)
        ok = (values >= 0.0) & ~np.isnan(values)
    else:
        ok = np.isfinite(values)
    if values.ndim != 1 or values.size == 0 or not np.all(ok):
        if limits:
            raise InvalidOptionError(
                f"{name} must be {word!r}, one number >= 0 for every actuator or "
                "a 1-D sequence of one or more numbers >= 0 (inf: no limit), got "
                f"{describe(value)}"
            )
        raise InvalidOptionError(
            f"{name} must be a 1-D sequence of one or more finite numbers, got "
            f"{describe(value)}"
        )
    return tuple(float(x) for x in values)


def checked_options(options: Any) -> AnalysisOptions:
    """``options`` if it is an :class:`AnalysisOptions`; refused otherwise."""
    if not isinstance(options, AnalysisOptions):
        raise InvalidOptionError(
            f"options must be an AnalysisOptions, got {type(options).__name__}"
        )
    return options


def _coupling_tolerance(value: Any) -> float:
    """``coupling_tolerance`` as a float in ``(0, MAX_COUPLING_TOL]``."""
    message = (
        f"coupling_tolerance must be finite and > 0, at most {MAX_COUPLING_TOL:g} "
        f"(m or rad), got {describe(value)}"
    )
    try:
        tol = real_scalar("coupling_tolerance", value)
    except InvalidOptionError:
        raise InvalidOptionError(message) from None
    if not 0.0 < tol <= MAX_COUPLING_TOL:
        raise InvalidOptionError(message)
    return tol


def resolve_options(
    options: AnalysisOptions | None, **keywords: Any
) -> AnalysisOptions:
    """The options of a call: ``options``, or one made from its keywords.

    A call may give an :class:`AnalysisOptions` or keywords, not both: a
    keyword whose value differs from the field's default next to ``options``
    is refused (it would be silently ignored otherwise).
    """
    if options is None:
        return AnalysisOptions(**keywords)
    checked_options(options)
    defaults = AnalysisOptions()
    given = sorted(
        name
        for name, value in keywords.items()
        if not _same(value, getattr(defaults, name))
    )
    if given:
        raise InvalidOptionError(
            f"give options= or the keywords {given}, not both "
            "(options.replace(...) changes a field)"
        )
    return options


def _same(value: Any, default: Any) -> bool:
    if isinstance(default, ContactModel):
        try:
            return ContactModel.parse(value) is default
        except Exception:  # noqa: BLE001 - an invalid value is "given"
            return False
    return value is default or (type(value) is type(default) and value == default)
