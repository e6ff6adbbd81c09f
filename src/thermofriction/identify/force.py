"""Identification from measured force or torque (docs/force-data.md): a prescribed-motion model driven by each
experiment's measured motion, its friction force fitted to the measured one.

The residuals are the force (torque) errors ``F_sim + offset - F_meas``. One constant ``offset`` (the force
sensor's bias) is shared by all experiments of a fit: profiled out (the mean residual removed over all of them,
the Jacobian's columns centred likewise), then estimated at the optimum with its standard error and written
into the fitted model (``[plant] sensor_offset``), where validation uses it as it is, never re-fitting it on
held-out data. ``offset=False`` holds it at the initial model's value (0 unless the file gives one).

The Jacobian is by forward differences of whole runs at a tighter tolerance (a prescribed-motion model has only
the friction states, so a run costs little): the C core's sensitivities are those of the states, and the friction
force is an output of them.
"""

from __future__ import annotations

import contextvars
import dataclasses
import math
import time as _time

import numpy as np
from scipy import stats

from .. import _bridge
from ..drive import drive
from ..errors import InputError
from ..models import LuGre, Model, PrescribedMotion
from .engine import _MAX_STEPS, Problem, Trace, pool
from .result import FitResult

#: Whether the Problems built while a force identification runs fit the shared offset (set by identify_force,
#: read when its traces are made; the engine's procedures build their traces themselves).
FIT_OFFSET = contextvars.ContextVar("thermofriction_fit_offset", default=True)
#: Relative step of the forward differences, and the tolerance of the runs they difference: the solver's
#: error over the step (1e-9 / 1e-5) and the truncation error (~1e-5) make the Jacobian good to ~1e-4, ample
#: for Gauss-Newton steps and for the intervals (1e-10 costs half as much again for nothing visible).
FD_STEP = 1e-5
#: What to try when a fit to force data is not adequate.
FORCE_ADVICE = ("check the units in the files' headers; check that the sampling resolves the force's swing after "
                "each reversal (a few samples at least); try another friction model (--friction) or fit the "
                "parameters held fixed (--parameters); fit a thermal model (--method model-i or model-ii) if the "
                "experiments span temperatures")
FD_RTOL = 1e-9


@dataclasses.dataclass
class ForceTrace(Trace):
    """A force experiment ready to fit: ``force`` the measured force (torque), ``sensor_offset`` the offset
    held when ``fit_offset`` is False, ``unit`` N or N m."""

    force: np.ndarray | None = None
    sensor_offset: float = 0.0
    fit_offset: bool = True
    unit: str = "N"

    @property
    def measured(self) -> np.ndarray:
        return self.force

    @staticmethod
    def offsets_in(traces) -> int:
        """Offsets fitted besides the parameters (degrees of freedom): one shared, or none."""
        return int(bool(traces) and traces[0].fit_offset)


def make_force_trace(exp, model: Model) -> ForceTrace:
    if model.plant.type != "prescribed":
        raise InputError(f"{exp.file}: force data are fitted with a prescribed-motion model ([plant] type = "
                         f"\"prescribed\"), not a '{model.plant.type}' plant")
    if model.heat is not None:
        raise InputError("a self-heating model ([heat]) cannot be fitted to force data yet; fit Model I or II on "
                         "the measured temperatures instead")
    d = drive(exp, model, start="record")
    return ForceTrace(exp.file, np.ascontiguousarray(exp.time, float), np.ascontiguousarray(exp.displacement, float),
                      d.temperature, d.waveform, getattr(exp, "role", "fit"), float(exp.temperature),
                      force=np.ascontiguousarray(exp.force, float), sensor_offset=model.plant.sensor_offset,
                      fit_offset=FIT_OFFSET.get(), unit=exp.force_unit)


def _steps(model, names, theta):
    """The forward-difference step of each parameter: FD_STEP of its magnitude, of the friction level for a
    Model II value that starts at zero."""
    out = []
    for name, v in zip(names, theta):
        scale = abs(v) if v != 0 else (abs(model.reference_force()) if name.startswith("dF") else 1.0)
        out.append(FD_STEP * max(scale, 1e-300))
    return np.array(out)


class ForceProblem(Problem):
    """Residuals ``F_sim + offset - F_meas`` over all traces (the shared offset profiled out when fitted) and
    their Jacobian by forward differences."""

    def _force(self, model, trace, rtol):
        spec = _bridge.model_spec(model, trace.temperature, trace.waveform)
        out = np.empty((len(trace.time), _bridge.n_outputs(model, False)))
        try:
            # no sensitivities here: the solver may switch to Rodas4 where stiff bristles would hold Dormand-Prince
            # to tiny steps (a start far above the data's stiffness)
            _bridge.run(spec, trace.time, out, method="auto", rtol=rtol, max_steps=_MAX_STEPS)
        except _bridge.CoreFailure:
            return None
        return out[:, _bridge.OUTPUT_COLUMN["friction_force"]]

    def _forces(self, model, rtol):
        """The simulated force of every trace, concatenated; None when a run fails."""
        run = lambda tr: self._force(model, tr, rtol)  # noqa: E731
        forces = list(pool().map(run, self.traces)) if self.parallel and len(self.traces) > 1 else \
            [run(tr) for tr in self.traces]
        return None if any(f is None for f in forces) else np.concatenate(forces)

    @property
    def _measured(self):
        return np.concatenate([tr.force - (0.0 if tr.fit_offset else tr.sensor_offset) for tr in self.traces])

    @property
    def _fit_offset(self):
        return bool(self.traces[0].fit_offset)

    def evaluate(self, theta, jac=False):
        theta = np.asarray(theta, float)
        model = self._model(theta)
        self.nfev += 1
        self.njev += int(jac)
        if model is None:
            return None, None
        rtol = min(self.rtol, FD_RTOL) if jac else self.rtol
        F = self._forces(model, rtol)
        if F is None:
            return None, None
        r = F - self._measured
        J = None
        if jac:
            h = _steps(self.model, self.names, theta)
            J = np.empty((r.size, theta.size))
            for k in range(theta.size):
                for sign in (1.0, -1.0):  # backwards where a step forwards breaks a rule (fs >= fc)
                    step = theta.copy()
                    step[k] += sign * h[k]
                    mk = self._model(step)
                    Fk = None if mk is None else self._forces(mk, rtol)
                    if Fk is not None:
                        J[:, k] = (Fk - F) / (sign * h[k])
                        break
                else:
                    return None, None
        if self._fit_offset:
            r = r - r.mean()
            if J is not None:
                J = J - J.mean(axis=0)
        return r, J

    def per_trace(self, theta):
        r, _ = self.evaluate(theta)
        if r is None:
            return [None] * len(self.traces)
        edges = np.cumsum([0] + [len(tr.time) for tr in self.traces])
        return [r[a:b] for a, b in zip(edges[:-1], edges[1:])]


ForceTrace.problem_class = ForceProblem


def estimate_offset(model: Model, names, traces, variance_inflation=1.0) -> dict:
    """The shared offset at ``model`` (``names`` the fitted parameters): the mean of ``F_meas - F_sim`` over
    all traces, and its standard error from the Jacobian augmented with the offset's column of ones (so that
    the parameters' uncertainty is in it)."""
    plain = [dataclasses.replace(tr, fit_offset=False, sensor_offset=0.0) for tr in traces]
    problem = ForceProblem(model, names, plain, rtol=FD_RTOL, parallel=len(plain) > 1)
    theta = np.array([_value(model, n) for n in names], float)
    r, J = problem.evaluate(theta, jac=bool(names))
    if r is None:
        return {"value": math.nan, "stderr": math.nan, "ci95": (math.nan, math.nan)}
    offset = -float(r.mean())
    res = r + offset
    A = np.column_stack([J, np.ones(r.size)]) if names else np.ones((r.size, 1))
    dof = max(r.size - A.shape[1], 1)
    s2 = float(res @ res) / dof * variance_inflation
    col = np.linalg.norm(A, axis=0)
    col[col == 0] = 1.0
    cov = np.linalg.pinv((A / col).T @ (A / col), rcond=1e-12) / np.outer(col, col) * s2
    se = math.sqrt(max(float(cov[-1, -1]), 0.0))
    tq = float(stats.t.ppf(0.975, dof))
    return {"value": offset, "stderr": se, "ci95": (offset - tq * se, offset + tq * se)}


def _value(model, name):
    from .parameters import get_value
    return get_value(model, name)


# -- starting values ------------------------------------------------------------------------------

def force_start(experiments, kind: str = "lugre", plant: PrescribedMotion | None = None) -> dict:
    """A [friction] section of ``kind`` with starting values read off the data:

    - the Coulomb level fc and viscous sigma2 (and the sensor offset, where the motion goes both ways) by
      linear least squares ``F = b + fc sgn(v) + sigma2 v`` on the faster half of the sliding samples;
    - a Stribeck excess fs - fc from the slowest sliding samples, and vs where it has fallen by 1/e;
    - the bristle stiffness sigma0 from the force's rise over the motion after each reversal (the secant
      over half the swing, times ln 2, is sigma0 for LuGre), else fc over 1/1000 of the stroke;
    - sigma1 so that its force at the typical sliding speed is a tenth of fc.
    A rough start: the fit's multi-start spans a decade either way."""
    exps = list(getattr(experiments, "fit", experiments))
    if not exps:
        raise InputError("no experiment to take starting values from")
    v = np.concatenate([e.drive_velocity for e in exps])
    F = np.concatenate([e.force for e in exps])
    x = [np.asarray(e.displacement, float) for e in exps]
    speed = np.abs(v)
    top = float(np.quantile(speed, 0.95)) if speed.size else 0.0
    if not top > 0:
        raise InputError(f"{exps[0].file}: the motion does not move: no friction can be taken from it")
    sliding = speed > 0.02 * top
    fast = sliding & (speed >= np.median(speed[sliding]))
    both_ways = np.any(v[fast] > 0) and np.any(v[fast] < 0)
    cols = [np.sign(v[fast]), v[fast]] + ([np.ones(int(fast.sum()))] if both_ways else [])
    coef, *_ = np.linalg.lstsq(np.column_stack(cols), F[fast], rcond=None)
    fc = abs(float(coef[0]))
    b = float(coef[2]) if both_ways else 0.0
    fc = fc if fc > 0 else float(np.quantile(np.abs(F), 0.5)) or 1.0
    sigma2 = max(float(coef[1]), 1e-3 * fc / top)
    # presliding stiffness from the reversals
    secants, travelled = [], []
    for e, xe in zip(exps, x):
        ve, Fe = e.drive_velocity, e.force
        flips = np.flatnonzero(np.sign(ve[1:]) * np.sign(ve[:-1]) < 0)
        for i in flips:
            j = i + 1
            while j < len(Fe) and abs(Fe[j] - Fe[i]) < fc and j - i < 10_000:
                j += 1
            if j < len(Fe) and abs(xe[j] - xe[i]) > 0:
                secants.append(abs(Fe[j] - Fe[i]) / abs(xe[j] - xe[i]))
        start = np.zeros(len(xe), int)  # the sample of the last reversal before each sample
        start[flips + 1] = flips + 1
        travelled.append(np.abs(xe - xe[np.maximum.accumulate(start)]))
    stroke = max(float(np.ptp(np.concatenate(x))), 1e-300)
    sigma0 = math.log(2.0) * float(np.median(secants)) if secants else fc / (1e-3 * stroke)
    # a swing within one sample gives no stiffness, only a bound: start where the presliding spans a tenth of a
    # typical sample's motion (stiffer bristles change nothing the data can show, and make the runs stiff)
    step = float(np.median(np.concatenate([np.abs(np.diff(xe)) for xe in x])))
    if step > 0:
        sigma0 = min(sigma0, 2.0 * fc / (0.1 * step))
    typical = float(np.median(speed[sliding]))
    section = {"model": "lugre", "fc": fc, "sigma2": sigma2, "sigma0": sigma0, "sigma1": 0.1 * fc / typical}
    # Stribeck: the excess over the Coulomb-viscous line at the slowest speeds of steady sliding (five
    # presliding lengths fc/sigma0 past a reversal)
    steady = sliding & (np.concatenate(travelled) > 5.0 * fc / sigma0)
    excess = np.sign(v[steady]) * (F[steady] - b) - fc - sigma2 * speed[steady]
    s = speed[steady]
    order = np.argsort(s)
    n_bin = max(len(order) // 40, 5)
    bins = [order[i:i + n_bin] for i in range(0, len(order), n_bin)]
    levels = np.array([np.median(excess[i]) for i in bins])
    speeds = np.array([np.median(s[i]) for i in bins])
    if levels.size > 2 and levels[0] > 0.05 * fc:
        fs = fc + float(levels[0])
        below = np.flatnonzero(levels < levels[0] / math.e)
        vs = float(speeds[below[0]]) if below.size else float(speeds[-1])
        section.update(fs=fs, vs=max(vs, float(speeds[0])))
    if kind == "lugre":
        return section
    from . import with_friction_model
    start = Model(plant or PrescribedMotion(), LuGre.from_dict(section))
    return with_friction_model(start, kind).friction.to_dict()


# -- identification -------------------------------------------------------------------------------

@dataclasses.dataclass
class ForceFitResult(FitResult):
    """A fit to force data: the sensor's offset (``sensor_offset``: value, stderr, ci95, unit, fitted) and the
    unit of the residuals (N or N m)."""

    sensor_offset: dict = dataclasses.field(default_factory=dict)
    unit: str = "N"

    def to_dict(self) -> dict:
        from .._io import jsonable
        d = super().to_dict()
        d["rmse"] = d["rmse_offset_removed"]
        d["unit"] = self.unit
        d["sensor_offset"] = jsonable(self.sensor_offset)
        return d

    def report(self) -> str:
        lines = super().report().splitlines()
        out = []
        for line in lines:
            if line.strip().startswith("rmse"):
                line = f"    rmse             = {self.rmse:.4g} {self.unit} (force error, the shared offset removed)"
            elif line.strip().startswith("noise (data)") and self.fit_quality:
                q = self.fit_quality
                line = (f"    noise (data)     = {q['noise']:.4g} {self.unit}; rmse/noise = {q['ratio']:.3g}, "
                        f"lag-1 autocorrelation {q['autocorrelation']:.2g}")
            out.append(line)
        o = self.sensor_offset
        if o:
            how = "fitted, shared by all experiments" if o.get("fitted") else "held (--no-offset)"
            err = f" +- {o['stderr']:.3g}" if o.get("fitted") and o.get("stderr") is not None else ""
            out.insert(min(3, len(out)), f"    sensor offset    = {o['value']:.6g}{err} {self.unit} ({how})")
        return "\n".join(out)


def _relabel(result: FitResult, rotary: bool):
    """Units of a rotary joint's parameters (N m/rad, ...): the equations are the same, the numbers mean
    angles and torques."""
    if not rotary:
        return
    from ..models.plants import rotary_unit
    for p in result.parameters.values():
        if p.unit and "C" != p.unit:
            p.unit = rotary_unit(p.unit)


def _from_plant_only(init, experiments, rotary):
    """The initial model: a file or preset, where a plant-only file (or one naming only the friction model)
    gets its friction values from the data."""
    from ..models import load_model

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


def identify_force(data, method="base", init=None, *, friction=None, parameters=None, free=(), procedure="direct",
                   laws=None, refine=True, reference_temperature=None, offset=True, rtol=1e-8, starts=8, seed=0,
                   progress=None) -> ForceFitResult:
    """Identifies a friction model (``method`` base, model-i or model-ii) from the ``fit`` experiments of a force
    dataset (see :func:`thermofriction.identify.identify`, which calls this for force data). ``offset``: fit the
    force sensor's offset, one for all experiments (default), or hold it at the initial model's."""
    from ..data.force import units_of
    from . import with_friction_model
    from .model_ii import identify_model_ii
    from .procedures import base_model, default_fit_parameters, fit_friction, identify_model_i

    t0 = _time.perf_counter()
    if method not in ("base", "model-i", "model-ii"):
        raise InputError(f"method '{method}' does not apply to force data (base, model-i or model-ii)")
    if free:
        raise InputError("free= frees plant parameters; a prescribed-motion model has none to fit")
    if method == "model-ii" and procedure != "direct":
        raise InputError("Model II's paper procedure reads stick-slip displacements; force data use the direct one")
    experiments = list(getattr(data, "fit", data))
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
    if init.heat is not None:
        raise InputError("a self-heating model ([heat]) cannot be fitted to force data yet")
    opts = dict(rtol=rtol, starts=starts, seed=seed, progress=progress)
    token = FIT_OFFSET.set(bool(offset))
    try:
        if method == "base":
            model = base_model(init)
            res = fit_friction(experiments, model, parameters or default_fit_parameters(model), method="base", **opts)
        elif method == "model-i":
            if init.thermal is not None and not hasattr(init.thermal, "laws"):
                init = base_model(init)
            res = identify_model_i(experiments, init, laws=laws, refine=refine, **opts)
        else:
            res = identify_model_ii(experiments, init, procedure="direct", reference_temperature=reference_temperature,
                                    refine=refine, **opts)
        traces = [make_force_trace(e, res.model) for e in experiments]
    finally:
        FIT_OFFSET.reset(token)
    unit = "N m" if rotary else "N"
    names = [p.name for p in res.parameters.varying] if res.n_points else []
    if offset:
        est = estimate_offset(res.model, names, traces, res.statistics.get("variance_inflation", 1.0))
        model = dataclasses.replace(res.model, plant=dataclasses.replace(res.model.plant, sensor_offset=est["value"]))
    else:
        est = {"value": init.plant.sensor_offset, "stderr": 0.0, "ci95": (init.plant.sensor_offset,) * 2}
        model = res.model
    est.update(unit=unit, fitted=bool(offset))
    _relabel(res, rotary)
    for e in res.experiments:
        q = e.get("fit_quality") or {}
        e["rmse"] = q.get("rmse", e.get("rmse_offset_removed"))
        e["unit"] = unit
    fields = {f.name: getattr(res, f.name) for f in dataclasses.fields(FitResult)}
    fields.update(model=model, wall_time=_time.perf_counter() - t0)
    return ForceFitResult(**fields, sensor_offset=est, unit=unit)


def compare_friction_models(data, kinds=("coulomb", "stribeck", "lugre"), init=None, *, offset=True, **opts) -> dict:
    """Fits each friction model of ``kinds`` (method base) to the fit experiments and predicts the held-out ones:
    ``{kind: {"aicc", "delta_aicc", "rmse", "heldout_rmse", "n_parameters", "result"}}``, delta_aicc against
    the best. A model that fails to fit is reported with its reason (``failed``)."""
    from ..errors import ThermofrictionError
    from ..validate import validate

    out = {}
    held = list(getattr(data, "validate", []))
    for kind in kinds:
        try:
            res = identify_force(data, "base", init, friction=kind, offset=offset, **opts)
        except ThermofrictionError as e:
            out[kind] = {"failed": str(e)}
            continue
        entry = {"aicc": res.aicc, "rmse": res.rmse, "n_parameters": len(res.parameters.varying), "result": res,
                 "heldout_rmse": math.nan}
        if held:
            v = validate(res.model, data, held)
            errs = [p.rmse for p in v.predictions]
            entry["heldout_rmse"] = float(np.sqrt(np.mean(np.square(errs)))) if errs else math.nan
        out[kind] = entry
    fitted = [e["aicc"] for e in out.values() if "aicc" in e and math.isfinite(e["aicc"])]
    best = min(fitted) if fitted else math.nan
    for e in out.values():
        if "aicc" in e:
            e["delta_aicc"] = e["aicc"] - best
    return out


__all__ = ["ForceTrace", "ForceProblem", "ForceFitResult", "make_force_trace", "estimate_offset", "force_start",
           "identify_force", "compare_friction_models", "FIT_OFFSET"]
