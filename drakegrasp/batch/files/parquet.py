"""The Parquet result writer (optional extra ``parquet``: pyarrow).

One row group per chunk, one column per array, ``kind``/``tol``/
``required_rank`` in the schema metadata; ``pandas.read_parquet`` loads it
directly.  As the ``.npz`` writer does, the chunks go to a scratch directory
beside the output and the file reaches its name only when it is complete: a
run that fails or is interrupted leaves no file there (a Parquet file of the
first chunks is a valid file, which a reader would take for all of them).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from drakegrasp.errors import BatchFileError

__all__ = ["ParquetWriter"]


class ParquetWriter:
    """Write result arrays to ``path`` as Parquet, one row group per chunk."""

    def __init__(self, path: Path, K: int, meta: dict):  # noqa: ARG002
        # K (the row count) keeps one constructor for both writers; Parquet
        # needs none, as row groups are appended chunk by chunk.
        try:
            import pyarrow as pa
            import pyarrow.parquet as pq
        except ImportError as exc:
            raise BatchFileError(
                "writing .parquet needs the optional package pyarrow "
                "(pip install drakegrasp[parquet]); write .npz instead"
            ) from exc
        self.pa, self.pq, self.path = pa, pq, path
        self.meta = {k: repr(v) if isinstance(v, float) else str(v)
                     for k, v in meta.items()}  # fmt: skip
        self.writer = None
        self.scratch = Path(tempfile.mkdtemp(prefix=".batch-", dir=path.parent))
        self.partial = self.scratch / "results.parquet"

    def write(self, arrays: dict[str, np.ndarray]) -> None:
        """Append one chunk's arrays as a row group."""
        table = self.pa.table(dict(arrays))
        if self.writer is None:
            schema = table.schema.with_metadata(self.meta)
            self.writer = self.pq.ParquetWriter(self.partial, schema)
        self.writer.write_table(table.replace_schema_metadata(self.meta))

    def close(self) -> None:
        """Finish the file (an empty table with the metadata if nothing came).

        It is moved to ``path`` once complete, and the scratch directory
        removed.
        """
        if self.writer is None:  # no grasps: an empty table with the metadata
            self.pq.write_table(self.pa.table({}).replace_schema_metadata(self.meta),
                                self.partial)  # fmt: skip
        else:
            self.writer.close()
        os.replace(self.partial, self.path)
        shutil.rmtree(self.scratch, ignore_errors=True)

    def abort(self) -> None:
        """Give up: close the writer, remove what it wrote; ``path`` is untouched."""
        try:
            if self.writer is not None:
                self.writer.close()
        except OSError:  # a full disk fails the footer too: removed all the same
            pass
        finally:
            shutil.rmtree(self.scratch, ignore_errors=True)
