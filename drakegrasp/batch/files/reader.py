"""Files of grasps in: a ``.npz`` archive or a directory of ``.npy`` files.

Input arrays (a directory's files are named after them: ``positions.npy``,
``normals.npy``, ...):

* ``positions`` (K, N, d) float, metres;
* ``normals`` (K, N, d) float, pointing into the object;
* optional ``mu`` (scalar, (K,) or (K, N)), ``torsional_friction`` (same
  shapes), ``reference_points`` ((d,) or (K, d)) and ``characteristic_lengths``
  (scalar or (K,)).

A ``.npz`` archive is read whole (numpy cannot map a member of a zip file); a
directory's ``.npy`` files are memory-mapped, so the engine reads one chunk of
grasps at a time and a file of millions of grasps is analysed in bounded memory
(only the per-grasp results, a few numbers each, are held).
"""

from __future__ import annotations

import math
import os
import zipfile
import zlib
from pathlib import Path

import numpy as np

from drakegrasp.core.calls import checked_call
from drakegrasp.core.files import not_a_file, unexaminable, unlistable
from drakegrasp.core.validation import path_text
from drakegrasp.errors import BatchFileError, GraspError, InvalidOptionError

__all__ = ["as_path", "engine_options", "input_files", "read_grasps"]

_OPTIONAL = ("mu", "torsional_friction", "reference_points", "characteristic_lengths")


@checked_call
def read_grasps(path: str | os.PathLike) -> dict[str, np.ndarray]:
    """Read grasps from a ``.npz`` archive or a directory of ``.npy`` files.

    Parameters
    ----------
    path : str or path-like
        ``.npz`` archive, or directory of ``.npy`` files, holding ``positions``
        and ``normals`` and the optional arrays listed in the module docstring.

    Returns
    -------
    dict of str to ndarray
        The arrays present, by name (memory-mapped for a directory).
    """
    path = as_path("input", path)
    _check_examinable(path)
    if path.is_dir():
        return _read_npy_directory(path)
    if path.suffix.lower() != ".npz":
        raise BatchFileError(
            f"input file {str(path)!r} must be a .npz archive (arrays positions, "
            "normals and optionally mu, torsional_friction, reference_points, "
            "characteristic_lengths)"
        )
    _check_regular("input file", path)
    _check_magic(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            if not hasattr(data, "files"):  # pragma: no cover - magic says zip
                raise BatchFileError(f"input file {str(path)!r} is not an archive")
            _check_names(path, "input file", list(data.files))
            _check_members(path, data.zip)
            return {k: data[k] for k in data.files}
    except GraspError:
        raise
    except MemoryError:
        raise BatchFileError(
            f"input file {str(path)!r} holds more than the free memory (a .npz "
            "archive is read whole); store its arrays as a directory of .npy "
            "files, which is memory-mapped"
        ) from None
    except ValueError as err:
        if "pickle" in str(err):
            raise BatchFileError(
                f"input file {str(path)!r} holds object arrays (pickled Python "
                "objects), which drakegrasp never loads; store numeric arrays"
            ) from None
        raise _corrupt(path, err) from None
    except (zipfile.BadZipFile, zlib.error, EOFError, OSError, KeyError) as err:
        raise _corrupt(path, err) from None


_ZIP_MAGIC = (b"PK\x03\x04", b"PK\x05\x06")


_NPY_MAGIC = b"\x93NUMPY"


def as_path(what: str, path) -> Path:
    """``path`` as a ``Path``; a clear error for anything but a non-empty path.

    Read by :func:`~drakegrasp.core.validation.path_text`, as every path is.
    """
    return Path(path_text(what, path, error=BatchFileError))


def _check_regular(what: str, path: Path) -> None:
    """Refuse anything but a regular file by ``stat``, before it is opened.

    Opening a named pipe would block until a writer comes, and a device would
    be read forever or as nothing.
    """
    why = not_a_file(path)
    if why:
        raise BatchFileError(f"{what} {str(path)!r} {why}")


def _check_header(where: str, name: str, f, size: int) -> None:
    """Refuse an array whose header claims more bytes than its ``.npy`` holds.

    ``f`` is open at the start of the array's ``.npy`` bytes, ``size`` bytes
    long; numpy would allocate what the header claims before reading a byte.
    """
    version = np.lib.format.read_magic(f)
    read = (
        np.lib.format.read_array_header_1_0
        if version == (1, 0)
        else np.lib.format.read_array_header_2_0  # 3.0 differs in encoding only
    )
    shape, _, dtype = read(f)
    if dtype.hasobject:  # refused as pickled objects when loaded
        return
    claimed, held = math.prod(shape) * dtype.itemsize, size - f.tell()
    if claimed > held:
        raise BatchFileError(
            f"{where} is damaged: {name} claims shape {shape} of {dtype} "
            f"({claimed} bytes) in {held} bytes; write it again"
        )


def _check_members(path: Path, archive: zipfile.ZipFile) -> None:
    """Check every member's array header against the bytes the member holds.

    A legitimate array occupies its member's uncompressed size (``file_size``;
    a stored member also its ``compress_size``, within the archive).
    """
    total = path.stat().st_size
    for info in archive.infolist():
        size = info.file_size
        if info.compress_type == zipfile.ZIP_STORED:
            size = min(size, info.compress_size, total)
        with archive.open(info) as f:
            name = info.filename.removesuffix(".npy")
            _check_header(f"input file {str(path)!r}", name, f, size)


def _check_magic(path: Path) -> None:
    """Refuse a file that is not a zip archive before numpy guesses at it."""
    try:
        with open(path, "rb") as f:
            head = f.read(6)
    except FileNotFoundError:
        raise BatchFileError(f"input file {str(path)!r} does not exist") from None
    except OSError as err:
        raise BatchFileError(
            f"input file {str(path)!r} cannot be read: {err.strerror or err}"
        ) from None
    if head.startswith(_NPY_MAGIC):
        raise BatchFileError(
            f"input file {str(path)!r} holds one .npy array, not a .npz archive "
            "of named arrays (positions, normals, ...)"
        )
    if not head.startswith(_ZIP_MAGIC):
        kind = "is empty" if not head else f"starts with {head!r}"
        raise BatchFileError(
            f"input file {str(path)!r} is not a .npz archive (it {kind}; a .npz "
            "file is the zip archive that numpy.savez writes)"
        )


def _corrupt(path: Path, err: Exception) -> BatchFileError:
    return BatchFileError(
        f"input file {str(path)!r} is a damaged or truncated .npz archive "
        f"({type(err).__name__}: {err}); write it again"
    )


def _check_names(path: Path, what: str, names: list[str]) -> None:
    missing = [k for k in ("positions", "normals") if k not in names]
    if missing:
        raise BatchFileError(
            f"{what} {str(path)!r} has no array(s) {missing}; it holds {sorted(names)}"
        )
    unknown = set(names) - {"positions", "normals", *_OPTIONAL}
    if unknown:
        raise BatchFileError(
            f"{what} {str(path)!r} has unknown array(s) {sorted(unknown)}; "
            f"valid names are positions, normals, {', '.join(_OPTIONAL)}"
        )


def _read_npy_directory(path: Path) -> dict[str, np.ndarray]:
    names = {f.stem: f for f in sorted(path.glob("*.npy"))}
    _check_names(path, "input directory", list(names))
    for f in names.values():
        _check_regular("input file", f)
    try:
        for k, f in names.items():
            with open(f, "rb") as fp:
                size = os.fstat(fp.fileno()).st_size
                _check_header(f"input directory {str(path)!r}", k, fp, size)
        return {
            k: np.load(f, mmap_mode="r", allow_pickle=False) for k, f in names.items()
        }
    except (ValueError, OSError, EOFError) as err:
        raise BatchFileError(
            f"input directory {str(path)!r} holds an unreadable .npy file ({err})"
        ) from None


def input_files(source: Path) -> list[Path]:
    """``source`` and, for a directory, the ``.npy`` files it holds."""
    _check_examinable(source)
    return [source, *(sorted(source.glob("*.npy")) if source.is_dir() else [])]


def _check_examinable(path: Path) -> None:
    """Refuse an input whose kind, or a directory's names, cannot be read.

    In a folder this process may not search, pathlib's ``is_dir()`` raised
    ``PermissionError``; a directory it may not read globbed as empty.
    """
    why = unexaminable(path)
    if not why and path.is_dir():
        why = unlistable(path)
    if why:
        raise BatchFileError(f"input {str(path)!r} {why}")


def engine_options(
    data: dict, input_path, *, kind: str, mu, torsional_friction
) -> dict:
    """What a grasp file gives the engine besides positions and normals.

    Parameters
    ----------
    data : dict
        The arrays :func:`read_grasps` returned.
    input_path : str or path-like
        The file, named in the error when friction is missing.
    kind : {"force", "form"}
    mu, torsional_friction : optional
        Given values override the file's arrays.

    Returns
    -------
    dict
        ``reference_points`` and ``characteristic_lengths`` (or None); for
        force closure also ``mu`` (given, else the file's: one is needed) and
        ``torsional_friction`` (given, else the file's, else None).
    """
    options = {
        "reference_points": data.get("reference_points"),
        "characteristic_lengths": data.get("characteristic_lengths"),
    }
    if kind == "force":
        value = mu if mu is not None else data.get("mu")
        if value is None:
            raise InvalidOptionError(
                f"force closure needs friction: {str(input_path)!r} has no array "
                "'mu' and no mu was given"
            )
        options["mu"] = value
        options["torsional_friction"] = (
            torsional_friction
            if torsional_friction is not None
            else data.get("torsional_friction")
        )
    return options
