"""Friction force or torque under a measured motion (docs/force-data.md): a prescribed-motion model driven by
each experiment's measured motion, its friction force held against the measured one.

The residuals are the force (torque) errors ``F_sim + offset - F_meas``. The offset (the force sensor's bias)
is, by the policy this measurement is made with, one constant shared by all experiments of a fit ("shared":
profiled out, the mean residual removed over all of them and the Jacobian's columns centred likewise, then
estimated at the optimum with its standard error and written into the fitted model's ``[plant]
sensor_offset``, where validation uses it as it is, never re-fitting it on held-out data), one per experiment
("per-experiment": nuisance parameters, each run's mean residual removed, estimated on every run, held-out ones
included, for a sensor re-zeroed between runs), or none fitted ("none": the model's own is used).

The simulated force and its Jacobian come from the C core's exact stepping of the prescribed motion
(core/src/prescribed.c, ``_bridge.prescribed_force``) wherever it applies: the motion is piecewise linear, so at a
constant temperature the friction state's rate (LuGre, Dahl, each GMS element) is affine in the state between knots,
with a closed-form step and sensitivities; static maps have no state; the elasto-plastic bristle is integrated with
its variational equations inside its transition band (core/src/prescribed_ep.c). Model I's laws act through their
values at a run's temperature (``Problem.chain_matrix``). Elsewhere -- Model II, a temperature signal, a fitted name
that is not a friction parameter -- runs are integrated and the Jacobian is by forward differences of whole runs.
A position ripple is added outside either, at the recorded angle, in closed form (measurements/ripple.py).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import _bridge
from ..drive import drive
from ..errors import InputError, SolverError
from ..data.experiments import run_label
from ..data.force import ForceExperiment
from ..models import FRICTION_MODELS, Model, ModelI, PrescribedMotion
from ..models.sides import RIPPLE_AMPLITUDES
from . import ripple
from ..simulation import StepSizeController, simulate
from ..waveforms import Sampled
from ..fitting.quality import fit_quality
from .base import FD_RTOL, FD_STEP, OFFSETS, Measurement, Trace, center, center_each, reverses, thermal_check
from .force_finish import force_finish
from .force_load import stepped_force
from ..models.load_laws import load_laws
from .force_start import force_initial, screen_starts, start_section, stribeck_speeds

#: What to check when a fit to force data is not adequate, where it applies (Force.checks)
UNITS_CHECK = "check the units in the files' headers"
SAMPLING_CHECK = "check that the sampling resolves the force's swing after each reversal (a few samples at least)"

#: Force data see the whole friction-velocity map: the Stribeck and viscous parameters are fitted too (each
#: description's ``fitted``).
FIT_PARAMETERS = {name: cls.description.fitted["force"] for name, cls in FRICTION_MODELS.items()}


def _steps(model, names, theta):
    """The forward-difference step of each parameter: FD_STEP of its magnitude, of the friction level for a
    Model II value that starts at zero."""
    return np.array([FD_STEP * max(abs(v) if v != 0 else (abs(model.reference_force()) if name.startswith("dF")
                                                            else 1.0), 1e-300) for name, v in zip(names, theta)])


#: what force data's tables call an error relative to the data: a signal that changes sign has no level to divide by,
#: and its largest error sits at a reversal, so the RMSE is taken against the range the measured signal spans
RANGE_PCT = "RMSE [% of range] = 100 RMSE / (max F_meas - min F_meas)"

class Force(Measurement):
    """A friction force or torque under a measured motion (docs/force-data.md).

    Parameters
    ----------
    offset : {"shared", "per-experiment", "none"}, default "shared"
        The offset policy (OFFSETS): "shared", one fitted offset for all runs; "per-experiment", each run's own,
        estimated on it; "none", the model's own, held.
    ripple_phase : {"recorded", "per-run", "auto"}, default "recorded"
        The position ripple's angle (measurements/ripple.py): at the recorded position, or each run's own phase.

    Raises
    ------
    InputError
        An offset policy that does not apply to these data; an unknown ripple phase.
    """

    name = "force"
    quantity = "friction force (torque)"
    plants = ("prescribed",)
    fit_parameters = FIT_PARAMETERS
    methods = ("base", "model-i", "model-ii", "warm-up")

    @staticmethod
    def recognises(exp) -> bool:
        return isinstance(exp, ForceExperiment)

    def __init__(self, offset: str = "shared", ripple_phase: str = "recorded"):
        if offset not in OFFSETS:
            raise InputError(f"offset must be one of {', '.join(OFFSETS)} for force data, got {offset!r}")
        self.offset = offset
        #: the ripple's angle: "recorded" or "per-run" (measurement_of resolves "auto" from the data, ripple_note why)
        self.ripple_phase = ripple.check_phase_option(ripple_phase)
        self.ripple_note = None
        self.phases_fitted = 0

    @property
    def removed(self) -> str:
        return {"shared": "the shared sensor offset (fitted)", "none": "the model's sensor offset (held)",
                "per-experiment": "each experiment's own sensor offset (fitted)"}[self.offset]

    @property
    def validation_removed(self) -> str:
        return ("each experiment's own sensor offset (its mean error), estimated on every experiment, held-out ones "
                "included" if self.offset == "per-experiment" else
                "the model's sensor offset ([plant] sensor_offset), as fitted") + ripple.phases_said(self)

    def unit(self, experiments=()) -> str:
        exps = list(getattr(experiments, "experiments", experiments))
        return "N m" if exps and exps[0].rotary else "N"

    def stribeck_speeds(self, experiments) -> tuple:
        """(largest, start, unit): the largest speed of the runs' driving motion, above which a fitted Stribeck
        velocity leaves fc and vs undetermined, a Stribeck velocity inside their speeds to start from
        (measurements/force_start.py: stribeck_speeds), and the speeds' unit (what identification/procedures.py
        fit_friction asks where a fit's vs ends above the data's speeds)."""
        largest, start = stribeck_speeds(experiments)
        return largest, start, "rad/s" if self.unit(experiments) == "N m" else "m/s"

    def initial_model(self, init, method, data, experiments, *, parameters=(), **options):
        """A prescribed-motion model of the data's kind, with starting values read off the data where ``init``
        gives none (measurements/force_start.py), and fitted ripple amplitudes it starts at zero solved from the
        data (measurements/ripple.py: ``started``)."""
        model = force_initial(init, method, data, experiments, force=Force, **options)
        return ripple.started(self, model, experiments, parameters or ())

    def complete(self, res, experiments, init):
        """The sensor offset estimated at the optimum as the policy says, a rotary joint's units
        (measurements/force_finish.py)."""
        return force_finish(res, experiments, init, self, force=Force)

    def make_trace(self, exp, model) -> Trace:
        if model.plant.type != "prescribed":
            raise InputError(f"{exp.file}: force data are fitted with a prescribed-motion model ([plant] type = "
                             f"\"prescribed\"), not a '{model.plant.type}' plant")
        if load_laws(model):
            raise InputError(f"[thermal] {', '.join(load_laws(model))}: a law of the load is fitted by identify's Model "
                             "I (method \"model-i\", each run at its load); this fit takes none")
        if model.heat is not None:
            raise InputError("a self-heating model ([heat]) cannot be fitted to force data yet; fit Model I or II on "
                             "the measured temperatures instead")
        d = drive(exp, model, start="record")
        return Trace(run_label(exp), np.ascontiguousarray(exp.time, float), np.ascontiguousarray(exp.force, float),
                     d.temperature, d.waveform, getattr(exp, "role", "fit"), float(exp.temperature), self,
                     held_offset=model.plant.sensor_offset, unit=exp.force_unit,
                     angle=np.ascontiguousarray(exp.displacement, float))

    def _forces(self, problem, model, rtol):
        """The simulated force of every trace, concatenated; None when a run fails. (No sensitivities: the
        solver may switch to Rodas4 where stiff bristles would hold Dormand-Prince to tiny steps, a start far
        above the data's stiffness.)"""
        def run(i):
            out, _ = problem.simulate(model, problem.traces[i], None, False, method="auto", rtol=rtol)
            return None if out is None else out[:, _bridge.OUTPUT_COLUMN["friction_force"]]
        forces = problem.run_all(run, False)
        return None if any(f is None for f in forces) else np.concatenate(forces)

    @staticmethod
    def exact_names(problem, model):
        """The friction parameters the exact stepping differentiates for this problem (the values at a run's
        temperature, ``problem.chain``, where laws are fitted), or None where it does not apply: a thermal model
        other than Model I, a temperature signal, a fitted name that is not a friction parameter, or a model the
        core does not step exactly (``_bridge.prescribed_applies``; a ripple it steps at the waveform's position)."""
        if model.thermal is not None and not isinstance(model.thermal, ModelI):
            return None
        # a Stribeck excess fs - fc fitted as such (fitting/parameters.py: EXCESS) is fs to the core, its
        # column moved into fc's by Problem.in_names (integrated instead, Model I's per-temperature fits took 2x)
        names = problem.chain if problem.chain is not None else [
            "fs" if n == "fs_excess" else n for n in problem.names]
        if problem.chain is None and any(n in getattr(model, "laws", {}) for n in names):
            return None  # a law's base value fitted as such: not a value at the temperature
        arrays = getattr(model.friction, "arrays", ())
        if any(n not in _bridge.PARAMETERS or n in arrays for n in names):
            return None
        for tr in problem.traces:
            if not isinstance(tr.temperature, (int, float)):
                return None
        if not problem.traces or not _bridge.prescribed_applies(
                _bridge.model_spec(model, problem.traces[0].temperature, problem.traces[0].waveform)):
            return None
        return list(names)

    def _exact(self, problem, model, names, jac):
        """(force, Jacobian in the fitted names or None) of every trace, concatenated, by the exact stepping;
        (None, None) when a run fails."""
        def run(i):
            tr = problem.traces[i]
            T = float(tr.temperature)
            try:  # Model I's laws evaluated at T by the core; derivatives in the values there
                F, dF = _bridge.prescribed_force(_bridge.model_spec(model, T, tr.waveform), tr.time,
                                                 names if jac else ())
            except _bridge.CoreFailure:
                return None
            if not jac:
                return F, None
            return F, problem.in_names(dF, model, tr)
        out = problem.run_all(run, jac)
        if any(o is None for o in out):
            return None, None
        return np.concatenate([o[0] for o in out]), (np.vstack([o[1] for o in out]) if jac else None)

    def residuals(self, problem, model, theta, jac):
        measured = np.concatenate([tr.measured - (tr.held_offset if self.offset == "none" else 0.0)
                                   for tr in problem.traces])
        outside = ripple.additive(model)  # the ripple added here, at the recorded angle (measurements/ripple.py)
        base = ripple.without(model) if outside else model
        names = self.exact_names(problem, base)  # (the amplitudes' columns 0 there: the base has no ripple)
        if names is not None:
            F, J = self._exact(problem, base, names, jac)
        else:
            F, J = self._integrated(problem, base, theta, jac, RIPPLE_AMPLITUDES if outside else (), outside)
        if F is None:
            return None, None
        r, J, g = ripple.added(self, problem, model, F - measured, J) if outside else (F - measured, J, None)
        r, J = self.profiled(problem.traces, r, J)
        return r, (ripple.projected(J, g, problem.traces, self.offset) if outside else J)

    def _integrated(self, problem, model, theta, jac, skip=(), outside=False):
        """(force, Jacobian by forward differences of whole runs, zero in ``skip``) of every trace, integrated;
        (None, None) when a run fails. ``outside``: the ripple is added elsewhere (each stepped model without it)."""
        rtol = min(problem.rtol, FD_RTOL) if jac else problem.rtol
        F = self._forces(problem, model, rtol)
        if F is None or not jac:
            return F, None
        h = _steps(problem.model, problem.names, theta)
        J = np.zeros((F.size, theta.size))
        for k in range(theta.size):
            if problem.names[k] in skip:
                continue
            for sign in (1.0, -1.0):  # backwards where a step forwards breaks a rule (fs >= fc)
                step = theta.copy()
                step[k] += sign * h[k]
                mk = problem.model_at(step)
                mk = ripple.without(mk) if mk is not None and outside else mk
                Fk = None if mk is None else self._forces(problem, mk, rtol)
                if Fk is not None:
                    J[:, k] = (Fk - F) / (sign * h[k])
                    break
            else:
                return None, None
        return F, J

    def offsets_in(self, traces) -> int:
        return super().offsets_in(traces) + self.phases_fitted  # the ripple's phases per run

    def profiled(self, traces, r, J):
        """The residuals and Jacobian with the offsets the policy fits profiled out."""
        if self.offset == "shared":
            r, J = center(r, J)
        elif self.offset == "per-experiment":
            r, J = center_each(r, J, [tr.n_residuals for tr in traces])
        return r, J

    def checks(self, model, traces) -> list:
        """The units; the sampling at reversals where the runs reverse; a thermal model where they span
        temperatures."""
        out = [UNITS_CHECK]
        if any(reverses(tr) for tr in traces):  # (one-way runs have no reversal to resolve)
            out.append(SAMPLING_CHECK)
        return out + thermal_check(model, traces)

    # -- validation --------------------------------------------------------------------------------

    def check_model(self, model, experiments):
        ripple.check_per_run(self, model)
        if model.plant.type != "prescribed":
            raise InputError(f"force data are predicted with a prescribed-motion model ([plant] type = "
                             f"\"prescribed\"); this model's plant is '{model.plant.type}'")
        for exp in experiments:
            if model.plant.rotary != exp.rotary:
                raise InputError(f"{exp.file}: the data are {'rotary' if exp.rotary else 'linear'} but the model's "
                                 f"motion is {model.plant.motion}")

    def validation_extras(self, model) -> dict:
        return {"sensor_offset": model.plant.sensor_offset}

    #: what validation removes from the model's prediction where the model's own offset is held, in the caption
    #: and in the footer (a measurement whose prediction holds more, the command's inertia term, says so here)
    held_offset_said = "the model's sensor offset removed"
    held_offset_said_in_full = "the model's sensor offset ([plant] sensor_offset) removed"

    @property
    def caption(self) -> str:
        removed = "each experiment's own offset removed (estimated on it)" if self.offset == "per-experiment" else \
            f"{self.held_offset_said} (fitted on the fit experiments, never re-fitted)"
        return f"RMSE: {removed}{ripple.phases_said(self)}; {RANGE_PCT}"

    @property
    def footer(self) -> str:
        removed = ("each experiment's own offset removed: a nuisance parameter estimated on every experiment, "
                   "held-out ones included (their errors are then of the friction model's shape, not of its "
                   "offset)" if self.offset == "per-experiment" else
                   f"{self.held_offset_said_in_full}, as fitted on the fit experiments and "
                   "never re-fitted on held-out ones")
        return (f"RMSE: {removed}{ripple.phases_said(self)}; {RANGE_PCT}; max |error|: the largest single error, in the data's unit (on "
                f"a signal that changes sign it is at a reversal, where a small timing difference shows large); mean "
                f"error: the prediction's mean minus the measurement's, before any offset was removed "
                f"(docs/force-data.md#4-validation)")

    #: the tables show NRMSE as a percentage of the range
    column_scale = {"nrmse": 100.0}

    def columns_for(self, unit):
        return (("file", "file", "{}"), ("T [C]", "temperature", "{:.4g}"), ("role", "role", "{}"),
                (f"RMSE [{unit}]", "rmse_offset_removed", "{:.4g}"), ("RMSE [% of range]", "nrmse", "{:.3g}"),
                (f"max |error| [{unit}]", "max_error", "{:.3g}"), (f"mean error [{unit}]", "bias", "{:+.3g}"))

    def friction_of(self, model, exp, rtol=1e-8, fast=False, measured=None) -> np.ndarray:
        """The friction force (torque) ``model`` predicts along one experiment's measured motion, on its samples:
        simulated (with the simulation's checks and warnings); where the integrator cannot finish (bristles so
        stiff that a fit driven by the exact stepping put them there), by the exact stepping itself, which
        needs no step size. ``fast``: by the exact stepping wherever it applies (no simulation checks: for
        what only needs the values, the unit check). A ripple is added at the recorded angle (measurements/ripple.py;
        per run: at the angle offset that fits ``measured``). A model with laws of load: at the run's load, by the
        exact stepping (measurements/force_load.py: each run at its constant load)."""
        if load_laws(model):
            return stepped_force(model, exp, warn=True)[0]
        if ripple.additive(model):
            base = self.friction_of(ripple.without(model), exp, rtol, fast)
            return base + ripple.for_run(self, model, exp, base, measured)
        d = drive(exp, model, start="model")
        stepped = self._stepped(d, model, exp) if fast else None
        if stepped is not None:
            return stepped
        try:
            res = simulate(d.model(model), t_eval=exp.time, temperature=d.temperature, input=d.waveform,
                           controller=StepSizeController(rtol=rtol))
        except SolverError:
            stepped = self._stepped(d, model, exp)
            if stepped is None:
                raise
            return stepped
        return res.friction_force

    @staticmethod
    def _stepped(d, model, exp):
        """The exact stepping's friction along ``exp`` (driven as ``d``), or None where it does not apply."""
        if not isinstance(d.temperature, (int, float)):
            return None
        spec = _bridge.model_spec(d.model(model), d.temperature, d.waveform)
        if not _bridge.prescribed_applies(spec):
            return None
        return _bridge.prescribed_force(spec, np.asarray(exp.time, float))[0]

    def predicted(self, model, exp, rtol=1e-8, fast=False):
        """(predicted, measured) of one experiment: the friction plus the sensor offset, and the record."""
        measured = np.asarray(exp.force, float)
        return self.friction_of(model, exp, rtol, fast, measured) + model.plant.sensor_offset, measured

    def spans(self, model, exp, rtol=1e-6):
        """(measured, predicted) for the unit check, by the exact stepping where it applies."""
        self.check_model(model, [exp])
        predicted, measured = self.predicted(model, exp, rtol, fast=True)
        return measured, predicted

    def predict(self, model, exp, rtol=1e-8, fast=False) -> "ForcePrediction":
        """Simulates one force experiment on its own samples and compares the force (``fast``: by the exact stepping
        wherever it applies, as :meth:`friction_of`)."""
        self.check_model(model, [exp])
        pred, meas = self.predicted(model, exp, rtol, fast)
        err = pred - meas
        span = float(np.ptp(meas))
        bias = float(np.mean(err))
        if self.offset == "per-experiment":  # this run's own offset, estimated on it (and in what is shown)
            err, pred = err - bias, pred - bias
        quality = fit_quality(err, meas)
        rmse = float(np.sqrt(np.mean(err ** 2)))
        return ForcePrediction(run_label(exp), float(exp.temperature), getattr(exp, "role", "fit"), np.asarray(exp.time),
                               np.asarray(exp.displacement), np.asarray(exp.drive_velocity), meas, pred, rmse,
                               rmse / span if span > 0 else math.nan,
                               100 * float(np.max(np.abs(err))) / span if span > 0 else math.nan,
                               bias, exp.force_unit, quality, float(np.max(np.abs(err))))

    def summary(self, predictions) -> dict:
        out = {}
        for role, ps in self.by_role(predictions):
            pcts = [p.max_error_pct for p in ps if not math.isnan(p.max_error_pct)]
            rmse = float(np.sqrt(np.mean([p.rmse ** 2 for p in ps])))
            nrmse = [p.nrmse for p in ps if not math.isnan(p.nrmse)]
            out[role] = {"max_error_pct": max(pcts) if pcts else math.nan, "rmse": rmse,
                         "rmse_offset_removed": rmse, "unit": ps[0].unit, "n": len(ps),
                         "nrmse": float(np.sqrt(np.mean(np.square(nrmse)))) if nrmse else math.nan,
                         "max_error": max(p.max_error for p in ps)}
        return out


@dataclasses.dataclass
class ForcePrediction:
    """One force experiment: measured and predicted force [N or N m], the motion, and the metrics.

    Parameters
    ----------
    file : str
        The experiment's file.
    temperature : float
        Its temperature [C].
    role : {"fit", "validate"}
        Its role in the dataset.
    time : numpy.ndarray
        The sample times [s].
    position, velocity : numpy.ndarray
        The measured motion [m, m/s] (rad, rad/s for a joint).
    measured, predicted : numpy.ndarray
        The measured and predicted force, in ``unit``.
    rmse : float
        The root mean square of predicted minus measured (less the run's own mean under the "per-experiment"
        offset policy), in ``unit``.
    nrmse : float
        ``rmse`` over the measured force's span [-].
    max_error_pct : float
        100 times the largest absolute error over the measured force's span [%].
    max_error : float
        The largest absolute error, in ``unit``.
    bias : float
        The mean of predicted minus measured, in ``unit``.
    unit : str
        "N" or "N m".
    fit_quality : dict, optional
        A fit experiment's residuals against the noise estimated from the data.
    """

    file: str
    temperature: float
    role: str
    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    measured: np.ndarray
    predicted: np.ndarray
    rmse: float
    nrmse: float
    max_error_pct: float
    bias: float
    unit: str
    fit_quality: dict | None = None
    #: max |error| in the data's unit (max_error_pct is it over the range: kept for readers, not shown)
    max_error: float = math.nan

    def metrics(self) -> dict:
        # "rmse": the name this metric had before it was named as displacement's is (kept for readers of
        # earlier results; docs/formats.md)
        return {"file": self.file, "temperature": self.temperature, "role": self.role,
                "rmse_offset_removed": self.rmse, "rmse": self.rmse, "nrmse": self.nrmse,
                "max_error_pct": self.max_error_pct, "max_error": self.max_error, "bias": self.bias, "unit": self.unit,
                "fit_quality": self.fit_quality}


def force_start(experiments, kind: str = "lugre", plant: PrescribedMotion | None = None, screen: bool = True,
                progress=None) -> dict:
    """A [friction] section of ``kind`` with starting values read off the data (measurements/force_start.py:
    read_start), screened.

    Of the data-derived starts, the one whose short fit on the data ends lowest (:func:`screened`): a fit from the
    wrong one ended at half the Coulomb level (issue 40). A rough start: the fit's multi-start spans a decade
    either way.

    Parameters
    ----------
    experiments : list of ForceExperiment
        The force experiments (a Dataset's fit experiments where a Dataset is given).
    kind : str, default "lugre"
        The friction model.
    plant : PrescribedMotion, optional
        The plant (its motion: linear or rotary).
    screen : bool, default True
        Whether to screen the starts by short fits (else the first, from the static map).
    progress : callable, optional
        Called with a line saying what is done.

    Returns
    -------
    dict
        The [friction] section: "model" and the starting values, in SI units.

    Raises
    ------
    InputError
        No experiment; a record at rest; an unknown friction model.
    """
    return start_section(experiments, kind, plant, screen, progress, force=Force)


def screened(experiments, candidates, plant=None, progress=None) -> dict:
    """The candidate [friction] section whose short fit on the data ends with the least misfit
    (measurements/force_start.py: screen_starts, each run's own offset profiled out)."""
    return screen_starts(experiments, candidates, plant, progress, force=Force)


def steady_state_curve(model: Model, velocities, temperature=None) -> np.ndarray:
    """The model's friction force in steady sliding at each of ``velocities``, by simulation (any friction model,
    any thermal form): a constant velocity held over thirty presliding lengths (g/stiffness), where the
    bristles have long settled. Without the sensor offset.

    Parameters
    ----------
    model : Model
        A prescribed-motion model.
    velocities : array_like
        The sliding velocities [m/s or rad/s]; 0 gives 0.
    temperature : float, optional
        The temperature [C]; default 25 C for the parameters, the model's own for the simulation.

    Returns
    -------
    numpy.ndarray
        The friction force [N or N m] at each velocity.

    Raises
    ------
    InputError
        A model or temperature ``simulate`` refuses.
    SolverError
        A simulation failed.
    """
    p = model.parameters_at(temperature if temperature is not None else 25.0)
    stiffness = p.get("sigma0") or (sum(p["k"]) if p.get("k") is not None else None)
    level = max(p.get("fc") or 0.0, p.get("fs") or 0.0)
    distance = 30.0 * level / stiffness if stiffness else 1e-9
    out = []
    for v in np.asarray(velocities, float):
        if v == 0:
            out.append(0.0)
            continue
        T = distance / abs(v)
        res = simulate(model, t_eval=np.array([0.0, T]), temperature=temperature,
                       input=Sampled(np.array([0.0, 2 * T]), np.array([0.0, 2 * T * v])),
                       controller=StepSizeController(rtol=1e-8))
        out.append(float(res.friction_force[-1]))
    return np.array(out)


__all__ = ["Force", "ForcePrediction", "steady_state_curve", "force_start", "screened", "FD_STEP", "FD_RTOL", "UNITS_CHECK", "SAMPLING_CHECK", "FIT_PARAMETERS"]
