"""The fit record written with a fitted model (models/fit_record.py, docs/formats.md#the-fit-record): what
``identify`` scored, so that ``validate``, ``report`` and ``propagate`` score the model the same way."""

from __future__ import annotations

import math

from ..data.experiments import run_label
from ..measurements.ripple import has_ripple


def motion_policy(experiments) -> str:
    """The motion option that drives held-out runs as the fit's were: "position" where every fit run with a
    velocity column was driven by its position, "velocity" where one was driven by a column that does not agree
    with the position's derivative (asked for), else "auto" (a column drives where it agrees)."""
    with_column = [e for e in experiments if getattr(e, "velocity", None) is not None]
    if not with_column:
        return "auto"
    if all(e.motion_source == "position" for e in with_column):
        return "position"
    if any(e.motion_source == "velocity" and e.motion_check is not None and not e.motion_check.agrees
           for e in with_column):
        return "velocity"
    return "auto"


def _experiment_entry(exp, offsets: dict) -> dict:
    entry = {}
    if getattr(exp, "force", None) is not None:  # force and command data: what drove the run
        entry["motion"] = exp.motion_source
        check = exp.motion_check
        if check is not None and math.isfinite(check.lag) and math.isfinite(check.scale):
            entry.update(velocity_lag=float(check.lag), velocity_scale=float(check.scale))
    if run_label(exp) in offsets:
        entry["offset"] = offsets[run_label(exp)]
    return entry


def fit_record(fit, experiments, offset_policy: str, ripple_phase: str | None = None) -> dict:
    """The record of ``fit`` made on ``experiments`` (the fit runs) with the measurement's ``offset_policy``, and
    its ``ripple_phase`` ("recorded" or "per-run", as decided) where the fitted model has a ripple."""
    offsets = {r["file"]: float(r["value"]) for r in (fit.sensor_offset or {}).get("per_experiment", [])
               if r.get("value") is not None and math.isfinite(r["value"])}
    record = {"measurement": fit.measurement, "offset": offset_policy,
              "fitted": [p.name for p in fit.parameters.varying],
              "held": [p.name for p in fit.parameters.values() if not p.vary]}
    if any(getattr(e, "force", None) is not None for e in experiments):
        record["motion"] = motion_policy(experiments)
        if ripple_phase in ("recorded", "per-run") and has_ripple(fit.model):
            record["ripple_phase"] = ripple_phase
    noise = (fit.fit_quality or {}).get("noise")
    if noise is not None and math.isfinite(noise) and noise > 0:
        record.update(noise=float(noise), noise_unit=fit.unit)
    entries = {run_label(e): _experiment_entry(e, offsets) for e in experiments}
    record["experiments"] = {k: v for k, v in entries.items() if v}
    return record


__all__ = ["fit_record", "motion_policy"]
