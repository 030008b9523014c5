"""Drake Systems: the grasp monitor that judges a running simulation.

The outer ring: it imports the plant layer, and nothing inside imports it.
"""

from drakegrasp._lazy import lazy_exports

_SOURCES = {
    "drakegrasp.systems.grasp_monitor": ("GraspMonitor",),
    "drakegrasp.systems.sample": ("VERDICT_NAMES", "GraspSample"),
    "drakegrasp.systems.monitor": ("add_grasp_monitor",),
    "drakegrasp.systems.monitor_options": ("MonitorSettings",),
    "drakegrasp.systems.holding": ("HOLDING_STATES", "HoldingThresholds"),
}

_SUBMODULES = (
    "finger_loads",
    "grasp_monitor",
    "holding",
    "monitor",
    "monitor_options",
    "sample",
    "sensing",
)

__getattr__, __dir__ = lazy_exports(
    __name__, globals(), _SOURCES, submodules=_SUBMODULES
)

__all__ = [
    "HOLDING_STATES",
    "VERDICT_NAMES",
    "GraspMonitor",
    "GraspSample",
    "HoldingThresholds",
    "MonitorSettings",
    "add_grasp_monitor",
]
