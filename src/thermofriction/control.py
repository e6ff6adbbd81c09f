"""Friction compensation in a position control loop, on the C core's real-time API (control.h).

    loop = tf.control.simulate_loop(stage, tf.control.sine_reference(1e-3, 0.5, 4.0), temperature=41.5,
                                    compensation=tf.control.FeedForward(model, temperature=41.5))
    loop.rms_error, loop.max_error

A single-mass stage ``m x'' = u - F`` (its friction model, with its thermal extension, at the
stage's ``temperature``: one value, or one per control period as it warms; and, for laws of the load, at its
``load``, the same way) under a PID at the control period ``dt``, plus optional compensation: ``FeedForward``
(the friction model driven by the reference velocity) or ``Observer`` (the LuGre observer of Canudas de Wit et
al. 1995), each told a temperature: the stage's (a perfect sensor), a fixed calibration temperature (blind), a
sensor's reading per period, or an online ``TemperatureEstimator``'s estimate from the friction a
``DisturbanceObserver`` measures; and told a load: the stage's, a sensor's per period, or a constant (load-blind).
The parts are in ``compensation.py``, the references in ``references.py``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from . import _args, _bridge
from ._bridge import model_spec
from .compensation import (DEFAULT_PID, OBSERVED_MODELS, PID, DisturbanceObserver, FeedForward, Observer, _check_at,
                           _model, _number, _samples)
from .errors import InputError, SolverError, shorten
from .estimation import TemperatureEstimate, TemperatureEstimator
from .figures.study_plots import loop_figure
from .models import MassPlant, Model
from .models.load_laws import load_laws
from .simulation.loads import as_load, load_findings
# MAX_REFERENCE_SAMPLES: its name here, as before the split
from .references import MAX_REFERENCE_SAMPLES, Reference, duty_cycle, point_to_point, sine_reference  # noqa: F401
from .results import Result, Summary


@dataclass(eq=False)
class LoopResult(Result):
    """One closed-loop run, per control period (plain arrays, SI, temperatures in C).

    Parameters
    ----------
    time : numpy.ndarray
        The control instants [s].
    reference, position : numpy.ndarray
        x_ref and the stage's x [m].
    control : numpy.ndarray
        The controller's force [N], compensation included.
    compensation : numpy.ndarray
        The friction compensation's share [N].
    plant_friction : numpy.ndarray, optional
        The stage's friction, mean over each period [N].
    plant_temperature : numpy.ndarray, optional
        The stage's temperature [C].
    compensation_temperature : numpy.ndarray, optional
        The temperature the compensation was told [C] (NaN without compensation or estimator).
    temperature_variance : numpy.ndarray, optional
        The estimator's variance of it [K^2]; None without an estimator.
    measured_friction : numpy.ndarray, optional
        The disturbance observer's friction the estimator read [N] (NaN: none); None without an estimator.
    stats : dict, default {}
        The run's costs.
    plant_load, compensation_load : numpy.ndarray, optional
        The stage's load and the load the compensation was told [N or N m], per period; None where the model
        has no law of the load.
    """

    time: np.ndarray
    reference: np.ndarray
    position: np.ndarray
    control: np.ndarray
    compensation: np.ndarray
    plant_friction: np.ndarray | None = None
    plant_temperature: np.ndarray | None = None
    compensation_temperature: np.ndarray | None = None
    temperature_variance: np.ndarray | None = None
    measured_friction: np.ndarray | None = None
    stats: dict = field(default_factory=dict)
    plant_load: np.ndarray | None = None
    compensation_load: np.ndarray | None = None

    @property
    def error(self) -> np.ndarray:
        return self.reference - self.position

    @property
    def rms_error(self) -> float:
        return float(np.sqrt(np.mean(self.error ** 2)))

    @property
    def max_error(self) -> float:
        return float(np.max(np.abs(self.error)))

    @property
    def friction_error(self) -> np.ndarray | None:
        """The compensation minus the stage's friction [N] (None when the run did not record the friction)."""
        return None if self.plant_friction is None else self.compensation - self.plant_friction

    @property
    def temperature_error(self) -> np.ndarray | None:
        """The compensation's temperature minus the stage's [C] (NaN without compensation or estimator)."""
        if self.plant_temperature is None or self.compensation_temperature is None:
            return None
        return self.compensation_temperature - self.plant_temperature

    title = "closed-loop run"

    def summary(self) -> Summary:
        rows = [("duration", f"{self.time[-1] - self.time[0]:.6g} s"), ("samples", f"{len(self.time)}"),
                ("RMS error", f"{self.rms_error * 1e6:.4g} um"), ("max error", f"{self.max_error * 1e6:.4g} um")]
        if self.friction_error is not None and np.any(self.compensation):
            rows.append(("RMS friction-estimate error", f"{_rms(self.friction_error):.4g} N"))
        dT = self.temperature_error
        if dT is not None and np.all(np.isfinite(dT)):
            rows += [("RMS temperature-estimate error", f"{_rms(dT):.4g} K"),
                     ("max temperature-estimate error", f"{np.max(np.abs(dT)):.4g} K")]
        return Summary(rows)

    def _frame(self) -> dict:
        frame = {"time": self.time, "reference": self.reference, "position": self.position, "error": self.error,
                 "control": self.control, "compensation": self.compensation}
        for name in ("plant_friction", "plant_temperature", "compensation_temperature", "temperature_variance",
                     "measured_friction", "plant_load", "compensation_load"):
            if getattr(self, name) is not None:
                frame[name] = getattr(self, name)
        return frame

    def to_dict(self) -> dict:
        return {"summary": dict(self.summary()), "rms_error": self.rms_error, "max_error": self.max_error,
                "stats": self.stats, "samples": self._frame()}

    def plot(self):
        """A matplotlib figure: reference and position, and the tracking error, against time; with
        compensation, the friction-estimate error, and the temperature-estimate error where the
        compensation's temperature was not the stage's."""
        return loop_figure(self)


def _rms(a) -> float:
    return float(np.sqrt(np.mean(np.square(a))))


def _plant_temperature(where: str, stage: Model, temperature, n: int):
    """The stage's temperature: (the first value, the per-period array or None)."""
    if np.ndim(temperature) == 0:
        return _number(where, "temperature", temperature), None
    series = _samples(where, "temperature", temperature, n)
    return float(series[0]), series


def _per_period(where: str, name: str, value, n: int):
    """A number or one value per period: (the first value, the per-period array or None); None: (NaN, None)."""
    if value is None:
        return math.nan, None
    if np.ndim(value) == 0:
        return _number(where, name, value), None
    series = _samples(where, name, value, n)
    return float(series[0]), series


def _check_inputs(where: str, model: Model, t, T, T_series, L, L_series):
    """The model at the extremes of its temperatures and, with a law of the load, of its loads (the core checks
    every period's), with the simulator's messages."""
    Ts = sorted({T} if T_series is None else {float(T_series.min()), float(T_series.max())})
    if not load_laws(model):
        for Ti in Ts:
            _check_at(where, model, Ti)
        return
    load = None if L_series is None and math.isnan(L) else L if L_series is None else as_load((t, L_series))
    try:
        load_findings(model, Ts, load)
    except InputError as e:
        raise InputError(f"{where}: {e}") from None


def _estimator_inputs(where, comp, n, T_plant, *, ambient, start, start_variance, proxy_temperature,
                      friction_measurement):
    """The binding's estimator tuple for a compensation told a TemperatureEstimator, and its start."""
    est = comp.temperature
    T_amb = T_plant if ambient is None else _number(where, "ambient", ambient)
    T0 = T_amb if start is None else _number(where, "start", start)
    var0 = _number(where, "start_variance", start_variance, positive=True)
    if not isinstance(friction_measurement, DisturbanceObserver):
        raise InputError(f"{where}: friction_measurement must be a DisturbanceObserver, "
                         f"got {type(friction_measurement).__name__}")
    T_p = None
    if proxy_temperature is not None:
        if est.proxy == "none":
            raise InputError(f"{where}: proxy_temperature given, but the estimator has no proxy (proxy='none')")
        try:
            T_p = np.ascontiguousarray(proxy_temperature, float)
        except (TypeError, ValueError, OverflowError):
            T_p = None
        if T_p is None or T_p.shape != (n,) or np.any(np.isinf(T_p)):
            raise InputError(f"{where}: proxy_temperature must have one value per period ({n}), finite or NaN")
    if not load_laws(comp.model):  # with one, checked at the compensation's load (_compensation_inputs)
        _check_at(f"{where}: the estimator's start", comp.model, T0)
    return (model_spec(comp.model, T0), est.config(), T0, var0, T_amb, T_p, friction_measurement.noise(n),
            friction_measurement.filter_time), T0


def _compensation_inputs(where, comp, t, T_plant, T_series, L_plant, L_series, **estimation):
    """(spec, T_comp, T_comp_series, estimator tuple, L_comp, L_comp_series) of the compensation for the binding."""
    n = t.size
    if comp is None:
        return None, math.nan, None, None, math.nan, None
    told, est, series = comp.temperature, None, None
    name = {"feedforward": "feed-forward"}.get(comp.kind, comp.kind)
    if isinstance(told, TemperatureEstimator):
        est, T = _estimator_inputs(where, comp, n, T_plant, **estimation)
    elif told is None:
        T, series = T_plant, T_series  # a perfect sensor
    elif np.ndim(told):
        if told.size != n:
            raise InputError(f"{where}: the {name} compensation's temperature must have one value per period "
                             f"({n}), got {told.size}")
        T, series = float(told[0]), told
    else:
        T = told
    L, L_series = (L_plant, L_series) if comp.load is None else _per_period(where, f"the {name} compensation's load",
                                                                           comp.load, n)
    if est is not None and load_laws(comp.model):
        if L_series is None and math.isnan(L):
            raise InputError(f"{where}: the {name} compensation's model has a law of the load "
                             f"({', '.join(load_laws(comp.model))}) and its estimator is told no load: give load=")
        _check_inputs(f"{where}: the estimator's start", comp.model, t, T, None, L, L_series)
    if est is None:
        _check_inputs(f"{where}: the {name} compensation's model", comp.model, t, T, series, L, L_series)
    return model_spec(comp.model, T), T, series, est, L, L_series


def _checked_reference(where: str, reference) -> tuple:
    if not isinstance(reference, Reference):
        raise InputError(f"{where}: reference must be a Reference (sine_reference, point_to_point, duty_cycle), "
                         f"got {type(reference).__name__}")
    t = _samples(where, "reference.time", reference.time)
    if t.size < 2:
        raise InputError(f"{where}: reference needs two samples or more, got {t.size}")
    x_ref = _samples(where, "reference.position", reference.position, t.size)
    v_ref = _samples(where, "reference.velocity", reference.velocity, t.size)
    dt = float(t[1] - t[0])
    if not (math.isfinite(dt) and dt > 0):
        raise InputError(f"{where}: reference.time must increase (control period {dt!r})")
    return t, x_ref, v_ref, dt


def simulate_loop(stage: Model, reference: Reference, *, temperature, pid: PID = DEFAULT_PID,
                  compensation: FeedForward | Observer | None = None, substeps: int = 10, ambient=None, start=None,
                  start_variance: float = 1.0, proxy_temperature=None,
                  friction_measurement: DisturbanceObserver = DisturbanceObserver(),
                  inertia_feedforward: bool = False, load=None) -> LoopResult:
    """The closed loop of control.h: the C core runs every control period (fixed step, ``reference``'s
    sampling) and ``substeps`` plant steps within it.

    Parameters
    ----------
    stage : Model
        The stage: a model with a single-mass plant.
    reference : Reference
        The position reference.
    temperature : float or array_like
        The stage's temperature [C]: one value, or one per control period (a warm-up).
    pid : PID, default DEFAULT_PID
        The feedback controller.
    compensation : FeedForward or Observer, optional
        The friction compensation; None: none. Its ``temperature`` says what it is told.
    substeps : int, default 10
        Plant steps per control period.
    ambient : float, optional
        With a ``TemperatureEstimator``: the ambient temperature [C]; None: the stage's first.
    start : float, optional
        With a ``TemperatureEstimator``: its start [C]; None: ``ambient`` (a stage started soaked).
    start_variance : float, default 1.0
        With a ``TemperatureEstimator``: the start's variance [K^2], > 0.
    proxy_temperature : array_like, optional
        With a ``TemperatureEstimator`` that has a proxy: the proxy sensor's reading per period [C] (NaN: none).
    friction_measurement : DisturbanceObserver, default DisturbanceObserver()
        With a ``TemperatureEstimator``: how the friction it reads is measured.
    inertia_feedforward : bool, default False
        Add the reference's inertia force, mass times the reference's mean acceleration over each period
        (computed-torque feed-forward), to the control. Without it a large, fast move's error is the PID's lag
        behind the acceleration, which can hide what the friction compensation does.
    load : float or array_like, optional
        The stage's load [N or N m]: one value, or one per control period (held over it), read by its laws of
        the load (required by a stage with one, ignored otherwise); a compensation told no load of its own
        (``FeedForward(..., load=None)``) is told this one.

    Returns
    -------
    LoopResult

    Raises
    ------
    InputError
        A stage that is not a single mass, a reference or argument of the wrong type or value, named; a
        model refused at a temperature or load it is told or the estimate (the period named); no load for a
        stage with a law of the load.
    SolverError
        The closed loop went unstable (a non-finite position), or the estimator overflowed.
    """
    where = "simulate_loop"
    _model(where, "stage", stage)
    if not isinstance(stage.plant, MassPlant):
        raise InputError("the closed loop drives a single-mass stage: the model's plant must be 'mass'")
    t, x_ref, v_ref, dt = _checked_reference(where, reference)
    T_plant, T_series = _plant_temperature(where, stage, temperature, t.size)
    L_plant, L_series = _per_period(where, "load", load, t.size)
    _check_inputs(f"{where}: the stage", stage, t, T_plant, T_series, L_plant, L_series)
    if not isinstance(pid, PID):
        raise InputError(f"{where}: pid must be a PID, got {type(pid).__name__}")
    if compensation is not None and not isinstance(compensation, (FeedForward, Observer)):
        raise InputError(f"{where}: compensation must be FeedForward, Observer or None, "
                         f"got {type(compensation).__name__}")
    _args.whole(substeps, f"{where}: substeps", low=1)
    if not isinstance(inertia_feedforward, (bool, np.bool_)):
        raise InputError(f"{where}: inertia_feedforward must be True or False, got {inertia_feedforward!r}")
    spec, T_comp, T_comp_series, est, L_comp, L_comp_series = _compensation_inputs(
        where, compensation, t, T_plant, T_series, L_plant, L_series, ambient=ambient, start=start, start_variance=start_variance,
        proxy_temperature=proxy_temperature, friction_measurement=friction_measurement)
    outs = [np.empty_like(x_ref) for _ in range(7)]
    if est is None:
        outs[5] = outs[6] = None
    kind = "none" if compensation is None else compensation.kind
    try:
        status = _bridge.loop(model_spec(stage, T_plant), T_plant, spec, T_comp, kind,
                              float(getattr(compensation, "gain", 0.0)), stage.plant.mass,
                              (pid.kp, pid.ki, pid.kd, pid.tau_d), dt, int(substeps), x_ref, v_ref, outs,
                              T_plant_series=T_series, T_comp_series=T_comp_series, estimator=est,
                              inertia_feedforward=bool(inertia_feedforward), load_plant=L_plant, load_comp=L_comp,
                              load_plant_series=L_series, load_comp_series=L_comp_series)
    except ValueError as e:  # the core's own checks: the models at a period's temperature, the estimate
        raise InputError(f"{where}: the C core refused the loop: {e}") from None
    if status != "ok":
        raise SolverError("the closed loop went unstable (non-finite position or estimate): lower the gains or the "
                          "control period")
    T_stage = np.full(t.size, T_plant) if T_series is None else T_series
    loads = [None if not load_laws(m) else np.full(t.size, L) if s is None else s
             for m, L, s in ((stage, L_plant, L_series), (getattr(compensation, "model", stage), L_comp, L_comp_series))]
    return LoopResult(t, x_ref, outs[0], outs[1], outs[2], outs[3], T_stage, outs[4], outs[5], outs[6],
                      plant_load=loads[0], compensation_load=loads[1] if compensation is not None else None)


def friction_steps(model: Model, velocity, dt: float, temperature: float | None = None, load=None):
    """The real-time model (realtime.h: tf_rt_step) stepped at ``dt`` through the sliding velocities
    ``velocity`` (one per step, held over it) at ``temperature`` and ``load``.

    Parameters
    ----------
    model : Model
        The friction model.
    velocity : array_like
        The sliding velocity [m/s], one per step.
    dt : float
        The step [s], > 0.
    temperature : float or array_like, optional
        The temperature [C], one value or one per step; required for a thermal model.
    load : float or array_like, optional
        The load [N or N m], one value or one per step; required by a model with a law of the load (naming the
        law), ignored by one without.

    Returns
    -------
    tuple
        (forces [N] as a numpy.ndarray, seconds spent in C).

    Raises
    ------
    InputError
        An argument of the wrong type or value, named; a temperature where the model is invalid.
    SolverError
        The real-time step failed.
    """
    where = "friction_steps"
    _model(where, "model", model)
    if not isinstance(velocity, (list, tuple, np.ndarray)) or not len(velocity) or np.asarray(velocity).dtype.kind not in "iuf":
        raise InputError(f"{where}: velocity must be an array of numbers [m/s], one per step, got "
                         f"{type(velocity).__name__} {shorten(velocity)}")
    v = _samples(where, "velocity", velocity)
    dt = _number(where, "dt", dt, positive=True)
    F = np.empty_like(v)
    L = math.nan if load is None else (_number(where, "load", load) if np.ndim(load) == 0 else
                                       _samples(where, "load", load, v.size))
    if load_laws(model):
        return _load_steps(where, model, v, dt, temperature, load, L, F)
    if temperature is None or np.ndim(temperature) == 0:
        T = math.nan if temperature is None else _number(where, "temperature", temperature)
        if model.thermal is not None or temperature is not None:  # (the former: "give a temperature")
            _check_at(where, model, None if temperature is None else T)
        spec_T = None if temperature is None else T
    else:  # one temperature per step: the core checks the model at each new one
        T = _samples(where, "temperature", temperature, v.size)
        spec_T = float(T[0]) if T.size else None
    try:
        seconds = _bridge.rt_steps(model_spec(model, spec_T), T, v, dt, F)
    except FloatingPointError as e:
        raise SolverError(f"{where}: {_step_message(e, T)}") from None
    except ValueError as e:  # the core refused a step: the model at that step's temperature
        raise InputError(f"{where}: {_step_message(e, T)}") from None
    return F, seconds


def _load_steps(where, model, v, dt, temperature, load, L, F):
    """friction_steps of a model with a law of the load: checked over the temperatures' and loads' ranges (their
    extremes, as the simulator checks them), then stepped by the core."""
    if temperature is None:
        raise InputError(f"{where}: the model depends on temperature: give a temperature")
    T = _number(where, "temperature", temperature) if np.ndim(temperature) == 0 else \
        _samples(where, "temperature", temperature, v.size)
    Ts = [float(np.min(T)), float(np.max(T))]
    try:
        load_findings(model, Ts, None if load is None else as_load(L if np.ndim(L) == 0 else
                                                                   (np.arange(L.size, dtype=float), L)))
    except InputError as e:
        raise InputError(f"{where}: {e}") from None
    try:
        seconds = _bridge.rt_steps(model_spec(model, Ts[0], load=float(np.ravel(L)[0])), T, v, dt, F, L)
    except FloatingPointError as e:
        raise SolverError(f"{where}: {_step_message(e, T)}") from None
    except ValueError as e:  # the core refused a step: the model at that step's temperature and load
        raise InputError(f"{where}: {_step_message(e, T)}") from None
    return F, seconds


def _step_message(error, T) -> str:
    """The core's "step N: what" with the step's temperature and a sentence for a parameter name."""
    m = re.fullmatch(r"step (\d+): (.*)", str(error))
    if not m:
        return str(error)
    i, what = int(m.group(1)), m.group(2)
    Ti = float(T[i]) if np.ndim(T) else float(T)
    at = f" (T = {Ti:g} C)" if math.isfinite(Ti) else ""
    name = what.split(" ")[0]
    if name in _bridge.PARAMETERS or name == "dF":
        return f"the model is invalid at step {i}{at}: '{name}' is out of its domain{what[len(name):]}"
    return f"step {i}{at}: {what}"


def compare_compensation(stage: Model, references, temperatures=(30.0, 41.5), calibration: float = 30.0,
                         observer_gain: float = 100.0, pid: PID = DEFAULT_PID):
    """Tracking errors with no compensation, temperature-blind compensation (the model told
    ``calibration``) and temperature-aware compensation (told the stage's temperature), feed-forward
    and observer, for each reference and stage temperature.

    Parameters
    ----------
    stage : Model
        The stage (a single-mass plant).
    references : list of Reference
        The references tracked.
    temperatures : sequence of float, default (30.0, 41.5)
        The stage's temperatures [C].
    calibration : float, default 30.0
        The temperature [C] the blind compensation is told.
    observer_gain : float, default 100.0
        The observer's gain [1/s].
    pid : PID, default DEFAULT_PID
        The feedback controller.

    Returns
    -------
    list of dict
        One row per reference, temperature and compensation: ``reference``, ``temperature``,
        ``compensation``, ``rms_error`` [m], ``max_error`` [m], ``result`` (the LoopResult).

    Raises
    ------
    InputError
        An argument of the wrong type or value, named.
    SolverError
        A closed-loop run went unstable.
    """
    where = "compare_compensation"
    _model(where, "stage", stage)
    if not (isinstance(references, (list, tuple)) and references and all(isinstance(r, Reference) for r in references)):
        raise InputError(f"{where}: references must be a non-empty list of References (sine_reference, point_to_point), "
                         f"got {type(references).__name__} {shorten(references)}")
    temperatures = [float(T) for T in _args.number_list(temperatures, f"{where}: temperatures", "C")]
    _number(where, "calibration", calibration)
    _number(where, "observer_gain", observer_gain)
    if not isinstance(pid, PID):
        raise InputError(f"{where}: pid must be a PID, got {type(pid).__name__}")
    rows = []
    for ref in references:
        for T in temperatures:
            cases = [("none", None),
                     ("feed-forward, blind", FeedForward(stage, calibration)),
                     ("feed-forward, aware", FeedForward(stage)),
                     ("observer, blind", Observer(stage, observer_gain, calibration)),
                     ("observer, aware", Observer(stage, observer_gain))]
            for name, comp in cases:
                r = simulate_loop(stage, ref, temperature=T, pid=pid, compensation=comp)
                rows.append({"reference": ref.name, "temperature": T, "compensation": name,
                             "rms_error": r.rms_error, "max_error": r.max_error, "result": r})
    return rows


__all__ = ["OBSERVED_MODELS", "PID", "FeedForward", "Observer", "DisturbanceObserver", "Reference", "sine_reference",
           "point_to_point", "duty_cycle", "LoopResult", "simulate_loop", "compare_compensation", "friction_steps",
           "DEFAULT_PID", "TemperatureEstimator", "TemperatureEstimate"]
