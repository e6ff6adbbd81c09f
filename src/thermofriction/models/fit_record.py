"""A fitted model's fit record (docs/formats.md#the-fit-record): how ``identify`` scored the data it fitted -- the
measured quantity, the sensor offset policy and each run's offset, what drove each run (the position or the
velocity column) and how that column compared with the position's derivative, a ripple's angle (the recorded one
or a phase per run), the names fitted and held, and the noise the verdict compared with. It travels in the model file (``[provenance.fit_record]``) so that ``validate``,
``report`` and ``propagate`` score the model the way it was fitted unless told otherwise, and say which.

Here the table's form is checked; what its values mean (an offset policy, a motion) is checked where they are used
(measurements/, data/), which name the key."""

from __future__ import annotations

import math

from ..errors import InputError, shorten, unknown_keys

#: the record's keys: strings, but for the name lists, the noise (a number) and the experiments' table
FIT_RECORD_KEYS = ("measurement", "offset", "motion", "ripple_phase", "fitted", "held", "noise", "noise_unit",
                   "experiments")
#: one experiment's entry (by file name): what drove it, its offset, its velocity column against the position
EXPERIMENT_KEYS = ("motion", "offset", "velocity_lag", "velocity_scale")
_STRINGS = ("measurement", "offset", "motion", "ripple_phase", "noise_unit")
_NUMBERS = ("noise", "offset", "velocity_lag", "velocity_scale")


def _number(value, where: str, key: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(float(value)):
        raise InputError(f"{where}: '{key}' must be a finite number, got {shorten(value)}")
    return float(value)


def check_fit_record(record, where: str = "[provenance.fit_record]") -> dict:
    """The fit record's table, checked: known keys, each of its type; one InputError naming the key."""
    if not isinstance(record, dict):
        raise InputError(f"{where} must be a table, got {shorten(record)}")
    unknown = set(record) - set(FIT_RECORD_KEYS)
    if unknown:
        raise InputError(f"{where}: {unknown_keys(unknown, FIT_RECORD_KEYS)}")
    for key, value in record.items():
        if key in _STRINGS and not isinstance(value, str):
            raise InputError(f"{where}: '{key}' must be a string, got {shorten(value)}")
        if key in ("fitted", "held") and (not isinstance(value, list) or not all(isinstance(x, str) for x in value)):
            raise InputError(f"{where}: '{key}' must be a list of parameter names, got {shorten(value)}")
        if key == "noise":
            _number(value, where, key)
    experiments = record.get("experiments", {})
    if not isinstance(experiments, dict):
        raise InputError(f"{where}: 'experiments' must be a table of file names, got {shorten(experiments)}")
    for name, entry in experiments.items():
        here = f"{where}.experiments.{name!r}"
        if not isinstance(entry, dict):
            raise InputError(f"{here} must be a table, got {shorten(entry)}")
        unknown = set(entry) - set(EXPERIMENT_KEYS)
        if unknown:
            raise InputError(f"{here}: {unknown_keys(unknown, EXPERIMENT_KEYS)}")
        for key, value in entry.items():
            if key == "motion":
                if not isinstance(value, str):
                    raise InputError(f"{here}: 'motion' must be a string, got {shorten(value)}")
            else:
                _number(value, here, key)
    return record


def fit_record_lines(model) -> list:
    """How ``model`` was fitted, in words, one line each (the FMU's documentation; none for a model ``identify`` did
    not make)."""
    prov = getattr(model, "provenance", None) or {}
    record = prov.get("fit_record")
    if not record:
        return []
    lines = [f"identified by thermofriction {prov.get('thermofriction', '')}, method {prov.get('method', '?')}, "
             f"from {prov.get('data', '?')} ({', '.join(prov.get('fit_files') or [])})",
             f"measured quantity: {record.get('measurement', '?')}; sensor offset policy: {record.get('offset', '?')}"
             + (f"; motion: {record['motion']}" if record.get("motion") else ""),
             f"fitted: {', '.join(record.get('fitted') or []) or 'none'}; "
             f"held: {', '.join(record.get('held') or []) or 'none'}"]
    if record.get("noise") is not None:
        lines.append(f"measurement noise estimated from the data: {record['noise']:.4g} {record.get('noise_unit', '')}")
    for name, entry in (record.get("experiments") or {}).items():
        parts = [f"{k.replace('_', ' ')} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in entry.items()]
        lines.append(f"{name}: {', '.join(parts)}")
    return lines


def fit_record_of(model) -> dict | None:
    """The fit record of ``model`` (a dict, see the module), or None for a model ``identify`` did not make."""
    return (getattr(model, "provenance", None) or {}).get("fit_record")


__all__ = ["FIT_RECORD_KEYS", "EXPERIMENT_KEYS", "check_fit_record", "fit_record_of", "fit_record_lines"]
