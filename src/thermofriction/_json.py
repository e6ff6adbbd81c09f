"""Plain JSON types from the package's results."""

from __future__ import annotations

import math


def jsonable(obj):
    """Plain JSON types: arrays to lists, non-finite floats to "inf"/"-inf"/"nan" strings (JSON
    has none), numpy scalars to Python ones."""
    import numpy as np
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return jsonable(obj.tolist())
    if isinstance(obj, (float, np.floating)):
        x = float(obj)
        return x if math.isfinite(x) else ("inf" if x > 0 else "-inf" if x < 0 else "nan")
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.bool_):
        return bool(obj)
    return obj


__all__ = ["jsonable"]
