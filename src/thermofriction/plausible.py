"""Physical plausibility of what users give: temperatures that look like kelvin, displacements whose
unit looks wrong, lengths with units on the command line. One rule for every entry point (data files,
dataset manifests, ``simulate``), so that the same value is accepted or refused everywhere."""

from __future__ import annotations

import math
import re

import numpy as np

from .errors import InputError

#: [degC] what a temperature sensor on an actuator can plausibly read
TEMPERATURE_RANGE = (-100.0, 300.0)
#: [m] a displacement record spanning less than this is below any displacement sensor's resolution
#: (capacitive sensors resolve ~1e-10 m): its values are most likely in another unit than the header's
MIN_DISPLACEMENT_SPAN = 1e-11

#: what every warning of a suspected unit starts with (here and unit_scale.py; the report puts them first)
SUSPICIOUS = "suspicious unit: "

#: [m] an actuator's displacement record spanning more than this is warned about at loading (UnitWarning):
#: stick-slip positioners travel millimetres, at most some tenths of a metre, so a larger span is most likely µm or mm values under an [m]
#: header (30 µm read as 30 m). Not refused: the model, where one meets the data, judges more finely
#: (unit_scale.py)
MAX_DISPLACEMENT_SPAN = 1.0

#: [V] the largest plausible actuator drive voltage in recorded data: piezo stick-slip actuators are driven
#: at up to ~150 V, high-voltage stacks at up to ~1 kV; beyond 10 kV a value is in another unit or corrupt
VOLTAGE_LIMIT = 1e4

_LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "μm": 1e-6, "nm": 1e-9, "pm": 1e-12}


def temperature_problem(T) -> str | None:
    """Why ``T`` [degC] (a number or array) is not a plausible temperature, or None."""
    T = np.atleast_1d(np.asarray(T, float))
    lo, hi = TEMPERATURE_RANGE
    bad = ~np.isfinite(T) | (T < lo) | (T > hi)
    if not bad.any():
        return None
    v = float(T[np.argmax(bad)])
    return f"{v:g} C is not a plausible temperature (expected {lo:g} to {hi:g} C{kelvin_hint(v)})"


def kelvin_hint(v: float) -> str:
    """A temperature that reads like kelvin says so."""
    try:
        v = float(v)
    except (TypeError, ValueError, OverflowError):
        return ""
    return f"; in kelvin? {v:g} K is {v - 273.15:.4g} C" if 200.0 <= v <= 600.0 else ""


def check_temperature(T, where: str):
    problem = temperature_problem(T)
    if problem:
        raise InputError(f"{where}: {problem}")


def displacement_problem(x, unit: str) -> str | None:
    """Why a displacement record (in metres, read under a ``[unit]`` header) does not look like one,
    or None: a span below any sensor's resolution (values in metres under a [um] header)."""
    x = np.asarray(x, float)
    span = float(np.ptp(x)) if x.size else 0.0
    if span == 0.0:
        return None  # a constant record is its own case (nothing to fit), said where it matters
    if span < MIN_DISPLACEMENT_SPAN:
        return (f"the displacement spans only {span:.3g} m, below any sensor's resolution: are the values in "
                f"metres under a [{unit}] header? (give the unit the numbers are in)")
    return None


def displacement_doubt(x, unit: str) -> str | None:
    """Why an actuator's displacement record (in metres, read under a ``[unit]`` header) looks like another
    unit, though it may be one, or None: a span above :data:`MAX_DISPLACEMENT_SPAN`."""
    x = np.asarray(x, float)
    span = float(np.ptp(x)) if x.size else 0.0
    if not span > MAX_DISPLACEMENT_SPAN:
        return None
    return (f"the displacement spans {span:.3g} m, more than an actuator travels (millimetres, at most some tenths "
            f"of a metre): are the values in um or mm under a [{unit}] header? (give the unit the numbers are in)")


def voltage_problem(v) -> str | None:
    """Why a voltage record [V] (or one value) is not an actuator's drive voltage, or None: where its
    largest magnitude exceeds :data:`VOLTAGE_LIMIT`, that value and its 1-based sample number."""
    v = np.atleast_1d(np.asarray(v, float))
    if not v.size:
        return None
    i = int(np.argmax(np.abs(v)))
    if abs(v[i]) <= VOLTAGE_LIMIT:
        return None
    where = f"sample {i + 1}: " if v.size > 1 else ""
    return (f"{where}{v[i]:g} V is not a plausible actuator voltage (expected within +-{VOLTAGE_LIMIT:g} V: "
            f"values in another unit, e.g. mV (give voltage[mV]), or a corrupt record?)")


def input_voltage_problem(waveform) -> str | None:
    """:func:`voltage_problem` of a waveform's peak (|offset| + |amplitude|, or a sampled input's values)."""
    values = getattr(waveform, "value", None)
    if values is None:
        values = abs(float(getattr(waveform, "offset", 0.0))) + abs(float(getattr(waveform, "amplitude", 0.0)))
    problem = voltage_problem(values)
    return problem and problem.replace(" V is not", " V (its peak) is not") if values is not None else None


def parse_length(text: str, what: str) -> float:
    """A length from the command line: a number in metres, or a number with a unit (``20nm``, ``5 um``)."""
    m = re.fullmatch(r"\s*([-+0-9.eE]+)\s*([a-zµμ]*)\s*", str(text))
    unit = m.group(2) if m else None
    if m is None or (unit and unit not in _LENGTH_UNITS):
        raise InputError(f"{what}: '{text}' is not a length (a number in metres, or with a unit: "
                         f"{', '.join(k for k in _LENGTH_UNITS if k not in ('µm', 'μm'))})")
    try:
        value = float(m.group(1)) * _LENGTH_UNITS[unit or "m"]
    except ValueError:
        raise InputError(f"{what}: '{text}' is not a length") from None
    if not math.isfinite(value) or value < 0:
        raise InputError(f"{what}: must be a non-negative length, got '{text}'")
    return value


__all__ = ["kelvin_hint", "TEMPERATURE_RANGE", "VOLTAGE_LIMIT", "voltage_problem", "input_voltage_problem", "MIN_DISPLACEMENT_SPAN", "temperature_problem", "check_temperature",
           "displacement_problem", "displacement_doubt", "MAX_DISPLACEMENT_SPAN", "SUSPICIOUS", "parse_length"]
