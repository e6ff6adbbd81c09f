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
from dataclasses import dataclass, field

import numpy as np

from . import _bridge
from ._bridge import model_spec
from .errors import InputError, SolverError
from .models import MassPlant, Model


@dataclass(frozen=True)
class PID:
    """u = kp e + ki int e + kd de/dt (derivative filtered with time constant ``tau_d``), e = x_ref - x."""

    kp: float
    ki: float
    kd: float
    tau_d: float = 0.0


@dataclass(frozen=True)
class FeedForward:
    """u_ff = F(v_ref, T) from ``model`` told ``temperature`` (None: the stage's, i.e. measured)."""

    model: Model
    temperature: float | None = None
    kind = "feedforward"


@dataclass(frozen=True)
class Observer:
    """Canudas de Wit et al. (1995): z^' = v - sigma0 |v| z^/g(v) - gain (x - x_ref),
    u_c = sigma0 z^ + sigma1 z^' + sigma2 v, from ``model`` told ``temperature`` (None: measured)."""

    model: Model
    gain: float = 100.0
    temperature: float | None = None
    kind = "observer"


@dataclass(frozen=True)
class Reference:
    """A position reference sampled at the control period: time, position x_ref, velocity v_ref."""

    name: str
    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray


def sine_reference(amplitude: float, frequency: float, duration: float, dt: float = 1e-4) -> Reference:
    """x_ref = amplitude (1 - cos(2 pi f t)): starts at rest at 0, reverses every half period."""
    t = np.arange(int(round(duration / dt)) + 1) * dt
    w = 2 * math.pi * frequency
    return Reference(f"sine {amplitude * 1e3:g} mm, {frequency:g} Hz", t, amplitude * (1 - np.cos(w * t)),
                     amplitude * w * np.sin(w * t))


def point_to_point(distance: float, move_time: float, dwell: float, dt: float = 1e-4) -> Reference:
    """A quintic (minimum-jerk) move of ``distance`` in ``move_time``, a dwell, and back the same way."""
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
class LoopResult:
    """One closed-loop run, per control period (plain arrays, SI)."""

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


#: Gains for the stage-model-i preset (1 kg): ~30 Hz bandwidth, well damped, at 10 kHz.
DEFAULT_PID = PID(kp=4e4, ki=4e5, kd=280.0, tau_d=2e-4)


def simulate_loop(stage: Model, reference: Reference, *, temperature: float, pid: PID = DEFAULT_PID,
                  compensation: FeedForward | Observer | None = None, substeps: int = 10) -> LoopResult:
    """The closed loop of control.h: the C core runs every control period (fixed step, ``reference``'s
    sampling) and ``substeps`` plant steps within it."""
    if not isinstance(stage.plant, MassPlant):
        raise InputError("the closed loop drives a single-mass stage: the model's plant must be 'mass'")
    dt = float(reference.time[1] - reference.time[0])
    x_ref = np.ascontiguousarray(reference.position, float)
    v_ref = np.ascontiguousarray(reference.velocity, float)
    outs = [np.empty_like(x_ref) for _ in range(3)]
    comp_spec, T_comp, kind, gain = None, math.nan, "none", 0.0
    if compensation is not None:
        T_comp = temperature if compensation.temperature is None else compensation.temperature
        comp_spec = model_spec(compensation.model, T_comp)
        kind = compensation.kind
        gain = float(getattr(compensation, "gain", 0.0))
    status = _bridge.loop(model_spec(stage, temperature), temperature, comp_spec, T_comp, kind, gain,
                          stage.plant.mass, (pid.kp, pid.ki, pid.kd, pid.tau_d), dt, substeps, x_ref, v_ref, *outs)
    if status != "ok":
        raise SolverError("the closed loop went unstable (non-finite position): lower the gains or the control period")
    return LoopResult(reference.time, x_ref, outs[0], outs[1], outs[2])


def friction_steps(model: Model, velocity, dt: float, temperature: float | None = None):
    """The real-time model (realtime.h: tf_rt_step) stepped at ``dt`` through the sliding velocities
    ``velocity`` (one per step, held over it) at ``temperature`` (a number, or one per step):
    returns (forces, seconds spent in C)."""
    v = np.ascontiguousarray(velocity, float)
    F = np.empty_like(v)
    if temperature is None or np.ndim(temperature) == 0:
        T = math.nan if temperature is None else float(temperature)
        spec_T = temperature
    else:  # one temperature per step
        T = np.ascontiguousarray(temperature, float)
        spec_T = float(T[0])
    seconds = _bridge.rt_steps(model_spec(model, spec_T), T, v, dt, F)
    return F, seconds


def compare_compensation(stage: Model, references, temperatures=(30.0, 41.5), calibration: float = 30.0,
                         observer_gain: float = 100.0, pid: PID = DEFAULT_PID):
    """Tracking errors with no compensation, temperature-blind compensation (the model told
    ``calibration``) and temperature-aware compensation (told the stage's temperature), feed-forward
    and observer, for each reference and stage temperature. Returns a list of row dicts."""
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


__all__ = ["PID", "FeedForward", "Observer", "Reference", "sine_reference", "point_to_point", "LoopResult",
           "simulate_loop", "compare_compensation", "friction_steps", "DEFAULT_PID"]
