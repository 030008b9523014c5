"""Contacts and contact frames (numpy only).

A :class:`Contact` is a point on the object's surface with the unit normal that
points **into the object** (the direction in which the finger pushes), a friction
coefficient and a contact model.  Two-dimensional position and normal make a planar
contact.  See ``docs/conventions.md`` for every sign and ordering used here.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.deprecation import renamed_keyword, warn_deprecated
from drakegrasp.core.tolerances import UNIT_NORMAL_TOL
from drakegrasp.core.validation import (
    check_coefficient,
    check_positions,
    describe,
    plain_str,
    real_array,
    unit_vectors,
)
from drakegrasp.errors import InvalidContactError, InvalidOptionError

__all__ = [
    "Contact",
    "ContactModel",
    "contact_frame",
    "contact_frames",
    "missing_torsional_friction",
]


class ContactModel(str, enum.Enum):
    """How a contact transmits force and moment to the object.

    ``FRICTIONLESS``: normal force only, ``f = [f_n]``.
    ``HARD_FINGER``: point contact with Coulomb friction, ``f = [f_n, f_t1, f_t2]``
    (planar ``[f_n, f_t]``).
    ``SOFT_FINGER``: hard finger plus a moment about the normal,
    ``f = [f_n, f_t1, f_t2, m_n]`` (spatial only).
    """

    FRICTIONLESS = "frictionless"
    HARD_FINGER = "hard_finger"
    SOFT_FINGER = "soft_finger"

    @classmethod
    def parse(cls, value: ContactModel | str) -> ContactModel:
        """Return the model named by ``value`` (an enum member or its string)."""
        if isinstance(value, cls):
            return value
        try:  # a str subclass is read as a plain str: its own __str__ may raise
            text = str(plain_str(value))
            return cls(str.strip(text).lower().replace("-", "_"))
        except Exception:  # noqa: BLE001 - no model's name, or a hostile __str__
            valid = ", ".join(repr(m.value) for m in cls)
            raise InvalidContactError(
                f"unknown contact model {describe(value)} (contact_model=); valid "
                f"models are {valid}"
            ) from None

    def __str__(self) -> str:
        return self.value


def missing_torsional_friction(error: type = InvalidContactError) -> Exception:
    """The error for a soft finger given no torsional friction ``ν``.

    One wording wherever a soft finger is asked for (a contact, the options
    objects, the batch engine, the planner); ``error`` is the caller's kind.
    """
    return error(
        "contact_model='soft_finger' needs torsional_friction (nu >= 0: the "
        "moment about each contact normal is bounded by b * nu * f_n); pass "
        "it (0 makes a soft finger act as a hard one), or use "
        "contact_model='hard_finger'"
    )


@checked_call
def contact_frames(normals: np.ndarray) -> np.ndarray:
    """Contact frames ``R = [n, t1, t2]`` (or ``[n, t]``) for many unit normals.

    Parameters
    ----------
    normals : (..., 3) or (..., 2) float
        Unit contact normals, pointing into the object.  They are not
        re-normalised here: a length off 1 by more than
        :data:`~drakegrasp.core.tolerances.UNIT_NORMAL_TOL` (1e-6) is refused
        (:func:`contact_frame` normalises one normal).

    Returns
    -------
    R : (..., 3, 3) or (..., 2, 2) float
        Rotation matrices whose columns are ``n, t1, t2`` (spatial) or ``n, t``
        (planar), in the frame the normals are expressed in.

    Notes
    -----
    Spatial: ``t1`` is the unit projection, onto the plane normal to ``n``, of the
    coordinate axis along which ``|n|`` has its smallest component (the first such
    axis on ties), and ``t2 = n × t1``.  This depends on ``n`` alone, so equal
    normals always get equal frames.  Planar: ``t = (-n_y, n_x)``.
    """
    n = real_array("normals", normals)
    if n.ndim == 0:
        raise InvalidContactError(
            f"normals must have 2 or 3 components, got shape {n.shape}"
        )
    if not np.all(np.isfinite(n)) or not np.all(np.any(n != 0.0, axis=-1)):
        raise InvalidContactError(
            "normals must be finite, non-zero unit vectors (see contact_frame, "
            "which normalises one)"
        )
    if n.shape[-1] in (2, 3):
        off = np.abs(np.sqrt(np.sum(n * n, axis=-1)) - 1.0)  # n is float64
        if not np.all(off <= UNIT_NORMAL_TOL):
            idx = tuple(int(i) for i in np.argwhere(~(off <= UNIT_NORMAL_TOL))[0])
            where = f" at index {idx}" if idx else ""
            raise InvalidContactError(
                f"normals must be unit vectors: the normal{where} "
                f"{np.asarray(n[idx]).tolist()} has a length off 1 by "
                f"{float(off[idx]):.3g} (more than {UNIT_NORMAL_TOL:g}; normalise "
                "them, or build each frame with contact_frame, which does)"
            )
    if n.shape[-1] not in (2, 3):
        raise InvalidContactError(
            f"normals must have 2 or 3 components, got shape {n.shape}"
        )
    return _frames_of(n)


def _frames_of(n: np.ndarray) -> np.ndarray:
    """:func:`contact_frames` of unit normals already checked, float64 (..., d)."""
    if n.shape[-1] == 2:
        t = np.stack([-n[..., 1], n[..., 0]], axis=-1)
        return np.stack([n, t], axis=-1)
    axis = np.argmin(np.abs(n), axis=-1)
    e = (np.arange(3) == axis[..., None]).astype(float)
    # e·n is n's component along that axis: the other two terms are ±0
    along = np.take_along_axis(n, axis[..., None], axis=-1)
    t1 = e - along * n
    t1 /= np.linalg.norm(t1, axis=-1, keepdims=True)
    t2 = np.empty_like(n)  # n × t1, as np.cross computes it
    t2[..., 0] = n[..., 1] * t1[..., 2] - n[..., 2] * t1[..., 1]
    t2[..., 1] = n[..., 2] * t1[..., 0] - n[..., 0] * t1[..., 2]
    t2[..., 2] = n[..., 0] * t1[..., 1] - n[..., 1] * t1[..., 0]
    return np.stack([n, t1, t2], axis=-1)


@checked_call
def contact_frame(normal: np.ndarray) -> np.ndarray:
    """Contact frame ``R_i`` of one unit normal; see :func:`contact_frames`.

    Parameters
    ----------
    normal : (3,) or (2,) float
        Contact normal pointing into the object.  It is normalised here; a zero
        or non-finite normal raises :class:`~drakegrasp.InvalidContactError`.

    Returns
    -------
    R : (3, 3) or (2, 2) float
        Columns ``[n, t1, t2]`` (spatial) or ``[n, t]`` (planar); right-handed.
    """
    return contact_frames(_unit_normal(normal))


def _unit_normal(normal: np.ndarray) -> np.ndarray:
    n = real_array("normal", normal)
    if n.ndim > 1 and n.size in (2, 3):
        n = n.reshape(-1)
    if n.shape not in ((2,), (3,)):
        raise InvalidContactError(
            f"a normal must have 2 or 3 components, got shape {n.shape}"
        )
    # Divided by its largest component first: |n|^2 of a finite normal such as
    # [-1e155, 0, 0] overflows, and n / inf would be a zero vector.
    return unit_vectors("normal", n)


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


@renamed_keyword("model", "contact_model")
@checked_call
@dataclass(frozen=True, eq=False)
class Contact:
    """One contact between a finger and the object.

    Parameters
    ----------
    position : (3,) or (2,) float
        Contact point ``c`` on the object's surface, metres, in the grasp frame.
    normal : (3,) or (2,) float
        Contact normal pointing into the object, in the grasp frame; it is
        normalised.  Its dimension must match ``position``.
    mu : float, optional
        Coulomb friction coefficient, ``>= 0``.  Ignored by frictionless contacts.
    contact_model : ContactModel or str, optional
        ``"frictionless"``, ``"hard_finger"`` (default) or ``"soft_finger"``.  A
        soft finger is spatial only.  ``model=`` is its deprecated alias.
    torsional_friction : float or None, optional
        Torsional friction coefficient ``ν`` of a soft finger: the moment
        about the normal is bounded by ``b ν f_n`` with ``b`` the grasp's
        characteristic length.  ``None`` (default) means "not given": 0 for
        the other models, an error for a soft finger (one rule across the
        package: :func:`~drakegrasp.grasp_from_plant`, the batch engine and
        the command line do the same).  An explicit ``0`` is valid and makes a
        soft finger behave exactly as a hard finger.

    Raises
    ------
    InvalidContactError
        A position that is not real, finite and within
        :data:`~drakegrasp.core.validation.POSITION_BOUND`; a zero, non-finite or
        non-real normal; ``mu`` or ``ν`` outside 0 or ``[1e-12, 1e12]``; an
        unknown model; a planar soft finger or one without ``ν``.

    Notes
    -----
    Contacts are immutable; their arrays are read-only.  A hard finger with
    ``mu = 0`` has a cone that is a single ray: every program treats it exactly
    as a frictionless contact (see :meth:`effective_model`).
    """

    position: np.ndarray
    normal: np.ndarray
    mu: float = 0.0
    contact_model: ContactModel = ContactModel.HARD_FINGER
    torsional_friction: float = 0.0
    _frame: np.ndarray = field(init=False, repr=False, compare=False)

    def __init__(
        self,
        position: np.ndarray,
        normal: np.ndarray,
        *,
        mu: float = 0.0,
        contact_model: ContactModel | str = ContactModel.HARD_FINGER,
        torsional_friction: float | None = None,
    ) -> None:
        p = check_positions("contact position", position)
        if p.ndim > 1 and p.size in (2, 3):
            p = p.reshape(-1)
        if p.shape not in ((2,), (3,)):
            raise InvalidContactError(
                "a contact position must have 2 (planar) or 3 (spatial) "
                f"components, got shape {p.shape}"
            )
        p = np.array(p)
        n = _unit_normal(normal)
        if n.shape != p.shape:
            raise InvalidContactError(
                f"position {p.tolist()} has {p.size} components but normal "
                f"{n.tolist()} has {n.size}; both must be 2-D or both 3-D"
            )
        mu_value = check_coefficient("mu", mu)
        contact_model = ContactModel.parse(contact_model)
        if contact_model is ContactModel.SOFT_FINGER and p.size == 2:
            raise InvalidContactError(
                "a soft-finger contact is spatial only; planar contacts are "
                "'frictionless' or 'hard_finger'"
            )
        if torsional_friction is None:
            if contact_model is ContactModel.SOFT_FINGER:
                raise missing_torsional_friction()
            torsional_friction = 0.0
        nu_value = check_coefficient("torsional_friction", torsional_friction)
        object.__setattr__(self, "position", _frozen(p))
        object.__setattr__(self, "normal", _frozen(n))
        object.__setattr__(self, "mu", mu_value)
        object.__setattr__(self, "contact_model", contact_model)
        object.__setattr__(self, "torsional_friction", nu_value)
        object.__setattr__(self, "_frame", _frozen(_frames_of(n)))

    @property
    def dim(self) -> int:
        """Dimension of the contact: 2 (planar) or 3 (spatial)."""
        return int(self.position.size)

    @property
    def model(self) -> ContactModel:
        """Deprecated alias of ``contact_model`` (the attribute)."""
        warn_deprecated("Contact.model is deprecated; use Contact.contact_model")
        return self.contact_model

    @property
    def planar(self) -> bool:
        """True for a 2-D contact."""
        return self.dim == 2

    @property
    def frame(self) -> np.ndarray:
        """Contact frame ``R_i``, (3, 3) ``[n, t1, t2]`` or (2, 2) ``[n, t]``."""
        return self._frame

    @property
    def num_components(self) -> int:
        """Number of force components of the model (1, 2, 3 or 4)."""
        return len(self.component_names)

    @property
    def component_names(self) -> tuple[str, ...]:
        """Names of the force components in order, normal component first."""
        if self.contact_model is ContactModel.FRICTIONLESS:
            return ("f_n",)
        if self.planar:
            return ("f_n", "f_t")
        if self.contact_model is ContactModel.HARD_FINGER:
            return ("f_n", "f_t1", "f_t2")
        return ("f_n", "f_t1", "f_t2", "m_n")

    def effective_components(self) -> tuple[int, ...]:
        """Indices of the force components that the friction cone lets be non-zero.

        A hard finger with ``mu = 0`` keeps only ``f_n``; a soft finger drops its
        tangential components when ``mu = 0`` and its moment when
        ``torsional_friction = 0``.  The programs use only these components, so a
        degenerate cone never changes a verdict.
        """
        keep = [0]
        if self.contact_model is not ContactModel.FRICTIONLESS and self.mu > 0.0:
            keep += [1] if self.planar else [1, 2]
        if (
            self.contact_model is ContactModel.SOFT_FINGER
            and self.torsional_friction > 0
        ):
            keep.append(3)
        return tuple(keep)

    def effective_model(self) -> ContactModel:
        """The model this contact behaves as once degenerate cones are removed."""
        comps = self.effective_components()
        if comps == (0,):
            return ContactModel.FRICTIONLESS
        if 3 in comps:
            return ContactModel.SOFT_FINGER
        return ContactModel.HARD_FINGER

    def with_(self, **changes) -> Contact:
        """Return a copy with some fields replaced (``mu``, ``contact_model``, ...).

        A contact made a soft finger keeps the ``torsional_friction`` it
        carries; one that carries none (0, the other models' default) needs it
        given, as :class:`Contact` does.
        """
        kwargs = {
            "position": self.position,
            "normal": self.normal,
            "mu": self.mu,
            "contact_model": self.contact_model,
            "torsional_friction": self.torsional_friction,
        }
        unknown = set(changes) - set(kwargs) - {"model"}
        if unknown:
            raise InvalidContactError(
                f"Contact has no field(s) {sorted(unknown)}; "
                f"fields are {sorted(kwargs)}"
            )
        if "model" in changes:  # the deprecated alias of contact_model
            if "contact_model" in changes:
                raise InvalidOptionError(
                    "Contact.with_() got both model= (deprecated) and "
                    "contact_model=; give contact_model= only"
                )
            warn_deprecated("Contact.with_(): model= is deprecated; use contact_model=")
            changes["contact_model"] = changes.pop("model")
        kwargs.update(changes)
        if (
            "torsional_friction" not in changes
            and self.torsional_friction == 0.0
            and self.contact_model is not ContactModel.SOFT_FINGER
            and ContactModel.parse(kwargs["contact_model"]) is ContactModel.SOFT_FINGER
        ):
            # the default 0 of another model is no torsion coefficient: ask
            # for one, as Contact(contact_model="soft_finger") does
            kwargs["torsional_friction"] = None
        position = kwargs.pop("position")
        normal = kwargs.pop("normal")
        return Contact(position, normal, **kwargs)

    def to_dict(self) -> dict:
        """JSON-ready dictionary of the contact."""
        return {
            "position": self.position.tolist(),
            "normal": self.normal.tolist(),
            "mu": self.mu,
            "contact_model": self.contact_model.value,
            "torsional_friction": self.torsional_friction,
        }

    def __repr__(self) -> str:
        extra = f", nu={self.torsional_friction:g}" if self.torsional_friction else ""
        return (
            f"Contact(position={np.round(self.position, 6).tolist()}, "
            f"normal={np.round(self.normal, 6).tolist()}, mu={self.mu:g}, "
            f"contact_model={self.contact_model.value!r}{extra})"
        )
