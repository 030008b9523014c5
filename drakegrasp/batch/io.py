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
"""

from __future__ import annotations

import os
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
from drakegrasp.contact import ContactModel
from drakegrasp.errors import InvalidOptionError

__all__ = ["evaluate_file", "read_grasps", "write_result"]

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
    path = Path(path)
    if path.is_dir():
        return _read_npy_directory(path)
    if path.suffix.lower() != ".npz":
        raise InvalidOptionError(
            f"input file {str(path)!r} must be a .npz archive (arrays positions, "
            "normals and optionally mu, torsional_friction, reference_points, "
            "characteristic_lengths)"
        )
    try:
        archive = np.load(path, allow_pickle=False)
    except (ValueError, EOFError) as err:  # not .npy/.npz data at all
        raise InvalidOptionError(
            f"input file {str(path)!r} is not a readable .npz archive ({err})"
        ) from None
    if not hasattr(archive, "files"):  # a lone .npy array renamed .npz
        raise InvalidOptionError(
            f"input file {str(path)!r} holds one array, not a .npz archive of "
            "named arrays (positions, normals, ...)"
        )
    with archive as data:
        missing = [k for k in ("positions", "normals") if k not in data.files]
        if missing:
            raise InvalidOptionError(
                f"input file {str(path)!r} has no array(s) {missing}; it holds "
                f"{sorted(data.files)}"
            )
        unknown = set(data.files) - {"positions", "normals", *_OPTIONAL}
        if unknown:
            raise InvalidOptionError(
                f"input file {str(path)!r} has unknown array(s) {sorted(unknown)}; "
                f"valid names are positions, normals, {', '.join(_OPTIONAL)}"
            )
        return {k: data[k] for k in data.files}


def _read_npy_directory(path: Path) -> dict[str, np.ndarray]:
    names = {f.stem: f for f in sorted(path.glob("*.npy"))}
    missing = [k for k in ("positions", "normals") if k not in names]
    if missing:
        raise InvalidOptionError(
            f"input directory {str(path)!r} has no "
            f"{', '.join(m + '.npy' for m in missing)}; it holds "
            f"{sorted(f.name for f in names.values())}"
        )
    unknown = set(names) - {"positions", "normals", *_OPTIONAL}
    if unknown:
        raise InvalidOptionError(
            f"input directory {str(path)!r} has unknown array(s) {sorted(unknown)}; "
            f"valid names are positions, normals, {', '.join(_OPTIONAL)}"
        )
    try:
        return {
            k: np.load(f, mmap_mode="r", allow_pickle=False) for k, f in names.items()
        }
    except ValueError as err:
        raise InvalidOptionError(
            f"input directory {str(path)!r} holds an unreadable .npy file ({err})"
        ) from None


def write_result(result: BatchClosureResult, path: str | os.PathLike) -> Path:
    """Write a batch result to ``.npz`` (or ``.parquet`` if pyarrow is present).

    Parameters
    ----------
    result : BatchClosureResult
    path : str or path-like
        Output file; its suffix picks the format.

    Returns
    -------
    Path
        The file written.
    """
    path = Path(path)
    arrays = result.to_arrays()
    suffix = path.suffix.lower()
    if suffix == ".npz":
        np.savez(
            path,
            kind=np.array(result.kind),
            tol=np.array(result.tol),
            required_rank=np.array(result.required_rank),
            **arrays,
        )
        return path
    if suffix == ".parquet":
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ImportError as exc:
            raise InvalidOptionError(
                "writing .parquet needs the optional package pyarrow "
                "(pip install pyarrow); write .npz instead"
            ) from exc
        table = pa.table(dict(arrays))
        table = table.replace_schema_metadata(
            {
                "kind": result.kind,
                "tol": repr(result.tol),
                "required_rank": str(result.required_rank),
            }
        )
        pq.write_table(table, path)
        return path
    raise InvalidOptionError(
        f"output file {str(path)!r} must end in .npz (or .parquet with pyarrow)"
    )


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
) -> BatchClosureResult:
    """Decide closure for every grasp of a file and write the verdicts.

    Parameters
    ----------
    input_path : str or path-like
        ``.npz`` archive of grasps, or a directory of ``.npy`` files (memory-
        mapped: bounded memory for any number of grasps); see the module
        docstring.
    output_path : str or path-like
        ``.npz`` (or ``.parquet`` with pyarrow) file to write.
    kind : {"force", "form"}, optional
        LP2 (:func:`batch_force_closure`) or LP1 (:func:`batch_form_closure`).
    mu : float, optional
        Friction coefficient for every contact; overrides the file's ``mu``.
        Force closure needs one or the other.
    model, num_generators, tol, rank_tol, chunk_size, progress, metrics : optional
        As in :func:`batch_force_closure`.
    torsional_friction : float, optional
        Overrides the file's ``torsional_friction`` (default 0).

    Returns
    -------
    BatchClosureResult
        What was written.
    """
    data = read_grasps(input_path)
    common = {
        "reference_points": data.get("reference_points"),
        "characteristic_lengths": data.get("characteristic_lengths"),
        "tol": tol,
        "rank_tol": rank_tol,
        "chunk_size": chunk_size,
        "progress": progress,
        "metrics": metrics,
    }
    if kind == "force":
        mu_value = mu if mu is not None else data.get("mu")
        if mu_value is None:
            raise InvalidOptionError(
                f"force closure needs friction: {str(input_path)!r} has no array "
                "'mu' and no mu was given"
            )
        nu = torsional_friction
        if nu is None:
            nu = data.get("torsional_friction", 0.0)
        result = batch_force_closure(
            data["positions"],
            data["normals"],
            mu_value,
            model=model,
            num_generators=num_generators,
            torsional_friction=nu,
            **common,
        )
    elif kind == "form":
        result = batch_form_closure(data["positions"], data["normals"], **common)
    else:
        raise InvalidOptionError(f"kind must be 'force' or 'form', got {kind!r}")
    write_result(result, output_path)
    return result
