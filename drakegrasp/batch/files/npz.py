"""The ``.npz`` result writer: chunks appended in flat memory, then one archive.

Each result array is appended, chunk by chunk, to its own ``.npy`` file in a
scratch directory beside the output (the header is written first, since ``K``
is known); the files are then copied block by block into an uncompressed zip
archive that ``numpy.load`` reads like ``numpy.savez``'s, with the 0-d arrays
``kind``, ``tol`` and ``required_rank``, made in the scratch directory too and
moved to the output's name once complete.  The scratch directory is removed on
success and on failure.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile
import zipfile
from pathlib import Path

import numpy as np

__all__ = ["NpzWriter"]


class NpzWriter:
    """Write ``K`` rows of result arrays to ``path``, chunk by chunk."""

    def __init__(self, path: Path, K: int, meta: dict):
        self.path, self.K, self.meta = path, K, meta
        self.scratch = Path(tempfile.mkdtemp(prefix=".batch-", dir=path.parent))
        self.files: dict[str, object] = {}
        self.names: list[str] = []

    def write(self, arrays: dict[str, np.ndarray]) -> None:
        """Append one chunk's arrays (a row each per grasp)."""
        for name, a in arrays.items():
            if name not in self.files:
                f = open(self.scratch / f"{name}.npy", "wb")  # noqa: SIM115
                header = {"descr": np.lib.format.dtype_to_descr(a.dtype),
                          "fortran_order": False, "shape": (self.K,)}  # fmt: skip
                np.lib.format.write_array_header_1_0(f, header)
                self.files[name] = f
                self.names.append(name)
            self.files[name].write(np.ascontiguousarray(a).tobytes())

    def close(self) -> None:
        """Finish the archive at ``path`` and remove the scratch directory."""
        for f in self.files.values():
            f.close()
        archive = self.scratch / "results.npz"  # at path only once complete
        with zipfile.ZipFile(archive, "w", zipfile.ZIP_STORED, allowZip64=True) as z:
            for key, value in self.meta.items():
                tmp = self.scratch / f"{key}.npy"
                np.save(tmp, np.array(value))
                z.write(tmp, f"{key}.npy")
            for name in self.names:
                z.write(self.scratch / f"{name}.npy", f"{name}.npy")
        os.replace(archive, self.path)
        shutil.rmtree(self.scratch, ignore_errors=True)

    def abort(self) -> None:
        """Give up: close and remove everything written so far.

        Closing a file flushes its buffer, which fails again on a full disk;
        the scratch directory is removed whatever the files say, so a failed
        run never leaves the disk fuller than it found it.
        """
        try:
            for f in self.files.values():
                with contextlib.suppress(OSError):
                    f.close()
        finally:
            shutil.rmtree(self.scratch, ignore_errors=True)
