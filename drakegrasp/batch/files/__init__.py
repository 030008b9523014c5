"""Files: grasps in, verdicts out.

Grasps read from ``.npz``/``.npy`` (:mod:`~drakegrasp.batch.files.reader`),
results written as ``.npz`` or Parquet (one writer per format,
:mod:`~drakegrasp.batch.files.writer`), and the one driver that runs a file
end to end (:mod:`~drakegrasp.batch.files.driver`).
"""

from drakegrasp._lazy import lazy_exports

_SUBMODULES = (
    "driver",
    "npz",
    "parquet",
    "reader",
    "writer",
)

__getattr__, __dir__ = lazy_exports(__name__, globals(), {}, submodules=_SUBMODULES)
