"""Does a witness belong to this grasp?  Its arrays, read once (numpy only).

:meth:`~drakegrasp.certificates.certificate.Certificate.check` evaluates a
witness's inequalities on a grasp.  A forged or mismatched witness must not
reach that evaluation: a wrong shape would raise a raw numpy error, a NaN would
vanish in ``max(0.0, nan) == 0.0`` and a huge component would overflow a norm
into ``inf`` and divide every violation to 0.  This module reads the witness's
arrays as real float arrays, checks their shapes against the grasp (naming the
one that belongs to another grasp), and says whether every entry is finite.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from drakegrasp.certificates.kinds import (
    BALANCE,
    ESCAPE_TWIST,
    UNCONTROLLABLE,
    UNRESISTED_WRENCH,
    Witness,
)
from drakegrasp.core.grasp import Grasp
from drakegrasp.core.validation import (
    check_grasp,
    check_num_generators,
    describe,
    real_array,
    real_scalar,
)
from drakegrasp.errors import InvalidOptionError

__all__ = ["ReadWitness", "check_tolerance", "read_witness"]


@dataclass(frozen=True)
class ReadWitness:
    """A witness's arrays as float64, shapes checked against one grasp.

    The field names and the two methods are those of
    :class:`~drakegrasp.certificates.kinds.Witness` that the check reads.
    ``finite`` is False when some entry is NaN or infinite (the check then
    reports the witness as failing without evaluating it).
    """

    kind: str
    cones: str
    direction: np.ndarray | None
    null_basis: np.ndarray
    separating_twist: np.ndarray | None
    separating_basis: np.ndarray
    contact_forces: tuple[np.ndarray, ...] | None
    num_generators: int
    finite: bool

    @property
    def two_sided(self) -> bool:
        """True when both signs of the direction are witnesses."""
        return self.null_basis.shape[-1] > 0

    def stacked_forces(self) -> np.ndarray:
        """The internal force as one (M,) vector in ``G``'s column order."""
        if self.contact_forces is None:
            return np.zeros(0)
        return np.concatenate(self.contact_forces)


def check_tolerance(value) -> float:
    """The check's relative tolerance: a real number in (0, 1).

    Every violation is relative (0 when the inequalities hold, 1 when they fail
    by their own scale), so a tolerance of 1 or more would pass any witness.
    """
    x = real_scalar("tol", value)
    if not (0.0 < x < 1.0) or not math.isfinite(x):
        raise InvalidOptionError(
            f"tol must be a real number in (0, 1), got {describe(value)}: the check's "
            "violations are relative, and a tolerance of 1 or more passes any "
            "witness"
        )
    return x


def _foreign(what: str, got, want: str, grasp: Grasp) -> InvalidOptionError:
    kind = "planar" if grasp.planar else "spatial"
    return InvalidOptionError(
        f"this certificate belongs to another grasp: its {what} has shape {got}, "
        f"while the grasp ({grasp.num_contacts} {kind} contacts, "
        f"{grasp.num_components} force components) needs {want}"
    )


def _vector(cert: Witness, name: str, grasp: Grasp) -> np.ndarray:
    value = getattr(cert, name)
    if value is None:
        raise InvalidOptionError(
            f"a {cert.kind!r} certificate needs its {name}, got None"
        )
    a = real_array(f"the certificate's {name}", value, error=InvalidOptionError)
    if a.shape != (grasp.wrench_dim,):
        raise _foreign(name, a.shape, f"({grasp.wrench_dim},)", grasp)
    return a


def _basis(cert: Witness, name: str, grasp: Grasp) -> np.ndarray:
    a = real_array(
        f"the certificate's {name}", getattr(cert, name), error=InvalidOptionError
    )
    if a.size == 0:
        return np.zeros((grasp.wrench_dim, 0))
    if a.ndim != 2 or a.shape[0] != grasp.wrench_dim:
        raise _foreign(name, a.shape, f"({grasp.wrench_dim}, k)", grasp)
    return a


def _forces(cert: Witness, grasp: Grasp) -> tuple[np.ndarray, ...]:
    forces = cert.contact_forces
    if forces is None or isinstance(forces, (str, bytes)):
        raise InvalidOptionError(
            f"a {cert.kind!r} certificate needs its contact_forces (one array per "
            f"contact), got {describe(forces)}"
        )
    try:
        forces = list(forces)
    except TypeError:
        raise InvalidOptionError(
            "the certificate's contact_forces must be a sequence of arrays, one "
            f"per contact, got {type(cert.contact_forces).__name__}"
        ) from None
    if len(forces) != grasp.num_contacts:
        raise _foreign(
            "contact_forces", (len(forces),), f"{grasp.num_contacts} contacts", grasp
        )
    out = []
    for i, (f, c) in enumerate(zip(forces, grasp.contacts, strict=True)):
        a = real_array(
            f"the certificate's force of contact {i}", f, error=InvalidOptionError
        )
        if cert.cones == "normals" and a.shape == (1,):
            # form closure reports [f_n] only: the other components are zero
            a = np.concatenate([a, np.zeros(c.num_components - 1)])
        if a.shape != (c.num_components,):
            raise _foreign(
                f"force of contact {i}",
                a.shape,
                f"({c.num_components},) for a {c.contact_model.value} contact",
                grasp,
            )
        out.append(a)
    return tuple(out)


def read_witness(cert: Witness, grasp: Grasp) -> ReadWitness:
    """Read ``cert``'s arrays for a check on ``grasp``.

    Raises
    ------
    InvalidGraspError
        When ``grasp`` is not a Grasp.
    InvalidOptionError
        When an array is not real, or its shape is that of another grasp (other
        number of contacts, other dimension, other contact models).
    """
    check_grasp(grasp)
    n_g = check_num_generators(cert.num_generators)
    if cert.kind in (ESCAPE_TWIST, UNRESISTED_WRENCH):
        direction = _vector(cert, "direction", grasp)
        null_basis = _basis(cert, "null_basis", grasp)
        arrays = [direction, null_basis]
        twist, sep_basis, forces = None, np.zeros((grasp.wrench_dim, 0)), None
        if cert.kind == UNRESISTED_WRENCH:
            twist = _vector(cert, "separating_twist", grasp)
            sep_basis = _basis(cert, "separating_basis", grasp)
            if sep_basis.shape != null_basis.shape:
                raise InvalidOptionError(
                    "the certificate's separating_basis has shape "
                    f"{sep_basis.shape}, its null_basis {null_basis.shape}: one "
                    "separating twist per null-space wrench is needed"
                )
            arrays += [twist, sep_basis]
    else:
        assert cert.kind in (UNCONTROLLABLE, BALANCE)
        direction, twist = None, None
        null_basis = sep_basis = np.zeros((grasp.wrench_dim, 0))
        forces = _forces(cert, grasp)
        arrays = list(forces)
    finite = all(bool(np.all(np.isfinite(a))) for a in arrays)
    return ReadWitness(
        kind=cert.kind,
        cones=cert.cones,
        direction=direction,
        null_basis=null_basis,
        separating_twist=twist,
        separating_basis=sep_basis,
        contact_forces=forces,
        num_generators=n_g,
        finite=finite,
    )
