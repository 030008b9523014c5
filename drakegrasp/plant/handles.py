r"""Drake's handles in a pickled contact: what each one names, and where.

A :class:`~drakegrasp.plant.contacts.PlantContact` names its finger body by a
``BodyIndex`` and its two geometries by ``GeometryId``\ s, and pydrake pickles
neither, so a planned candidate could not be sent to another process
(``multiprocessing``, ``concurrent.futures``, Dask).  The two mean different
things outside the process that read them:

- a ``BodyIndex`` is the body's place in its plant, the same in every process
  that builds the same plant (as the body's scoped name is): it pickles as its
  number and is ``BodyIndex(number)`` again when unpickled;
- a ``GeometryId`` is a number that the process which registered the geometry
  drew from a counter of its own (every id Drake makes, of any kind, takes the
  next one), and pydrake makes no ``GeometryId`` from a number.  The same
  number in another process names another geometry, or none.  It pickles as
  its number and the process it came from; unpickled in that process it is
  the very ``GeometryId`` again, and in any other a :class:`ForeignGeometryId`,
  which says where it came from.  drakegrasp's functions that read a
  contact's geometry from a scene graph
  (:func:`~drakegrasp.plant.friction.pair_friction`,
  :func:`~drakegrasp.plant.friction.plant_friction`,
  :func:`~drakegrasp.plant.curvature.contact_curvatures`) refuse one
  (:func:`local_geometry_id`) rather than read whatever geometry has that
  number there.

So a candidate sent to a worker and back is whole again, and in the worker
everything but its contacts' two geometry ids works as it does at home: the
contact's points, normals, names, its geometries' labels
(``finger_geometry_label``, the same in every process), its finger's
``BodyIndex``, the candidate's ``grasp``, ``apply`` and ``to_dict``.  To read
a contact's geometry there, find the contacts again in that process:
``candidate.apply(plant, context)``, then
:func:`~drakegrasp.plant.contacts.find_contacts`.

A process started by ``fork`` is another process here too: it draws a name
of its own, and the ids it inherited count as foreign there.
"""

from __future__ import annotations

import os
import uuid
from dataclasses import dataclass
from typing import Any

from pydrake.geometry import GeometryId
from pydrake.multibody.tree import BodyIndex

from drakegrasp.errors import InvalidContactError

__all__ = ["ForeignGeometryId", "local_geometry_id", "pickled_handle"]

_SALT = uuid.uuid4().hex
"""Drawn once per interpreter; with the process id it names this process (a
forked child keeps the salt and has another id)."""

_MADE_HERE: dict[int, GeometryId] = {}
"""The ``GeometryId`` of each number this process has pickled, to give back the
same object when one comes home (a few bytes per geometry)."""


def _forked() -> None:
    """In a forked child: a name of its own, and none of its parent's ids.

    A child keeps the parent's salt, and a later sibling may get a dead
    child's pid; an id the parent forwards from one must not come home as
    another's.
    """
    global _SALT
    _SALT = uuid.uuid4().hex
    _MADE_HERE.clear()


os.register_at_fork(after_in_child=_forked)


def this_process() -> str:
    """The name of this process in a pickled ``GeometryId`` (salt and pid)."""
    return f"{_SALT}:{os.getpid()}"


@dataclass(frozen=True)
class ForeignGeometryId:
    """A ``GeometryId`` pickled in another process, which it names alone.

    It holds the id's number and the process that made it; pickled again, it
    becomes that ``GeometryId`` once back in that process.  Drake's functions
    do not take it, and drakegrasp's refuse it with an
    :class:`~drakegrasp.InvalidContactError` (see the module).

    Attributes
    ----------
    value : int
        The id's number (``GeometryId.get_value()``) in its own process.
    process : str
        The process that made it (an opaque name).
    """

    value: int
    process: str

    def get_value(self) -> int:
        """The id's number in the process that made it, as ``GeometryId``'s."""
        return self.value

    def __repr__(self) -> str:
        return f"<GeometryId value={self.value} of another process>"

    def __reduce__(self):
        return (_unpickled_geometry_id, (self.value, self.process))


def _unpickled_geometry_id(value: int, process: str) -> Any:
    """The ``GeometryId`` itself in the process that made it, else its stand-in."""
    if process == this_process():
        known = _MADE_HERE.get(value)
        if known is not None:
            return known
    return ForeignGeometryId(int(value), str(process))


@dataclass(frozen=True)
class _PickledBodyIndex:
    """A ``BodyIndex`` on its way into a pickle: it is unpickled as one."""

    value: int

    def __reduce__(self):
        return (BodyIndex, (self.value,))


def pickled_handle(value: Any) -> Any:
    """``value`` ready for pickling: a Drake handle as a stand-in, else itself.

    A ``BodyIndex`` is unpickled as ``BodyIndex`` of the same number; a
    ``GeometryId`` as itself in this process and as a
    :class:`ForeignGeometryId` in any other (see the module).
    """
    if isinstance(value, BodyIndex):
        return _PickledBodyIndex(int(value))
    if isinstance(value, GeometryId):
        number = int(value.get_value())
        _MADE_HERE.setdefault(number, value)
        return ForeignGeometryId(number, this_process())
    return value


def local_geometry_id(geometry: Any, what: str) -> Any:
    """``geometry``, unless it is a :class:`ForeignGeometryId`.

    Parameters
    ----------
    geometry : GeometryId or ForeignGeometryId
    what : str
        What it is, for the message (``"contact 2's object_geometry"``).

    Raises
    ------
    InvalidContactError
        A :class:`ForeignGeometryId`: it names a geometry of another process.
    """
    if isinstance(geometry, ForeignGeometryId):
        raise InvalidContactError(
            f"{what} is {geometry!r}: the contact was found in another process "
            "and pickled, and a GeometryId names a geometry only in the process "
            "that made it; find the contacts again in this process "
            "(candidate.apply(plant, context), then find_contacts)"
        )
    return geometry
