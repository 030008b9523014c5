"""JSON-ready values: the one conversion every ``to_dict`` uses."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["jsonable"]


def jsonable(value: Any) -> Any:
    """``value`` as plain JSON types.

    Arrays become nested lists, numpy scalars Python scalars, non-finite floats
    ``None`` (JSON has no NaN or infinity), and objects with a ``to_dict``
    method their dictionary; lists, tuples and dictionaries are converted
    element by element.  Anything else is returned as it is.
    """
    if isinstance(value, np.ndarray):
        return [jsonable(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, dict):
        return {k: jsonable(v) for k, v in value.items()}
    if isinstance(value, (float, np.floating)):
        x = float(value)
        return x if math.isfinite(x) else None
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    if hasattr(value, "to_dict"):
        return value.to_dict()
    return value
