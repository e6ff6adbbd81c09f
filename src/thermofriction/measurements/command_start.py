"""A drive's command's initial model and result (``Command.initial_model``, ``Command.complete``): the delay, the
inertia and a first offset read off the data before the fit (:func:`command_initial`), and the inertia, the offsets
and the delay estimated with their standard errors at the optimum (:func:`command_finish`). The force measurement's
class is passed in (``force``), and the command's measurement of the friction's means (``friction``): this module
sits below measurements/command.py, which calls it."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._lazy import lazy
from ..errors import ComputationError, InputError
from ..fitting.problem import Problem
from .base import FD_RTOL
from .command_terms import (MIN_DELAY_SAMPLES, applied_delay, coulomb_columns, delay_scan, delay_search, held,
                            held_acceleration, hold_means, linear_fit, node_experiment, nuisance_columns, shifted,
                            sliding)
from .delay import AUTO, check_not_at_end, search_range
from .force_finish import completed, estimate_linear
from .force_start import force_initial, moving_speed

stats = lazy("scipy.stats")


def command_initial(init, method, data, experiments, delay=AUTO, *, force, **options):
    """The initial model for a drive's command (``Command.initial_model``; ``force`` the force measurement's class): the delay, the inertia J0 and a first offset by linear least
    squares ``u(t - delay) = J0 a + b + fc sgn(v) + sigma2 v`` on a scan of delays (measurements/command.py:
    delay_scan; ``delay`` a DelaySpec: auto or a range scanned, a value or none held); force data's initial model
    (:func:`force_initial`) with friction values read off ``u(t - delay) - J0 a``; then the delay again with that
    model's friction as one more column (its Stribeck curve); the acceleration and the friction as their means over
    each held sample (measurements/command.py; at the samples where the initial model's [plant] command_hold is
    "none", there only), the first scan's over held samples either way (a start). The model's [plant] gets J0 and
    the delay (auto: applied only beyond MIN_DELAY_SAMPLES of a sample)."""
    if not experiments:
        raise InputError("the dataset has no experiment with role 'fit'")
    moving_speed(experiments)
    grid = (None if delay.kind in ("none", "value") else
            search_range(delay, [e.time for e in experiments], [e.drive_velocity for e in experiments],
                         [held_acceleration(e) for e in experiments]))

    def scan(columns):
        if grid is None:
            return delay.lo, linear_fit(experiments, columns, delay.lo, [sliding(e) for e in experiments])[0]
        d, _, coef, i = delay_scan(experiments, columns, grid[:2])
        check_not_at_end(delay, i, grid[1], grid[0], grid[2])
        return d, coef

    d0, coef = scan([coulomb_columns(e) for e in experiments])
    adjusted = [dataclasses.replace(e, force=shifted(e.time, e.force, d0) - coef[0] * held_acceleration(e))
                for e in experiments]
    init = force_initial(init, method, data, adjusted, force=force, **options)
    hold = held(init)
    d, coef = scan([np.column_stack([coulomb_columns(e, hold), _friction_column(force(), init, e, hold)])
                    for e in experiments])
    if delay.kind == "auto":
        d = applied_delay(d, grid[0])
    plant = dataclasses.replace(init.plant, inertia=max(float(coef[0]), 0.0), delay=d)
    return dataclasses.replace(init, plant=plant)


def _friction_column(measurement, model, exp, hold: bool):
    """The initial model's friction along ``exp``: its mean over each held sample, or at the samples."""
    if not hold:
        return measurement.friction_of(model, exp)
    return hold_means(measurement.friction_of(model, node_experiment(exp)), len(exp.time))


def command_finish(res, experiments, init, measurement, *, friction):
    """The fit completed for a drive's command (``Command.complete``; ``friction("none")`` a measurement whose
    residuals are the friction's means over the held samples minus the record, nothing profiled out:
    ``Command.unprofiled``): the inertia J and the offsets (as the policy says) estimated
    together at the optimum with their standard errors (:func:`estimate_linear` on the acceleration's and the
    offsets' columns, at the delay), the delay at the fitted friction with its standard error (the curvature of
    the cost over the delay, the friction held: measurements/command.py DelaySearch) where it is searched, all
    written into the fitted model's [plant] and ``details["plant"]`` (with how the command was read, its
    ``command_hold``)."""
    traces = [measurement.make_trace(e, res.model) for e in experiments]
    unit, policy, spec = traces[0].unit, measurement.offset, measurement.delay
    names = [p.name for p in res.parameters.varying] if res.n_points else []
    if policy == "none":  # the model's own offset, held
        traces = [dataclasses.replace(tr, measured=tr.measured - tr.held_offset) for tr in traces]
    search = delay_search(traces, "shared", spec, res.model.plant.delay)
    m = np.concatenate([tr.measured for tr in traces])
    plain = [dataclasses.replace(tr, measurement=friction("none"), held_offset=0.0) for tr in traces]
    r, _ = Problem(res.model, [], plain, rtol=FD_RTOL, parallel=len(plain) > 1).evaluate(np.array([]), jac=False)
    estimate, _, se = search.best(r + m) if r is not None else (math.nan, None, math.nan)
    searched = search.searched and math.isfinite(estimate)
    delay = estimate if searched or spec.kind == "value" else 0.0
    if searched:  # the fitted friction's delay too: not at the search's end
        check_not_at_end(spec, search.at, search.ks, search.dt, _range_reason(spec, traces))
    X = search.shift(nuisance_columns(traces, policy), delay)
    if searched:  # the delay's column, so that its error has the friction's in it: d(model at t + delay)/d delay
        X = np.column_stack([X, search.slope(r + m, delay)])
    ests, _ = estimate_linear(res.model, names, traces, X, res.statistics.get("variance_inflation", 1.0),
                              at=lambda r, J: (search.shift(r + m, delay) - m, None if J is None else search.shift(J, delay)),
                              force=friction)
    if searched:
        se = ests.pop()["stderr"]
    inertia, offsets = ests[0], ests[1:]
    offset = _offset_estimate(policy, offsets, traces, init)
    offset.update(unit=unit, fitted=policy != "none", policy=policy)
    plant = {"inertia": dict(inertia, unit="kg m^2" if unit == "N m" else "kg"),
             "delay": _delay_record(spec, delay, estimate, se, searched, search, traces),
             "command_hold": res.model.plant.command_hold}
    _check_inertia(inertia, plant["inertia"]["unit"])
    model = dataclasses.replace(res.model, plant=dataclasses.replace(
        res.model.plant, inertia=inertia["value"], sensor_offset=offset["value"], delay=delay))
    out = completed(res, model, offset, unit)
    out.details["plant"] = plant
    return out


def _offset_estimate(policy, offsets, traces, init) -> dict:
    if policy == "shared":
        return offsets[0]
    if policy == "per-experiment":
        return {"value": float(np.mean([o["value"] for o in offsets])), "stderr": None, "ci95": None,
                "per_experiment": [dict(o, file=tr.name) for o, tr in zip(offsets, traces)]}
    held = init.plant.sensor_offset
    return {"value": held, "stderr": 0.0, "ci95": (held, held)}


def _range_reason(spec, traces) -> str:
    return search_range(spec, [tr.time for tr in traces], [tr.velocity for tr in traces],
                        [tr.acceleration for tr in traces])[2]


def _delay_record(spec, delay, estimate, se, searched, search, traces) -> dict:
    """``details["plant"]["delay"]``: the delay applied, its estimate and interval where it was searched, how it
    was taken (``spec``: auto, none, a value, a range), the range searched and why, and a note saying so."""
    tq = float(stats.norm.ppf(0.975))
    out = {"value": delay, "estimate": estimate if searched else delay, "stderr": se if searched else 0.0,
           "ci95": (estimate - tq * se, estimate + tq * se) if searched else (delay, delay),
           "applied": bool(delay), "sampling_interval": search.dt, "spec": str(spec), "searched": None}
    if searched:
        lo, hi = search.ks[0] * search.dt, search.ks[-1] * search.dt
        out["searched"] = {"min": lo, "max": hi, "why": _range_reason(spec, traces)}
        how = ("the means of the model's friction and acceleration over each held sample" if traces[0].nodes is not None
               else "the model's friction and acceleration at the samples")
        out["note"] = (f"fitted with the friction ({how}, taken at t + delay); searched {lo * 1e3:.4g} to {hi * 1e3:.4g} ms ({out['searched']['why']})")
    elif spec.kind == "value":
        out["note"] = "held at the value given (--delay VALUE), not fitted"
    elif spec.kind == "none":
        out["note"] = "none fitted (--delay none)"
    else:
        out["note"] = (f"not applied: the estimate before the fit was within {MIN_DELAY_SAMPLES:g} of a sampling "
                       f"interval ({search.dt * 1e3:.3g} ms)")
    return out


def _check_inertia(inertia: dict, unit: str) -> None:
    """A moving part has a positive inertia: a fit that lands on none or a negative one failed (its model could
    not predict a command; validate refuses it), ComputationError saying so."""
    if not inertia["value"] > 0:
        lo, hi = inertia["ci95"]
        raise ComputationError(
            f"the fitted inertia is not positive ({inertia['value']:.4g} {unit}, 95 %: [{lo:.4g}, {hi:.4g}]): the "
            f"motion's acceleration does not explain the command. Check that the position resolves the acceleration "
            f"(a velocity column helps), the command's sign and torque constant, and that the command and the motion "
            f"are recorded on the same clock (docs/force-data.md#drives-without-a-torque-sensor)")


__all__ = ["command_initial", "command_finish"]
