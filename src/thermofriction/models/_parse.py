"""Reading numbers and sections from a parsed model file, with errors that name the key."""

from __future__ import annotations

import math
import numbers

import numpy as np

from ..errors import InputError, shorten, unknown_keys


def num(value, where, key):
    # numbers.Real: NumPy's integer and float scalars too (an array's elements); not bool, not a string
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise InputError(f"{where}: '{key}' must be a number, got {shorten(value)}")
    try:
        value = float(value)
    except OverflowError:  # an integer beyond the float range, e.g. 10**400
        raise InputError(f"{where}: '{key}' must be finite, got an integer too large for a number") from None
    if not math.isfinite(value):
        raise InputError(f"{where}: '{key}' must be finite, got {shorten(value)}")
    return value


def num_array(value, where, key, min_len=1):
    if not isinstance(value, (list, tuple, np.ndarray)) or len(value) < min_len:
        raise InputError(f"{where}: '{key}' must be an array of at least {min_len} number(s)")
    return np.array([num(v, where, f"{key}[{i}]") for i, v in enumerate(value)], dtype=float)




def by_symbol(cls, d: dict, where: str, required, what="", extra=()) -> dict:
    """A section keyed by the model file's symbols (``cls._SYMBOLS``: field -> symbol) as keyword
    arguments of ``cls``; unknown and missing keys are named."""
    names = {sym: name for name, sym in cls._SYMBOLS.items()}
    unknown = set(d) - set(names)
    if unknown:
        raise InputError(f"{where}: {unknown_keys(unknown, [*extra, *names], what)}")
    for req in required:
        if req not in d:
            raise InputError(f"{where}: missing '{req}'")
    return {names[k]: v for k, v in d.items()}

