"""What identification does per measurement, before and after the fit (the procedures' front door): the initial
model each measurement starts from (a preset, a file, or values read off the data), and what its result gains
afterwards (force data: the sensor offset estimated at the optimum, the units of a rotary joint).
:data:`SETUP` maps a measurement's name to its two steps."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._lazy import lazy
from ..data.force import units_of
from ..data.motion import with_v_smooth
from ..errors import ComputationError, InputError
from ..models import LuGre, Model, PrescribedMotion, StickSlipPlant, load_model
from ..measurements.command import (MIN_DELAY_SAMPLES, acceleration, applied_delay, coulomb_columns, delay_scan,
                                    delay_search, linear_fit, nuisance_columns, shifted, sliding)
from ..measurements.delay import AUTO, check_not_at_end, search_range
from ..measurements.force import FD_RTOL, Force
from ..models.plants import rotary_unit
from .identifiability import OFFSET, groups, scaled_svd, with_groups
from .optimiser import UNDETERMINED
from .parameters import get_value
from .problem import Problem, make_traces
from .start import force_start, lugre_start, moving_speed, with_friction_model

stats = lazy("scipy.stats")

#: each method's default initial model on displacement data (the paper's presets)
PRESET_OF_METHOD = {"plant": "li2009-base", "base": "li2009-base", "model-i": "li2009-model-i",
                    "model-ii": "li2009-model-ii", "heat": "li2009-self-heating"}


def displacement_initial(init, method, data, experiments, *, friction=None, free=(), procedure="direct"):
    """The initial model for displacement data: the method's preset by default; a file with only a [plant]
    (and [input]) starts LuGre from values taken from the data."""
    if init is None:
        init = PRESET_OF_METHOD[method]
    if not isinstance(init, Model):
        init = load_model(init, friction_from=lambda plant, inp, model="lugre": _start_of(
            model, plant, lugre_start(plant, experiments, inp)))
    if not isinstance(init.plant, StickSlipPlant):
        raise InputError(f"identification works on the stick-slip actuator (datasets record its voltage and "
                         f"displacement); a '{init.plant.type}' plant can be simulated but not identified yet")
    if friction is not None and method != "plant":
        init = with_friction_model(init, friction)
    return init


def _start_of(kind, plant, lugre_section) -> dict:
    """A [friction] section of ``kind`` from LuGre starting values (a file naming only its friction model)."""
    if kind == "lugre":
        return lugre_section
    return with_friction_model(Model(plant, LuGre.from_dict(lugre_section)), kind).friction.to_dict()


def force_initial(init, method, data, experiments, *, friction=None, free=(), procedure="direct"):
    """The initial model for force data: a prescribed-motion model of the data's kind (linear or rotary); a
    plant-only file (or one naming only the friction model), or none, gets its friction values from the data."""
    if free:
        raise InputError("free= frees plant parameters; a prescribed-motion model has none to fit")
    if method == "model-ii" and procedure != "direct":
        raise InputError("Model II's paper procedure reads stick-slip displacements; force data use the direct one")
    if not experiments:
        raise InputError("the dataset has no experiment with role 'fit'")
    rotary = units_of(getattr(data, "experiments", experiments))
    init = _from_plant_only(init, experiments, rotary)
    if init.plant.type != "prescribed":
        raise InputError(f"force data are fitted with a prescribed-motion model ([plant] type = \"prescribed\"); "
                         f"the initial model's plant is '{init.plant.type}'")
    if init.plant.rotary != rotary:
        want = "rotary" if rotary else "linear"
        raise InputError(f"the data are {want} ({'rad, N m' if rotary else 'm, N'}) but the initial model's motion is "
                         f"{init.plant.motion}: set motion = \"{want}\" in its [plant]")
    if friction is not None:
        init = with_friction_model(init, friction)
        if friction == "stribeck":  # asked for: a Stribeck map, not the Coulomb map a start without an excess fits
            init = _with_excess(init, experiments)
    if init.heat is not None:
        raise InputError("a self-heating model ([heat]) cannot be fitted to force data yet")
    moving_speed(experiments)  # a record at rest is refused whatever the initial model (it determines nothing)
    return _v_smooth_from_data(init, experiments)


def _with_excess(init, experiments):
    """A Stribeck map whose start has no excess (fs = fc: none seen in the data's slowest sliding) gets one to fit
    from: fs a tenth above fc, vs a tenth of the data's moving speed (the fit's defaults drop fs and vs where there
    is no excess, which made --friction stribeck a plain Coulomb map)."""
    values = init.friction.values()
    if "fs" in init.laws or values.get("fc") is None or (values.get("fs") or 0.0) > values["fc"]:
        return init
    return init.with_friction(fs=1.1 * values["fc"], vs=0.1 * moving_speed(experiments))


def _v_smooth_from_data(init, experiments):
    """A friction model whose ``v_smooth`` is left at its default gets one velocity step of the data where the
    velocity is quantised (a firmware's fixed steps): far below a step, a static model chatters at rest."""
    default = {f.name: f.default for f in dataclasses.fields(init.friction)}.get("v_smooth")
    if default is None or getattr(init.friction, "v_smooth", None) != default:
        return init
    return with_v_smooth(init, experiments)


def _from_plant_only(init, experiments, rotary):
    def start(plant, inp, model="lugre"):
        if plant.type != "prescribed":
            raise InputError("force data are fitted with a prescribed-motion model: [plant] type = \"prescribed\"")
        return force_start(experiments, model, plant)

    if init is None:
        plant = PrescribedMotion(motion="rotary" if rotary else "linear")
        return Model(plant, LuGre.from_dict(force_start(experiments, "lugre", plant)))
    if isinstance(init, Model):
        return init
    return load_model(init, friction_from=start)


def force_finish(res, experiments, init, measurement):
    """The fit completed for force data: the sensor offset estimated at the optimum ("shared": one, written into
    the fitted model; "per-experiment": one per run, their mean written into the model; "none": the initial
    model's); a rotary joint's parameters in its units."""
    traces = make_traces(experiments, res.model, measurement)
    unit = traces[0].unit
    names = [p.name for p in res.parameters.varying] if res.n_points else []
    inflation = res.statistics.get("variance_inflation", 1.0)
    found = []
    if measurement.offset == "shared":
        est = estimate_offset(res.model, names, traces, inflation, found)
    elif measurement.offset == "per-experiment":
        runs = [dict(estimate_offset(res.model, names, [tr], inflation, found), file=tr.name) for tr in traces]
        est = {"value": float(np.mean([r["value"] for r in runs])), "stderr": None, "ci95": None,
               "per_experiment": runs}
    else:
        est = {"value": init.plant.sensor_offset, "stderr": 0.0, "ci95": (init.plant.sensor_offset,) * 2}
    model = dataclasses.replace(res.model, plant=dataclasses.replace(res.model.plant, sensor_offset=est["value"]))
    est.update(unit=unit, fitted=measurement.offset != "none", policy=measurement.offset)
    if names and measurement.offset != "none":  # the offset's column seen: these groups replace the fit's own
        res = with_groups(res, found)
    return completed(res, model, est, unit)


def completed(res, model, offset: dict, unit: str):
    """A force fit's result with its model, its offset's estimate and its unit; a rotary joint's parameters in
    its units."""
    if unit == "N m":  # the equations are the same, the numbers mean angles and torques
        for p in res.parameters.values():
            if p.unit and "C" != p.unit:
                p.unit = rotary_unit(p.unit)
    for e in res.experiments:
        q = e.get("fit_quality") or {}
        e["rmse"] = q.get("rmse", e.get("rmse_offset_removed"))
        e["unit"] = unit
    return dataclasses.replace(res, model=model, sensor_offset=offset, unit=unit)


def estimate_offset(model: Model, names, traces, variance_inflation=1.0, found=None) -> dict:
    """The shared offset at ``model`` (``names`` the fitted parameters): the mean of ``F_meas - F_sim`` over
    all traces, and its standard error from the Jacobian augmented with the offset's column of ones (so that
    the parameters' uncertainty is in it); ``found``: as estimate_linear's."""
    return estimate_linear(model, names, traces, None, variance_inflation, found=found)[0][0]


def estimate_linear(model: Model, names, traces, columns=None, variance_inflation=1.0, at=None, found=None):
    """The linear parameters profiled out of a fit, at ``model`` (``names`` the fitted parameters): the least
    squares ``F_sim + columns beta = F_meas`` (``columns`` None: one column of ones, the shared offset), and
    their standard errors from the Jacobian augmented with those columns (so that the parameters' uncertainty
    is in them); ``at(r, J)``, where given, transforms the residuals and Jacobian first (a delay's shift).
    ``found``, a list where given, gets the undetermined groups (identifiability.groups) the columns (offsets) are
    members of. Returns (one dict per column: value, stderr, ci95; the residuals at the estimate)."""
    plain = [dataclasses.replace(tr, measurement=Force("none"), held_offset=0.0) for tr in traces]
    problem = Problem(model, names, plain, rtol=FD_RTOL, parallel=len(plain) > 1)
    theta = np.array([get_value(model, n) for n in names], float)
    r, J = problem.evaluate(theta, jac=bool(names))
    if at is not None and r is not None:
        r, J = at(r, J)
    X = np.ones((sum(tr.n_residuals for tr in traces), 1)) if columns is None else columns
    if r is None:
        return [{"value": math.nan, "stderr": math.nan, "ci95": (math.nan, math.nan)}] * X.shape[1], None
    beta = np.linalg.lstsq(X, -r, rcond=None)[0]
    res = r + X @ beta
    A = np.column_stack([J, X]) if names else X
    dof = max(r.size - A.shape[1], 1)
    s2 = float(res @ res) / dof * variance_inflation
    S, Vt, col, bad, cov1 = scaled_svd(A, UNDETERMINED)  # an offset the data do not determine: infinite error
    cov = cov1 * s2
    if found is not None and names:  # the groups the offset is part of (it is profiled out of the fit's own)
        se = np.sqrt(np.diag(cov))
        found += groups(S, Vt, col, list(names) + [OFFSET] * X.shape[1], np.concatenate([theta, beta]), se, s2,
                        nuisance={OFFSET}, bad=bad)
    tq = float(stats.t.ppf(0.975, dof))
    out = []
    for k, value in enumerate(beta):
        se = math.sqrt(max(float(cov[A.shape[1] - X.shape[1] + k, A.shape[1] - X.shape[1] + k]), 0.0))
        out.append({"value": float(value), "stderr": se, "ci95": (float(value) - tq * se, float(value) + tq * se)})
    return out, res


def command_initial(init, method, data, experiments, delay=AUTO, **options):
    """The initial model for a drive's command: the delay, the inertia J0 and a first offset by linear least
    squares ``u(t - delay) = J0 a + b + fc sgn(v) + sigma2 v`` on a scan of delays (measurements/command.py:
    delay_scan; ``delay`` a DelaySpec: auto or a range scanned, a value or none held); force data's initial model
    (:func:`force_initial`) with friction values read off ``u(t - delay) - J0 a``; then the delay again with that
    model's friction as one more column (its Stribeck curve). The model's [plant] gets J0 and the delay (auto:
    applied only beyond about a sample)."""
    if not experiments:
        raise InputError("the dataset has no experiment with role 'fit'")
    moving_speed(experiments)
    grid = (None if delay.kind in ("none", "value") else
            search_range(delay, [e.time for e in experiments], [e.drive_velocity for e in experiments],
                         [acceleration(e) for e in experiments]))

    def scan(columns):
        if grid is None:
            return delay.lo, linear_fit(experiments, columns, delay.lo, [sliding(e) for e in experiments])[0]
        d, _, coef, i = delay_scan(experiments, columns, grid[:2])
        check_not_at_end(delay, i, grid[1], grid[0], grid[2])
        return d, coef

    d0, coef = scan([coulomb_columns(e) for e in experiments])
    adjusted = [dataclasses.replace(e, force=shifted(e.time, e.force, d0) - coef[0] * acceleration(e))
                for e in experiments]
    init = force_initial(init, method, data, adjusted, **options)
    d, coef = scan([np.column_stack([coulomb_columns(e), Force().friction_of(init, e)]) for e in experiments])
    if delay.kind == "auto":
        d = applied_delay(d, grid[0])
    plant = dataclasses.replace(init.plant, inertia=max(float(coef[0]), 0.0), delay=d)
    return dataclasses.replace(init, plant=plant)


def command_finish(res, experiments, init, measurement):
    """The fit completed for a drive's command: the inertia J and the offsets (as the policy says) estimated
    together at the optimum with their standard errors (:func:`estimate_linear` on the acceleration's and the
    offsets' columns, at the delay), the delay at the fitted friction with its standard error (the curvature of
    the cost over the delay, the friction held: measurements/command.py DelaySearch) where it is searched, all
    written into the fitted model's [plant] and ``details["plant"]``."""
    traces = make_traces(experiments, res.model, measurement)
    unit, policy, spec = traces[0].unit, measurement.offset, measurement.delay
    names = [p.name for p in res.parameters.varying] if res.n_points else []
    if policy == "none":  # the model's own offset, held
        traces = [dataclasses.replace(tr, measured=tr.measured - tr.held_offset) for tr in traces]
    search = delay_search(traces, "shared", spec, res.model.plant.delay)
    m = np.concatenate([tr.measured for tr in traces])
    plain = [dataclasses.replace(tr, measurement=Force("none"), held_offset=0.0) for tr in traces]
    r, _ = Problem(res.model, [], plain, rtol=FD_RTOL, parallel=len(plain) > 1).evaluate(np.array([]), jac=False)
    estimate, _, se = search.best(r + m) if r is not None else (math.nan, None, math.nan)
    searched = search.ks.size > 1 and math.isfinite(estimate)
    delay = estimate if searched or spec.kind == "value" else 0.0
    if searched:  # the fitted friction's delay too: not at the search's end
        check_not_at_end(spec, search.at, search.ks, search.dt, _range_reason(spec, traces))
    X = search.shift(nuisance_columns(traces, policy), delay)
    if searched:  # the delay's column, so that its error has the friction's in it: d(model at t + delay)/d delay
        X = np.column_stack([X, _delay_column(search, r + m, X, m, delay)])
    ests, _ = estimate_linear(res.model, names, traces, X, res.statistics.get("variance_inflation", 1.0),
                              at=lambda r, J: (search.shift(r + m, delay) - m, None if J is None else search.shift(J, delay)))
    if searched:
        se = ests.pop()["stderr"]
    inertia, offsets = ests[0], ests[1:]
    offset = _offset_estimate(policy, offsets, traces, init)
    offset.update(unit=unit, fitted=policy != "none", policy=policy)
    plant = {"inertia": dict(inertia, unit="kg m^2" if unit == "N m" else "kg"),
             "delay": _delay_record(spec, delay, estimate, se, searched, search, traces)}
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
        out["note"] = (f"fitted with the friction (the model's friction and acceleration taken at t + delay); "
                       f"searched {lo * 1e3:.4g} to {hi * 1e3:.4g} ms ({out['searched']['why']})")
    elif spec.kind == "value":
        out["note"] = "held at the value given (--delay VALUE), not fitted"
    elif spec.kind == "none":
        out["note"] = "none fitted (--delay none)"
    else:
        out["note"] = (f"not applied: the estimate before the fit was within {MIN_DELAY_SAMPLES:g} sampling "
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


def _delay_column(search, F, X, m, delay):
    """The derivative of the model's side ``F + J a`` at ``t + delay`` by the delay (J by least squares first;
    central differences over half a sampling interval either way)."""
    J = float(np.linalg.lstsq(X, m - search.shift(F, delay), rcond=None)[0][0])
    model_side = F + J * search.X[:, 0]
    h = 0.5 * search.dt
    return (search.shift(model_side, delay + h) - search.shift(model_side, delay - h)) / (2 * h)


def _no_finish(res, experiments, init, measurement):
    return res


#: measurement name -> (the initial model, the result's completion)
SETUP = {"displacement": (displacement_initial, _no_finish), "force": (force_initial, force_finish),
         "command": (command_initial, command_finish)}

__all__ = ["SETUP", "PRESET_OF_METHOD", "displacement_initial", "force_initial", "force_finish", "estimate_offset",
           "estimate_linear", "command_initial", "command_finish"]
