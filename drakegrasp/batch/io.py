"""Files of grasps in, files of verdicts out (the ``drakegrasp batch`` command).

Input: a ``.npz`` archive, or a directory of ``.npy`` files named after them
(``positions.npy``, ``normals.npy``, ...), with arrays

* ``positions`` (K, N, d) float, metres;
* ``normals`` (K, N, d) float, pointing into the object;
* optional ``mu`` (scalar, (K,) or (K, N)), ``torsional_friction`` (same
  shapes), ``reference_points`` ((d,) or (K, d)) and ``characteristic_lengths``
  (scalar or (K,)).

A ``.npz`` archive is read whole (numpy cannot map a member of a zip file); a
directory's ``.npy`` files are memory-mapped, so the engine reads one chunk of
grasps at a time and a file of millions of grasps is analysed in bounded memory
(only the per-grasp results, a few numbers each, are held).

Output: ``.npz`` with the per-grasp arrays of :class:`BatchClosureResult`
(``is_closure``, ``d_star``, ``rank``, ``margin``, ``converged`` and the metrics)
plus 0-d arrays ``kind``, ``tol`` and ``required_rank``; or ``.parquet`` (one row
per grasp, the same columns) when the optional package ``pyarrow`` is installed.
The suffix is matched case-insensitively and the file is written under exactly
the name given (``OUT.NPZ`` stays ``OUT.NPZ``).

No data is lost:

* the output is written to a temporary file in the same directory and renamed
  into place (``os.replace``, atomic on POSIX), so an interrupted or failed
  run leaves any earlier file intact and no partial file behind;
* an output that is the input (the same path, or the same file through a
  symbolic or hard link) is refused;
* an existing output is refused unless ``overwrite=True``
  (``drakegrasp batch --overwrite``); this is checked before any grasp is
  analysed, so a long run never ends in a refusal.
"""

from __future__ import annotations

import os
import tempfile
import zipfile
import zlib
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from drakegrasp.batch.engine import (
    DEFAULT_CHUNK_SIZE,
    DEFAULT_RANK_TOL,
    DEFAULT_TOL,
    BatchClosureResult,
    batch_force_closure,
    batch_form_closure,
)
from drakegrasp.core.contact import ContactModel
from drakegrasp.core.validation import check_flag
from drakegrasp.errors import BatchFileError, GraspError, InvalidOptionError

__all__ = ["BatchFileError", "evaluate_file", "read_grasps", "write_result"]

_OPTIONAL = ("mu", "torsional_friction", "reference_points", "characteristic_lengths")


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
    path = _as_path("input", path)
    if path.is_dir():
        return _read_npy_directory(path)
    if path.suffix.lower() != ".npz":
        raise BatchFileError(
            f"input file {str(path)!r} must be a .npz archive (arrays positions, "
            "normals and optionally mu, torsional_friction, reference_points, "
            "characteristic_lengths)"
        )
    _check_magic(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            if not hasattr(data, "files"):  # pragma: no cover - magic says zip
                raise BatchFileError(f"input file {str(path)!r} is not an archive")
            _check_names(path, "input file", list(data.files))
            return {k: data[k] for k in data.files}
    except GraspError:
        raise
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


def _as_path(what: str, path) -> Path:
    if not isinstance(path, (str, os.PathLike)) or not str(path):
        raise BatchFileError(f"{what} must be a file path, got {path!r}")
    return Path(path)


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
    try:
        return {
            k: np.load(f, mmap_mode="r", allow_pickle=False) for k, f in names.items()
        }
    except (ValueError, OSError, EOFError) as err:
        raise BatchFileError(
            f"input directory {str(path)!r} holds an unreadable .npy file ({err})"
        ) from None


def _check_output(
    output: Path, inputs: Sequence[Path], *, overwrite: bool
) -> tuple[Path, str]:
    """Refuse an output that is an input or exists (unless overwrite); its format."""
    suffix = output.suffix.lower()
    if suffix not in (".npz", ".parquet"):
        raise BatchFileError(
            f"output file {str(output)!r} must end in .npz (or .parquet with pyarrow)"
        )
    for source in inputs:
        same = output.resolve() == source.resolve()
        if not same and output.exists() and source.exists():
            same = os.path.samefile(output, source)
        if same:
            raise BatchFileError(
                f"output file {str(output)!r} is the input file {str(source)!r}; "
                "writing the results would destroy the grasps: choose another "
                "output"
            )
    if output.is_dir():
        raise BatchFileError(f"output {str(output)!r} is a directory, not a file")
    if output.exists() and not overwrite:
        raise BatchFileError(
            f"output file {str(output)!r} exists; pass overwrite=True "
            "(drakegrasp batch --overwrite) to replace it"
        )
    if not output.parent.is_dir():
        raise BatchFileError(f"output directory {str(output.parent)!r} does not exist")
    return output, suffix


def write_result(
    result: BatchClosureResult,
    path: str | os.PathLike,
    *,
    overwrite: bool = False,
) -> Path:
    """Write a batch result to ``.npz`` (or ``.parquet`` if pyarrow is present).

    Parameters
    ----------
    result : BatchClosureResult
    path : str or path-like
        Output file; its suffix (any case) picks the format, and the file is
        written under exactly this name.
    overwrite : bool, optional
        Replace an existing file (default: refuse).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    BatchFileError
        An existing file without ``overwrite``, a bad suffix, a missing
        directory; pyarrow missing for ``.parquet``.

    Notes
    -----
    The data go to a temporary file in the same directory, which is renamed
    onto ``path`` only once complete: a failure or an interrupt never leaves a
    partial file, nor destroys an earlier one.
    """
    if not isinstance(result, BatchClosureResult):
        raise BatchFileError(
            f"result must be a BatchClosureResult, got {type(result).__name__}"
        )
    overwrite = check_flag("overwrite", overwrite)
    path, suffix = _check_output(_as_path("output", path), (), overwrite=overwrite)
    arrays = result.to_arrays()
    if suffix == ".parquet":
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ImportError as exc:
            raise BatchFileError(
                "writing .parquet needs the optional package pyarrow, which is "
                "not installed (pip install pyarrow); write .npz instead"
            ) from exc
        table = pa.table(dict(arrays))
        table = table.replace_schema_metadata(
            {
                "kind": result.kind,
                "tol": repr(result.tol),
                "required_rank": str(result.required_rank),
            }
        )

        def write(f):
            pq.write_table(table, f)
    else:

        def write(f):
            np.savez(
                f,
                kind=np.array(result.kind),
                tol=np.array(result.tol),
                required_rank=np.array(result.required_rank),
                **arrays,
            )

    _atomic_write(path, write, overwrite=overwrite)
    return path


def _link_or_rename(tmp: str, path: Path) -> None:
    """Move tmp to path without replacing a file that appeared meanwhile."""
    try:
        os.link(tmp, path)  # atomic, and fails if path exists
    except FileExistsError:
        raise
    except OSError:  # a file system without hard links
        if path.exists():
            raise FileExistsError(path) from None
        os.replace(tmp, path)
        return
    os.unlink(tmp)


def _atomic_write(path: Path, write, *, overwrite: bool) -> None:
    """``write(file object)`` into a temporary sibling, then rename it onto path."""
    fd, tmp = tempfile.mkstemp(
        dir=path.parent, prefix=f".{path.name}.", suffix=".partial"
    )
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        if overwrite:
            os.replace(tmp, path)
        else:
            _link_or_rename(tmp, path)
    except FileExistsError:
        os.unlink(tmp)
        raise BatchFileError(
            f"output file {str(path)!r} appeared while writing; pass "
            "overwrite=True to replace it"
        ) from None
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def evaluate_file(
    input_path: str | os.PathLike,
    output_path: str | os.PathLike,
    *,
    kind: str = "force",
    mu: float | None = None,
    model: ContactModel | str = "hard_finger",
    num_generators: int = 8,
    torsional_friction: float | None = None,
    tol: float = DEFAULT_TOL,
    rank_tol: float = DEFAULT_RANK_TOL,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    progress: bool = False,
    metrics: Sequence[str] = (),
    overwrite: bool = False,
) -> BatchClosureResult:
    """Decide closure for every grasp of a file and write the verdicts.

    Parameters
    ----------
    input_path : str or path-like
        ``.npz`` archive of grasps, or a directory of ``.npy`` files (memory-
        mapped: bounded memory for any number of grasps); see the module
        docstring.
    output_path : str or path-like
        ``.npz`` (or ``.parquet`` with pyarrow) file to write; never the input.
    kind : {"force", "form"}, optional
        LP2 (:func:`batch_force_closure`) or LP1 (:func:`batch_form_closure`).
    mu : float, optional
        Friction coefficient for every contact; overrides the file's ``mu``.
        Force closure needs one or the other; form closure ignores both.
    model, num_generators, tol, rank_tol, chunk_size, progress, metrics : optional
        As in :func:`batch_force_closure`.
    torsional_friction : float, optional
        Overrides the file's ``torsional_friction``.  A soft-finger run needs
        one or the other (an explicit 0 makes the fingers act as hard ones).
    overwrite : bool, optional
        Replace an existing output (default: refuse, before any work).

    Returns
    -------
    BatchClosureResult
        What was written.

    Raises
    ------
    BatchFileError
        Unreadable, damaged or non-``.npz`` input; an output that is the input
        or that exists without ``overwrite``.
    GraspError
        Any invalid grasp or option (see :mod:`drakegrasp.core.validation`).
    """
    if kind not in ("force", "form"):
        raise InvalidOptionError(f"kind must be 'force' or 'form', got {kind!r}")
    source = _as_path("input", input_path)
    inputs = [source]
    if source.is_dir():
        inputs += sorted(source.glob("*.npy"))
    output = _as_path("output", output_path)
    _check_output(output, inputs, overwrite=check_flag("overwrite", overwrite))
    data = read_grasps(source)
    common = {"chunk_size": chunk_size, "progress": progress, "metrics": metrics}
    common.update(_file_options(data, tol=tol, rank_tol=rank_tol))
    if kind == "force":
        result = batch_force_closure(
            data["positions"],
            data["normals"],
            _friction_of(data, input_path, mu),
            model=model,
            num_generators=num_generators,
            torsional_friction=_torsion_of(data, torsional_friction),
            **common,
        )
    else:
        result = batch_form_closure(data["positions"], data["normals"], **common)
    write_result(result, output, overwrite=overwrite)
    return result


def _file_options(data: dict, *, tol: float, rank_tol: float) -> dict:
    """Engine options every kind takes from a grasp file's optional arrays."""
    return {
        "reference_points": data.get("reference_points"),
        "characteristic_lengths": data.get("characteristic_lengths"),
        "tol": tol,
        "rank_tol": rank_tol,
    }


def _friction_of(data: dict, input_path, mu):
    """``mu`` if given, else the file's array ``mu``; force closure needs one."""
    value = mu if mu is not None else data.get("mu")
    if value is None:
        raise InvalidOptionError(
            f"force closure needs friction: {str(input_path)!r} has no array "
            "'mu' and no mu was given"
        )
    return value


def _torsion_of(data: dict, torsional_friction):
    """``torsional_friction`` if given, else the file's array (or None)."""
    if torsional_friction is not None:
        return torsional_friction
    return data.get("torsional_friction")
