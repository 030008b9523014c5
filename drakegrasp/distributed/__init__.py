"""Many machines: the batch engine and the plant layer on a Dask cluster.

The outer ring: :mod:`~drakegrasp.distributed.batch_side` runs the batch
engine in Parquet shards, :mod:`~drakegrasp.distributed.plant_side` analyses
many configurations of a scene.  Nothing inside imports this folder: the batch
engine never knows the scheduler.
"""

from drakegrasp._lazy import lazy_exports

_SOURCES = {
    "drakegrasp.distributed.batch_side": (
        "evaluate_on_cluster",
        "stream_file_on_cluster",
    ),
    "drakegrasp.distributed.dataset": ("read_dataset",),
    "drakegrasp.distributed.plant_side": ("analyze_poses", "cached_scenes"),
}

_SUBMODULES = (
    "batch_side",
    "client",
    "dataset",
    "plant_side",
)

__getattr__, __dir__ = lazy_exports(
    __name__, globals(), _SOURCES, submodules=_SUBMODULES
)

__all__ = [
    "analyze_poses",
    "cached_scenes",
    "evaluate_on_cluster",
    "read_dataset",
    "stream_file_on_cluster",
]
