"""Whether a record is in the unit its header declares, judged by a model (docs/your-data.md#units).

A value read under the wrong unit is still a valid number: µm values under a ``displacement[mm]`` header load
as a displacement 1000 times too large, and nothing in the file says otherwise. A model can: where one meets the
data (``validate``, ``report``, ``identify`` from an initial model) the span of the measured record is compared
with the span of what the model produces for the same experiment (the displacement it simulates under the
recorded voltage; the force or torque it predicts under the measured motion). The rule:

* a ratio of spans of at least :data:`TRUST_RATIO` (about 316, 2.5 decades) either way is reported, as a
  :class:`~thermofriction.errors.UnitWarning` and in the result's ``warnings``. A right model with a wrong
  parameter is off by a factor of 2-3 (a fit's start) or at worst ~10-30 (a preset for another actuator);
  2.5 decades leave an order of magnitude above that, so that a correct record does not raise it;
* the unit suggested is the one a power of 1000 away (a unit prefix: the mistakes users make) that the ratio
  is within half a decade of (:data:`SUGGEST_WITHIN`): a factor 300-3200 suggests the next prefix, 3e5-3e6 the
  one after. A ratio farther from any power of 1000 (say 1e4.5) is reported without a suggestion: no unit
  explains it, the model may be another plant's.

Messages start with ``suspicious unit:`` and name the file, the column (its header cell, or a MATLAB file's
variable) and the unit that would explain the ratio."""

from __future__ import annotations

import math

import numpy as np

from .data.experiments import _UNITS as _ACTUATOR_UNITS
from .data.force import _UNITS as _FORCE_UNITS
from .errors import ThermofrictionError, UnitWarning
from .plausible import SUSPICIOUS
from .results import Finding, collecting, emit

#: the ratio of spans (measured / predicted, or its inverse) at or above which a unit is suspected
TRUST_RATIO = 10 ** 2.5
#: [decades] how close the ratio must be to a power of 1000 for that power's unit prefix to be suggested
SUGGEST_WITHIN = 0.5
#: what every message starts with (the report puts these warnings first)
PREFIX = SUSPICIOUS

_PREFIXES = {-12: "p", -9: "n", -6: "µ", -3: "m", 0: "", 3: "k"}
_SPELLED = {"p": -12, "n": -9, "u": -6, "µ": -6, "μ": -6, "m": -3, "": 0, "k": 3}
_BASES = ("N*m", "N m", "Nm", "m", "N", "A")  # the longest first: "mN*m" is milli-"N*m", not "mN*" metres
#: every unit an experiment file can declare
_DECLARABLE = {u for table in (*_ACTUATOR_UNITS.values(), *_FORCE_UNITS.values()) for u in table}
#: the record a measurement compares, by the keys of Experiment.headers: a force experiment's measured column
#: (a friction sensor's, a command's or a motor current's), else the displacement
_MEASURED_KEYS = ("current", "command", "force", "displacement")


def split_unit(unit: str):
    """(the power of ten of its prefix, the base unit) of a metric unit such as ``mm``, ``um``, ``mN*m``, ``mA``;
    None for one that is not (``rad``, ``deg``)."""
    for base in _BASES:
        if unit.endswith(base) and unit[:-len(base)] in _SPELLED:
            return _SPELLED[unit[:-len(base)]], base
    return None


def span_ratio(measured, predicted) -> float | None:
    """The measured record's span over the predicted one's; None where either is zero or not finite (a model
    that does not move, a constant record: nothing to compare)."""
    a, b = (float(np.ptp(np.asarray(x, float))) if np.size(x) else 0.0 for x in (measured, predicted))
    if not (math.isfinite(a) and math.isfinite(b)) or a <= 0 or b <= 0:
        return None
    return a / b


def _column(exp):
    """(where the file holds the compared record, the unit its header declared), or a description without a
    header for an experiment made in memory (in SI units)."""
    headers = getattr(exp, "headers", None) or {}
    key = next((k for k in _MEASURED_KEYS if k in headers), None)
    if key is not None:
        return headers[key]
    if getattr(exp, "force", None) is not None:
        return ("the measured torque" if exp.rotary else "the measured force"), ("N*m" if exp.rotary else "N")
    return "the displacement", "m"


def suggestion(unit: str, ratio: float):
    """The unit that values read as ``unit`` are in when they are ``ratio`` times what they should be, where a
    power of 1000 explains the ratio; None otherwise."""
    split = split_unit(unit)
    if split is None:
        return None
    power, base = split
    true = power - math.log10(ratio)
    k = 3 * round(true / 3)
    if abs(true - k) > SUGGEST_WITHIN or k == power or k not in _PREFIXES:
        return None
    return _PREFIXES[k] + base


def _amount(value: float, base: str) -> str:
    """``value`` [base unit] with the prefix that puts it between 1 and 1000: 3e-5 m is "30 µm"."""
    k = min(max(3 * math.floor(math.log10(abs(value)) / 3), -12), 3) if value else 0
    return f"{value / 10.0 ** k:.3g} {_PREFIXES[k]}{base}"


def _factor(ratio: float) -> str:
    """A ratio in words: "~1,000×" or "~1/1,000 of"."""
    r = ratio if ratio >= 1 else 1 / ratio
    text = f"{float(f'{r:.2g}'):,.0f}"
    return f"~{text}× what" if ratio >= 1 else f"~1/{text} of what"


def _advice(label: str, unit: str, ratio: float) -> str:
    """The unit that would explain ``ratio``, and how to declare it."""
    better = suggestion(unit, ratio)
    if better is None:
        return (": no unit explains a factor this far from a power of 1000; check the header's unit, the sensor's "
                "scale, and whether the model is this plant's")
    ascii_unit = better.replace("µ", "u")
    if ascii_unit not in _DECLARABLE:
        how = f" (the file cannot declare {better}: convert the values to {split_unit(better)[1]})"
    elif label.startswith("column "):
        how = f" (header {label[7:].partition('[')[0].strip()}[{ascii_unit}])"
    elif label.startswith(("variable ", "struct ")):
        how = f" (declare {ascii_unit}: the variable's suffix, or the manifest's units table)"
    else:
        how = f" (an Experiment made in memory holds {split_unit(better)[1]})"
    other = "the torque_constant is off or " if unit.endswith("A") else ""
    return f": are they in {better}{how}? If they are not, {other}the model is far from this plant"


def _problem(exp, measured, predicted):
    """(the ratio of spans, its column, its unit, the spans) of one experiment whose measured record (SI)
    spans :data:`TRUST_RATIO` times more or less than ``predicted``, else None."""
    ratio = span_ratio(measured, predicted)
    if ratio is None or 1 / TRUST_RATIO < ratio < TRUST_RATIO:
        return None
    label, unit = _column(exp)
    base = ("N m" if exp.rotary else "N") if getattr(exp, "force", None) is not None else "m"
    spans = f"span {_amount(float(np.ptp(measured)), base)} against {_amount(float(np.ptp(predicted)), base)}"
    return ratio, label, unit, spans


def unit_warnings(pairs, what="the model", stacklevel=3) -> list:
    """The warnings over (experiment, measured, predicted) triples: one per column and suggested unit (a dataset
    whose every file has the same header says it once, naming the files), each issued as a :class:`UnitWarning`
    too (``stacklevel``: 3 names the caller of the function that calls this one)."""
    groups = {}
    for exp, measured, predicted in pairs:
        found = _problem(exp, measured, predicted)
        if found is not None:
            ratio, label, unit, spans = found
            groups.setdefault((label, unit, suggestion(unit, ratio), ratio > 1), []).append((exp.file, ratio, spans))
    out = []
    for (label, unit, _, _), runs in groups.items():
        files = ", ".join(f for f, _, _ in runs[:3]) + (f" and {len(runs) - 3} more" if len(runs) > 3 else "")
        ratio = float(np.median([r for _, r, _ in runs]))
        these = "this experiment" if len(runs) == 1 else "these experiments"
        detail = runs[0][2] if len(runs) == 1 else f"the median ratio; {runs[0][0]}: {runs[0][2]}"
        where = f"the values under {label}" if label.startswith(("column ", "variable ", "struct ")) else \
            f"{label}'s values (in {unit})"
        out.append(f"{PREFIX}{files}: {where} are {_factor(ratio)} {what} produces for {these} ({detail})"
                   f"{_advice(label, unit, ratio)}")
    emit([Finding(UnitWarning, m) for m in out], stacklevel=stacklevel)  # (kept as values where a caller collects)
    return out


def model_unit_warnings(model, experiments, measurement, rtol=1e-6) -> list:
    """:func:`unit_warnings` of ``model``'s predictions of ``experiments`` (an initial model before a fit): the
    simulations' own warnings are left to the fit, which runs them again; an experiment the model cannot run
    is left out (the fit says why)."""
    pairs = []
    for exp in experiments:
        with collecting():  # the simulations' findings: the fit's to say
            try:
                measured, predicted = measurement.spans(model, exp, rtol)
            except (ThermofrictionError, ArithmeticError):
                continue
        pairs.append((exp, measured, predicted))
    return unit_warnings(pairs, "the initial model", stacklevel=6)  # identify's caller, past its two decorators


__all__ = ["TRUST_RATIO", "SUGGEST_WITHIN", "PREFIX", "split_unit", "span_ratio", "suggestion",
           "unit_warnings", "model_unit_warnings"]
