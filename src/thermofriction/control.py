"""Friction compensation in a position control loop, on the C core's real-time API (control.h).

    loop = tf.control.simulate_loop(stage, tf.control.sine_reference(1e-3, 0.5, 4.0), temperature=41.5,
                                    compensation=tf.control.FeedForward(model, temperature=41.5))
    loop.rms_error, loop.max_error

A single-mass stage ``m x'' = u - F`` (its friction model, with its thermal extension, at the
stage's ``temperature``) under a PID at the control period ``dt``, plus optional compensation:
``FeedForward`` (the friction model driven by the reference velocity) or ``Observer`` (the LuGre
observer of Canudas de Wit et al. 1995), each told a temperature: the measured one
(temperature-aware) or a fixed calibration temperature (temperature-blind).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from . import _bridge
from ._bridge import model_spec
from . import _args
from .errors import InputError, SolverError, shorten
from .estimation import TemperatureEstimate, TemperatureEstimator
from .figures.study_plots import loop_figure
from .models import FRICTION_MODELS, MassPlant, Model
from .results import Result, Summary
from .simulation.checks import temperature_findings


# -- argument checks: the package's InputError naming the argument, before the C core sees it -----

def _number(where: str, name: str, value, *, minimum=None, positive=False) -> float:
    """A finite real number (not a string, not a bool), optionally > 0 or >= minimum (_args.number)."""
    return _args.number(value, f"{where}: {name}", minimum=minimum, positive=positive)


def _model(where: str, name: str, model) -> Model:
    if not isinstance(model, Model):
        raise InputError(f"{where}: {name} must be a thermofriction Model (e.g. tf.load_model(...)), "
                         f"got {type(model).__name__}")
    return model


def _samples(where: str, name: str, values, n=None) -> np.ndarray:
    """A 1-D array of finite floats (n of them when given)."""
    try:
        a = np.ascontiguousarray(values, float)
    except (TypeError, ValueError, OverflowError):  # (an int of 10**400 is no float)
        raise InputError(f"{where}: {name} must be an array of numbers") from None
    if a.ndim != 1 or (n is not None and a.size != n):
        raise InputError(f"{where}: {name} must be one-dimensional" + (f" with {n} values" if n is not None else "")
                         + f", got shape {a.shape}")
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise InputError(f"{where}: {name}[{bad[0]}] is {float(a[bad[0]])!r}: every value must be finite")
    return a


def _check_at(where: str, model: Model, temperature: float):
    """The model's domain at one temperature (Model I parameters, Model II's lambda), with the
    simulator's messages; its findings (calibrated range, passivity) are the simulator's business."""
    try:
        temperature_findings(model, temperature)
    except InputError as e:
        raise InputError(f"{where}: {e}") from None


#: The friction models with a bristle state for the observer to estimate.
OBSERVED_MODELS = tuple(n for n, c in FRICTION_MODELS.items() if c.description.bristle)


@dataclass(frozen=True)
class PID:
    """u = kp e + ki int e + kd de/dt (derivative filtered with time constant ``tau_d``), e = x_ref - x.

    Parameters
    ----------
    kp : float
        The proportional gain [N/m].
    ki : float
        The integral gain [N/(m s)].
    kd : float
        The derivative gain [N s/m].
    tau_d : float, default 0.0
        The derivative filter's time constant [s], >= 0 (0: unfiltered).

    Raises
    ------
    InputError
        A gain that is not a finite number, or a negative ``tau_d``, named.
    """

    kp: float
    ki: float
    kd: float
    tau_d: float = 0.0

    def __post_init__(self):
        for name in ("kp", "ki", "kd"):
            _number("PID", name, getattr(self, name))
        _number("PID", "tau_d", self.tau_d, minimum=0.0)


def _temperature(where: str, temperature):
    return None if temperature is None else _number(where, "temperature", temperature)


@dataclass(frozen=True)
class FeedForward:
    """u_ff = F(v_ref, T) from ``model`` told ``temperature`` (None: the stage's, i.e. measured).

    Parameters
    ----------
    model : Model
        The friction model used for compensation.
    temperature : float, optional
        The temperature [C] the model is told; None: the stage's (measured).

    Raises
    ------
    InputError
        Not a Model, or a temperature that is not a number, named.
    """

    model: Model
    temperature: float | None = None
    kind = "feedforward"

    def __post_init__(self):
        _model("FeedForward", "model", self.model)
        _temperature("FeedForward", self.temperature)


@dataclass(frozen=True)
class Observer:
    """Canudas de Wit et al. (1995): z^' = v - sigma0 |v| z^/g(v) - gain (x - x_ref),
    u_c = sigma0 z^ + sigma1 z^' + sigma2 v, from ``model`` told ``temperature`` (None: measured).

    The observer estimates a bristle deflection, so ``model`` must have one: LuGre, Dahl or
    elasto-plastic. Coulomb and Stribeck have no state to observe (use ``FeedForward``); GMS has one
    per element and no published observer. ``gain`` [1/s] >= 0 (0: no correction).

    Parameters
    ----------
    model : Model
        The model, with a LuGre, Dahl or elasto-plastic friction model.
    gain : float, default 100.0
        The observer gain [1/s], >= 0.
    temperature : float, optional
        The temperature [C] the model is told; None: the stage's (measured).

    Raises
    ------
    InputError
        Not a Model, a friction model without a bristle state, a negative gain, named.
    """

    model: Model
    gain: float = 100.0
    temperature: float | None = None
    kind = "observer"

    def __post_init__(self):
        _model("Observer", "model", self.model)
        kind = self.model.friction.model
        if kind not in OBSERVED_MODELS:
            raise InputError(f"Observer: the observer estimates a bristle state, which a {kind} model does not have "
                             f"(it needs a LuGre, Dahl or elasto-plastic model; use FeedForward for {kind})")
        _number("Observer", "gain", self.gain, minimum=0.0)
        _temperature("Observer", self.temperature)


@dataclass(frozen=True)
class Reference:
    """A position reference sampled at the control period: time, position x_ref, velocity v_ref.

    Parameters
    ----------
    name : str
        The reference's name in tables.
    time : numpy.ndarray
        The control instants [s].
    position : numpy.ndarray
        x_ref [m].
    velocity : numpy.ndarray
        v_ref [m/s].
    """

    name: str
    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray


#: the most samples of a reference (10 million: ~240 MB for its three arrays)
MAX_REFERENCE_SAMPLES = 10_000_000


def _check_length(where, duration, dt):
    if duration / dt > MAX_REFERENCE_SAMPLES:
        raise InputError(f"{where}: duration / dt = {duration / dt:.3g} samples, more than the limit of "
                         f"{MAX_REFERENCE_SAMPLES}: lengthen dt or shorten the reference")


def sine_reference(amplitude: float, frequency: float, duration: float, dt: float = 1e-4) -> Reference:
    """x_ref = amplitude (1 - cos(2 pi f t)): starts at rest at 0, reverses every half period.

    Parameters
    ----------
    amplitude : float
        [m]; the reference spans 0 to 2 amplitude.
    frequency : float
        [Hz], > 0.
    duration : float
        [s], > 0.
    dt : float, default 1e-4
        The control period [s], > 0.

    Returns
    -------
    Reference

    Raises
    ------
    InputError
        A value that is not a finite number or out of range, named; more samples than the limit.
    """
    where = "sine_reference"
    amplitude, frequency = _number(where, "amplitude", amplitude), _number(where, "frequency", frequency, positive=True)
    duration, dt = _number(where, "duration", duration, positive=True), _number(where, "dt", dt, positive=True)
    _check_length(where, duration, dt)
    t = np.arange(int(round(duration / dt)) + 1) * dt
    w = 2 * math.pi * frequency
    return Reference(f"sine {amplitude * 1e3:g} mm, {frequency:g} Hz", t, amplitude * (1 - np.cos(w * t)),
                     amplitude * w * np.sin(w * t))


def point_to_point(distance: float, move_time: float, dwell: float, dt: float = 1e-4) -> Reference:
    """A quintic (minimum-jerk) move of ``distance`` in ``move_time``, a dwell, and back the same way.

    Parameters
    ----------
    distance : float
        [m].
    move_time : float
        Each move's duration [s], > 0.
    dwell : float
        The rest between the moves [s], >= 0.
    dt : float, default 1e-4
        The control period [s], > 0.

    Returns
    -------
    Reference

    Raises
    ------
    InputError
        A value that is not a finite number or out of range, named; more samples than the limit.
    """
    where = "point_to_point"
    distance, move_time = _number(where, "distance", distance), _number(where, "move_time", move_time, positive=True)
    dwell, dt = _number(where, "dwell", dwell, minimum=0.0), _number(where, "dt", dt, positive=True)
    _check_length(where, 2 * (move_time + dwell), dt)
    n = int(round((2 * (move_time + dwell)) / dt)) + 1
    t = np.arange(n) * dt
    period = move_time + dwell
    x, v = np.zeros(n), np.zeros(n)
    for k, sign in ((0, 1.0), (1, -1.0)):
        s = np.clip((t - k * period) / move_time, 0.0, 1.0)
        inside = (t >= k * period) & (t <= k * period + move_time)
        x += sign * distance * (10 * s ** 3 - 15 * s ** 4 + 6 * s ** 5)
        v += np.where(inside, sign * distance * (30 * s ** 2 - 60 * s ** 3 + 30 * s ** 4) / move_time, 0.0)
    return Reference(f"point-to-point {distance * 1e3:g} mm in {move_time:g} s", t, x, v)


@dataclass(eq=False)
class LoopResult(Result):
    """One closed-loop run, per control period (plain arrays, SI).

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
    stats : dict, default {}
        The run's costs.
    """

    time: np.ndarray
    reference: np.ndarray
    position: np.ndarray
    control: np.ndarray
    compensation: np.ndarray
    stats: dict = field(default_factory=dict)

    @property
    def error(self) -> np.ndarray:
        return self.reference - self.position

    @property
    def rms_error(self) -> float:
        return float(np.sqrt(np.mean(self.error ** 2)))

    @property
    def max_error(self) -> float:
        return float(np.max(np.abs(self.error)))

    title = "closed-loop run"

    def summary(self) -> Summary:
        return Summary([("duration", f"{self.time[-1] - self.time[0]:.6g} s"), ("samples", f"{len(self.time)}"),
                        ("RMS error", f"{self.rms_error * 1e6:.4g} um"),
                        ("max error", f"{self.max_error * 1e6:.4g} um")])

    def _frame(self) -> dict:
        return {"time": self.time, "reference": self.reference, "position": self.position, "error": self.error,
                "control": self.control, "compensation": self.compensation}

    def to_dict(self) -> dict:
        return {"summary": dict(self.summary()), "rms_error": self.rms_error, "max_error": self.max_error,
                "stats": self.stats, "samples": self._frame()}

    def plot(self):
        """A matplotlib figure: reference and position, and the tracking error, against time."""
        return loop_figure(self)


#: Gains for the stage-model-i preset (1 kg): ~30 Hz bandwidth, well damped, at 10 kHz.
DEFAULT_PID = PID(kp=4e4, ki=4e5, kd=280.0, tau_d=2e-4)


def simulate_loop(stage: Model, reference: Reference, *, temperature: float, pid: PID = DEFAULT_PID,
                  compensation: FeedForward | Observer | None = None, substeps: int = 10) -> LoopResult:
    """The closed loop of control.h: the C core runs every control period (fixed step, ``reference``'s
    sampling) and ``substeps`` plant steps within it.

    Parameters
    ----------
    stage : Model
        The stage: a model with a single-mass plant.
    reference : Reference
        The position reference.
    temperature : float
        The stage's temperature [C].
    pid : PID, default DEFAULT_PID
        The feedback controller.
    compensation : FeedForward or Observer, optional
        The friction compensation; None: none.
    substeps : int, default 10
        Plant steps per control period.

    Returns
    -------
    LoopResult

    Raises
    ------
    InputError
        A stage that is not a single mass, a reference or argument of the wrong type or value, named.
    SolverError
        The closed loop went unstable (a non-finite position).
    """
    where = "simulate_loop"
    _model(where, "stage", stage)
    if not isinstance(stage.plant, MassPlant):
        raise InputError("the closed loop drives a single-mass stage: the model's plant must be 'mass'")
    if not isinstance(reference, Reference):
        raise InputError(f"{where}: reference must be a Reference (sine_reference, point_to_point), "
                         f"got {type(reference).__name__}")
    t = _samples(where, "reference.time", reference.time)
    if t.size < 2:
        raise InputError(f"{where}: reference needs two samples or more, got {t.size}")
    x_ref = _samples(where, "reference.position", reference.position, t.size)
    v_ref = _samples(where, "reference.velocity", reference.velocity, t.size)
    dt = float(t[1] - t[0])
    if not (math.isfinite(dt) and dt > 0):
        raise InputError(f"{where}: reference.time must increase (control period {dt!r})")
    temperature = _number(where, "temperature", temperature)
    if not isinstance(pid, PID):
        raise InputError(f"{where}: pid must be a PID, got {type(pid).__name__}")
    if compensation is not None and not isinstance(compensation, (FeedForward, Observer)):
        raise InputError(f"{where}: compensation must be FeedForward, Observer or None, "
                         f"got {type(compensation).__name__}")
    _args.whole(substeps, f"{where}: substeps", low=1)
    _check_at(f"{where}: the stage", stage, temperature)
    outs = [np.empty_like(x_ref) for _ in range(3)]
    comp_spec, T_comp, kind, gain = None, math.nan, "none", 0.0
    if compensation is not None:
        T_comp = temperature if compensation.temperature is None else compensation.temperature
        name = {"feedforward": "feed-forward"}.get(compensation.kind, compensation.kind)
        _check_at(f"{where}: the {name} compensation's model", compensation.model, T_comp)
        comp_spec = model_spec(compensation.model, T_comp)
        kind = compensation.kind
        gain = float(getattr(compensation, "gain", 0.0))
    try:
        status = _bridge.loop(model_spec(stage, temperature), temperature, comp_spec, T_comp, kind, gain,
                              stage.plant.mass, (pid.kp, pid.ki, pid.kd, pid.tau_d), dt, int(substeps), x_ref, v_ref,
                              *outs)
    except ValueError as e:  # the core's own checks (a backstop for the ones above)
        raise InputError(f"{where}: the C core refused the loop: {e}") from None
    if status != "ok":
        raise SolverError("the closed loop went unstable (non-finite position): lower the gains or the control period")
    return LoopResult(t, x_ref, outs[0], outs[1], outs[2])


def friction_steps(model: Model, velocity, dt: float, temperature: float | None = None):
    """The real-time model (realtime.h: tf_rt_step) stepped at ``dt`` through the sliding velocities
    ``velocity`` (one per step, held over it) at ``temperature``.

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


__all__ = ["OBSERVED_MODELS", "PID", "FeedForward", "Observer", "Reference", "sine_reference", "point_to_point", "LoopResult",
           "simulate_loop", "compare_compensation", "friction_steps", "DEFAULT_PID", "TemperatureEstimator",
           "TemperatureEstimate"]
