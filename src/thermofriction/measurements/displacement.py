"""Displacement driven by a voltage (the stick-slip actuator of Li et al. 2009): the residuals are the
simulated end-effector displacement minus the measured one, each run about its own zero (a displacement
sensor's zero is arbitrary); the Jacobian comes from the C core's forward sensitivities."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import _bridge
from ..data.experiments import run_label
from ..drive import drive
from ..errors import InputError
from ..models import FRICTION_MODELS, require_actuator
from ..results import Finding, emit
from ..simulation import StepSizeController, simulate
from .base import Measurement, MetricWarning, Trace, center, thermal_check
from .displacement_start import displacement_initial
from ..fitting.quality import fit_quality

#: The parameters fitted by default for each friction model (docs/identification.md#friction-models; each
#: description's ``fitted``):
#: what sets the level and the presliding stiffness, which displacement data determine; the shape
#: parameters (delta, vd, v_smooth, GMS's element stiffnesses k and capacities w) are kept. A
#: parameter the initial model leaves unset or at zero (vs, sigma2) is kept too: fitted in log
#: space it needs a positive start, and zero means "not in the model". fs and z_ba are bound to
#: other parameters (fs >= fc, z_ba < fc/sigma0), which a step of the fit may break, and the engine
#: does not yet treat such a step as unphysical (it stops): they are kept unless named.
FIT_PARAMETERS = {name: cls.description.fitted["displacement"] for name, cls in FRICTION_MODELS.items()}


class Displacement(Measurement):
    """Displacement driven by a voltage: a stick-slip actuator's end effector; each run's zero removed.

    Parameters
    ----------
    offset : {"per-experiment"}, default "per-experiment"
        The only policy of displacement data: each run's own zero.

    Raises
    ------
    InputError
        Any other offset policy (it applies to force data).
    """

    name = "displacement"
    quantity = "displacement"
    plants = ("stick-slip",)
    fit_parameters = FIT_PARAMETERS
    offset = "per-experiment"
    methods = ("plant", "base", "model-i", "model-ii", "heat")
    removed = "each experiment's constant offset"

    @staticmethod
    def recognises(exp) -> bool:
        return True  # the default: a record of voltage and displacement

    def __init__(self, offset: str = "per-experiment"):
        if offset != "per-experiment":
            raise InputError(f"offset={offset!r} (--offset, --no-offset) applies to force data; displacement data "
                             f"remove each experiment's zero (per-experiment)")

    def unit(self, experiments=()) -> str:
        return "m"

    def initial_model(self, init, method, data, experiments, *, parameters=(), **options):
        """The method's preset, or a model file's plant with a LuGre start read off the data
        (measurements/displacement_start.py); ``parameters`` (the fitted names) are not needed here."""
        return displacement_initial(init, method, data, experiments, measurement=self, **options)

    def make_trace(self, exp, model) -> Trace:
        d = drive(exp, model, start="record")
        trace = Trace(run_label(exp), np.ascontiguousarray(exp.time, float), np.ascontiguousarray(exp.displacement, float),
                      d.temperature, d.waveform, getattr(exp, "role", "fit"), float(exp.temperature), self)
        if model.heat is not None:
            trace.measured_temperature = d.measured_temperature
            trace.initial_temperature = d.initial_temperature
        return trace

    def _run(self, problem, model, trace, theta, jac):
        """One trace's residuals (about their mean; then the temperature record's, weighted) and Jacobian."""
        out, sens = problem.simulate(model, trace, theta, jac)
        if out is None:
            return None, None
        S = S_T = None
        if jac:
            S = problem.in_names(sens[:, _bridge.state_index(model, "x_e"), :], model, trace)
            if model.heat is not None:
                S_T = sens[:, _bridge.state_index(model, "T"), :]
        r, S = center(out[:, _bridge.OUTPUT_COLUMN["displacement"]] - trace.measured, S)
        if trace.measured_temperature is not None:
            w = trace.temperature_weight
            r = np.concatenate([r, w * (out[:, _bridge.OUTPUT_COLUMN["temperature"]] - trace.measured_temperature)])
            if S is not None:
                S = np.concatenate([S, w * S_T])
        return r, S

    def residuals(self, problem, model, theta, jac):
        results = problem.run_all(lambda i: self._run(problem, model, problem.traces[i], theta, jac), jac)
        if any(r is None for r, _ in results):
            return None, None
        r = np.concatenate([r for r, _ in results])
        J = np.concatenate([S for _, S in results]) if jac else None
        return r, J

    def per_trace(self, problem, model, theta):
        return [self._run(problem, model, tr, theta, False)[0] for tr in problem.traces]

    def checks(self, model, traces) -> list:
        return ["check the displacement unit in the files' headers"] + thermal_check(model, traces)

    # -- validation --------------------------------------------------------------------------------
    columns = (("file", "file", "{}"), ("T [C]", "temperature", "{:.4g}"), ("role", "role", "{}"),
               ("max error [%]", "max_error_pct", "{:.3g}"), ("RMSE [nm]", "rmse_offset_removed", "{:.4g}"),
               ("NRMSE", "nrmse", "{:.3g}"), ("final error [%]", "final_error_pct", "{:+.3g}"),
               ("step error [%]", "step_error_pct", "{:.3g}"))
    column_scale = {"rmse_offset_removed": 1e9}
    validation_removed = "each experiment's constant offset (its mean error)"

    def check_model(self, model, experiments):
        require_actuator(model, "validate")

    caption = "RMSE: each experiment's constant offset removed; NRMSE = RMSE / measured span"
    footer = ("RMSE: each experiment's constant offset removed; NRMSE = RMSE / measured span; max error: "
              "100 max|error| / measured span; final error: of the net displacement; step error: mean per input "
              "period (docs/formats.md#validation-metrics)")

    def predict(self, model, exp, rtol=1e-8) -> "Prediction":
        """Simulates one experiment (at rtol 1e-8: predictions should carry no solver error worth
        mentioning next to a measurement's) and computes its metrics."""
        d = drive(exp, model, start="model")  # a self-heating model from its own T_0, else the record's start
        waveform = d.waveform
        res = simulate(d.model(model), t_eval=exp.time, temperature=d.temperature, input=waveform,
                       controller=StepSizeController(rtol=rtol))
        pred = res.displacement - res.displacement[0]
        meas = np.asarray(exp.displacement, float)
        meas = meas - _zero(meas, pred)
        err = pred - meas
        span = float(np.max(meas) - np.min(meas))
        # RMSE as identification measures it: about the mean offset (the sensor's zero is arbitrary)
        quality = fit_quality(err - err.mean(), meas)
        rmse = quality["rmse"]
        net = float(meas[-1] - meas[0])
        ms = step_sizes(exp.time, meas, waveform.period)
        ps = step_sizes(exp.time, pred, waveform.period)
        step_err = float(np.mean(np.abs(ps - ms))) if ms.size else math.nan
        mean_step = abs(float(np.mean(ms))) if ms.size else math.nan

        # a percentage of nothing is not a number: a measurement that does not move (a constant
        # displacement, a sensor that was off) has no span; dividing by a stand-in such as 1e-300
        # gave 1e297 % with no word of why
        def pct(value, scale, what):
            if scale > 0:
                return 100 * value / scale
            emit([Finding(MetricWarning, f"{run_label(exp)}: the measured {what} is zero: percentage errors "
                                         f"relative to it are undefined (NaN)")], stacklevel=3)
            return math.nan

        max_pct = pct(float(np.max(np.abs(err))), span, "displacement's span (it is constant)")
        return Prediction(run_label(exp), float(exp.temperature), getattr(exp, "role", "fit"), np.asarray(exp.time), meas,
                          pred, max_pct, rmse, rmse / span if span > 0 else math.nan,
                          pct(float(err[-1]), abs(net), "net displacement (it ends where it starts)") if span > 0
                          else math.nan,
                          pct(step_err, mean_step, "mean step per cycle") if ms.size and span > 0 else math.nan,
                          step_err, ms, ps, quality)

    def summary(self, predictions) -> dict:
        out = {}
        for role, ps in self.by_role(predictions):
            # an undefined (NaN) percentage, warned about, does not hide the others
            pcts = [p.max_error_pct for p in ps if not math.isnan(p.max_error_pct)]
            out[role] = {"max_error_pct": max(pcts) if pcts else math.nan,
                         "mean_max_error_pct": float(np.mean(pcts)) if pcts else math.nan,
                         "rmse_offset_removed": float(np.sqrt(np.mean([p.rmse ** 2 for p in ps]))),
                         "n": len(ps)}
        return out


def _zero(measured, predicted):
    """The measurement's zero (a sensor's zero is arbitrary): the offset that makes the first 1 % of
    the run agree with the prediction on average -- exact for a perfect model, robust to noise,
    and blind to the rest of the run, so it cannot hide errors that build up."""
    k = max(len(measured) // 100, 1)
    return float(np.mean(measured[:k] - predicted[:k]))


def step_sizes(time, x, period):
    """Displacement over each whole period, read off by linear interpolation at k * period.

    Parameters
    ----------
    time : numpy.ndarray
        The sample times [s], increasing.
    x : numpy.ndarray
        The displacement [m] at those times.
    period : float or None
        The input's period [s]; None: no periodic input.

    Returns
    -------
    numpy.ndarray
        The displacement [m] over each whole period in the record; empty without a period or a whole one.

    Raises
    ------
    None
        Nothing is checked (NumPy's errors for arrays that are not numbers).
    """
    if period is None:
        return np.empty(0)
    k0 = math.ceil(time[0] / period - 1e-9)
    k1 = math.floor(time[-1] / period + 1e-9)
    if k1 - k0 < 1:
        return np.empty(0)
    return np.diff(np.interp(np.arange(k0, k1 + 1) * period, time, x))


@dataclasses.dataclass
class Prediction:
    """One experiment: the measurement, the model's prediction and its metrics (docs/formats.md#validation-metrics).

    With ``e = x_sim - x_meas`` at each sample (both from zero) and ``span = max x_meas - min x_meas``:

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
    measured, predicted : numpy.ndarray
        The measured and the predicted displacement [m].
    max_error_pct : float
        ``100 max abs(e) / span`` [%]: Li et al.'s (2009) "maximum prediction error".
    rmse : float
        The root mean square of ``e`` with its mean removed [m] (the same definition as identification's).
    nrmse : float
        ``rmse / span`` [-].
    final_error_pct : float
        The final displacement's error relative to the measured net displacement, signed [%].
    step_error_pct : float
        ``step_error`` relative to the mean measured step [%].
    step_error : float
        The mean absolute difference of the steps per period [m]; NaN without a periodic input.
    measured_steps, predicted_steps : numpy.ndarray
        The steps per period [m] (``step_sizes``).
    fit_quality : dict, optional
        A fit experiment's residuals against the noise estimated from the data.
    """

    file: str
    temperature: float
    role: str
    time: np.ndarray
    measured: np.ndarray
    predicted: np.ndarray
    max_error_pct: float
    rmse: float                 # the mean offset removed: the same definition as identification's
    nrmse: float
    final_error_pct: float
    step_error_pct: float
    step_error: float
    measured_steps: np.ndarray
    predicted_steps: np.ndarray
    fit_quality: dict | None = None

    def metrics(self) -> dict:
        return {"file": self.file, "temperature": self.temperature, "role": self.role,
                "max_error_pct": self.max_error_pct, "rmse_offset_removed": self.rmse, "nrmse": self.nrmse,
                "final_error_pct": self.final_error_pct, "step_error_pct": self.step_error_pct,
                "step_error": self.step_error, "fit_quality": self.fit_quality}


DISPLACEMENT = Displacement()

__all__ = ["Displacement", "DISPLACEMENT", "Prediction", "step_sizes", "FIT_PARAMETERS"]
