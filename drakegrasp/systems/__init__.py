"""Drake Systems: the grasp monitor that judges a running simulation.

The outer ring: it imports the plant layer, and nothing inside imports it.
"""

from drakegrasp._lazy import lazy_exports

_SOURCES = {
    "drakegrasp.systems.monitor": (
        "VERDICT_NAMES",
        "GraspMonitor",
        "GraspSample",
        "add_grasp_monitor",
    ),
    "drakegrasp.systems.holding": ("HOLDING_STATES", "HoldingThresholds"),
}

__getattr__, __dir__ = lazy_exports(__name__, globals(), _SOURCES)

__all__ = [
    "HOLDING_STATES",
    "VERDICT_NAMES",
    "GraspMonitor",
    "GraspSample",
    "HoldingThresholds",
    "add_grasp_monitor",
]
