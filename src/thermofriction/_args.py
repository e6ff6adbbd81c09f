"""Argument checks for the public Python API: one rule, one wording (docs/hardening.md#python-api-argument-types).

The rule:

- **An argument takes the types its documentation names, nothing else.** Anything else is an
  :class:`~thermofriction.errors.InputError` naming the argument, what it takes and what it got
  (``duration must be a number [s], got str '2'``), raised before any work: no ``TypeError`` or
  ``AttributeError`` from deep inside, and no half-done run.
- **Nothing is coerced.** A string is never read as a number (``duration='2'``), a boolean is never a
  number (``sample_rate=True`` is not 1 Hz), a number is never a flag, a string is never a list of its
  letters: one name where names are expected is that one name (``parameters='sigma0'`` is
  ``['sigma0']``).
- **Paths and names stand for objects only where the documentation says so**: a model file or preset
  name where a function documents "a model, a model file or a preset name" (``load_model``,
  ``identify(init=...)``, ``sweep``, ``identify_fleet``, ``export_fmu``), a solver's name (``simulate(solver='rodas4')``,
  as ``--solver rodas4``), dataset folders for ``identify_fleet``. Elsewhere a path given for a model or a
  dataset is refused with the call that loads it (``tf.identify('/path/to/data')``: ``data must be a
  Dataset ..., got str '/path/to/data': load the folder with tf.load_dataset('/path/to/data')``).
"""

from __future__ import annotations

import math
import numbers
import os

import numpy as np

from ._io import Target
from .errors import InputError, shorten


def got(value) -> str:
    """``str '2'``, ``int 42``, ``NoneType None``: the type and the value, shortened."""
    return f"{type(value).__name__} {shorten(value)}"


def refuse(name: str, what: str, value, hint: str = ""):
    raise InputError(f"{name} must be {what}, got {got(value)}{': ' + hint if hint else ''}")


def is_number(value) -> bool:
    """A real number (int, float, NumPy's), not a boolean and not a string."""
    return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))


#: whole numbers end at 64 bits: the C core's, NumPy's and a model file's integers (a seed of 10**400 would
#: run, then fail to be written to the fitted model's provenance)
WHOLE_LIMIT = 2 ** 63 - 1


def number(value, name: str, unit: str = "", *, none: bool = False, finite: bool = True, positive: bool = False,
           minimum=None):
    """``value`` as a float when it is a real number (None passes with ``none``); else InputError. A number
    too large for a float (an int of 10**400) is refused, and so are NaN and infinities unless ``finite`` is
    False; ``positive``: > 0; ``minimum``: >= it."""
    if value is None and none:
        return None
    unit = f" [{unit}]" if unit else ""
    if not is_number(value):
        refuse(name, f"a number{unit}" + (" or None" if none else ""), value)
    what = (f"a{' positive' if positive else ''}{' finite' if finite else ''} number{unit}"
            + (f" of {minimum:g} or more" if minimum is not None else ""))
    try:
        x = float(value)
    except OverflowError:  # an int beyond 1.8e308
        refuse(name, what, value, "too large for a floating-point number")
    if (finite and not math.isfinite(x)) or (positive and not x > 0) or (minimum is not None and not x >= minimum):
        refuse(name, what, value)
    return x


def whole(value, name: str, *, none: bool = False, low: int = -WHOLE_LIMIT, high: int = WHOLE_LIMIT):
    """``value`` as an int when it is a whole number (an Integral, NumPy's too, not a boolean) from ``low``
    to ``high`` (by default, any 64-bit integer); else InputError."""
    if value is None and none:
        return None
    what = ("a positive whole number" if (low, high) == (1, WHOLE_LIMIT)
            else f"a whole number, {low} or more" if high == WHOLE_LIMIT and low > -WHOLE_LIMIT
            else f"a whole number from {low} to {high}" if low > -WHOLE_LIMIT or high < WHOLE_LIMIT
            else "a whole number") + (" or None" if none else "")
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        refuse(name, what, value)
    if not low <= value <= high:
        refuse(name, what, value, "beyond a 64-bit integer" if abs(value) > WHOLE_LIMIT else "")
    return int(value)


def number_list(value, name: str, unit: str = "", *, empty: bool = False, none: bool = False,
                positive: bool = False):
    """A number or a list (tuple, 1-D array) of numbers, each as :func:`number` takes it (finite, not a
    string, not a boolean; ``positive``: > 0), as a 1-D float array; an empty list only with ``empty``; None
    with ``none``."""
    if value is None and none:
        return None
    if is_number(value):
        return np.array([number(value, name, unit, positive=positive)])
    what = (f"a number or a {'' if empty else 'non-empty '}list of {'positive ' if positive else ''}finite numbers"
            + (f" [{unit}]" if unit else "") + (" or None" if none else ""))
    if isinstance(value, np.ndarray) and value.ndim == 1 and value.dtype.kind in "iuf":  # at once: t_eval may be long
        x = value.astype(float)
        if (x.size or empty) and np.isfinite(x).all() and (not positive or (x > 0).all()):
            return x
        refuse(name, what, value)
    items = list(value) if isinstance(value, (list, tuple)) or (isinstance(value, np.ndarray)
                                                                 and value.ndim == 1) else None
    if items is None or (not items and not empty) or not all(is_number(v) for v in items):
        refuse(name, what, value)
    return np.array([number(v, name, unit, positive=positive) for v in items], dtype=float)


def flag(value, name: str) -> bool:
    """True or False (NumPy's booleans too); a number or a string is not a flag."""
    if not isinstance(value, (bool, np.bool_)):
        refuse(name, "True or False", value)
    return bool(value)


def text(value, name: str, *, none: bool = False):
    if value is None and none:
        return None
    if not isinstance(value, str):
        refuse(name, "a string" + (" or None" if none else ""), value)
    return value


def function(value, name: str, *, none: bool = True):
    if value is None and none:
        return None
    if not callable(value):
        refuse(name, "a function" + (" or None" if none else ""), value)
    return value


def path(value, name: str, *, none: bool = False):
    """A file or folder name: a non-empty str or os.PathLike (a bytes path is decoded)."""
    if value is None and none:
        return None
    if isinstance(value, Target):  # an output the command line has checked already
        return value
    if isinstance(value, (str, os.PathLike)):
        p = os.fspath(value)
        if isinstance(p, bytes):
            p = os.fsdecode(p)
        if not p.strip():
            refuse(name, "a file name", value)
        return value
    refuse(name, "a file name (str or pathlib.Path)" + (" or None" if none else ""), value)


def names(value, name: str, *, none: bool = True, allow=()):
    """A list of names: one string is one name (never its letters); a list or tuple of strings; None with
    ``none``; objects of the types ``allow`` pass as they are (a Parameters object)."""
    if value is None and none:
        return None
    if allow and isinstance(value, allow):
        return value
    if isinstance(value, str):
        return [value]
    if isinstance(value, (list, tuple, set, frozenset)) and all(isinstance(v, str) for v in value):
        return list(value)
    refuse(name, "a name or a list of names" + (" or None" if none else ""), value)


def instance(value, cls, name: str, what: str, *, none: bool = False, hint: str = ""):
    if value is None and none:
        return None
    if not isinstance(value, cls):
        refuse(name, what + (" or None" if none else ""), value, hint)
    return value


def model(value, cls, name: str = "model", *, loader=None, none: bool = False):
    """A model (an instance of ``cls``, :class:`~thermofriction.Model`); with a ``loader`` (``load_model``), a
    model file or preset name is loaded. Otherwise a path is refused naming ``tf.load_model``."""
    if value is None and none:
        return None
    if isinstance(value, cls):
        return value
    if loader is not None and isinstance(value, (str, os.PathLike)):
        return loader(value)
    hint = (f"load it with tf.load_model({shorten(os.fspath(value))})" if isinstance(value, (str, os.PathLike))
            else "")
    refuse(name, "a Model" + (", a model file or a preset name" if loader else "") + (" or None" if none else ""),
           value, hint)


def dataset(value, cls, name: str = "data", *, experiments: bool = False, none: bool = False):
    """A dataset (an instance of ``cls``, :class:`~thermofriction.Dataset`; with ``experiments``, also a
    non-empty list of experiments); a path is refused naming ``tf.load_dataset``."""
    if value is None and none:
        return None
    if isinstance(value, cls):
        return value
    if experiments and isinstance(value, (list, tuple)) and value and all(hasattr(e, "time") for e in value):
        return value
    held = getattr(value, "experiments", None)  # a dataset-like object (its experiments), as the tests build them
    if experiments and isinstance(held, (list, tuple)) and all(hasattr(e, "time") for e in held):
        return value
    hint = (f"load the folder with tf.load_dataset({shorten(os.fspath(value))})"
            if isinstance(value, (str, os.PathLike)) else "")
    refuse(name, "a Dataset" + (" or a list of experiments" if experiments else "") + (" or None" if none else ""),
           value, hint)


__all__ = ["got", "refuse", "is_number", "number", "whole", "number_list", "WHOLE_LIMIT", "flag", "text", "function", "path", "names",
           "instance", "model", "dataset"]
