"""Look-alike measured joint-torque experiments: data with the character of real joint and drive logs
(tests/data/README.md says what was measured on which public logs), made from a truth that does not use
thermofriction's friction models.

The truth is LuGre friction with **direction-dependent** Coulomb and static levels (``fc_pos``/``fc_neg``,
``fs_pos``/``fs_neg``), integrated here with SciPy (LSODA) under an analytic motion (a sum of sines), plus a
torque ripple periodic in the position (cogging, gear mesh). What the logger adds, each a parameter:

- irregular sample times around a nominal rate (``rate``, ``jitter``: a fraction of the interval);
- a position quantised by the encoder (``position_step``);
- a velocity column that is a firmware estimate: the true velocity ``lag`` seconds late, times
  ``velocity_scale``, quantised to ``velocity_step``;
- a per-run sensor offset (``offsets``, one per run: it also sets the number of runs);
- AR(1) noise on the torque (``rho``, ``noise``: its stationary standard deviation), then the torque quantised
  (``force_step``);
- optionally the torque's sign reversed (``reaction=True``: a reaction-torque sensor).

``lookalike_runs(...)`` returns the runs (arrays and their truth); ``write_dataset(folder, runs)`` writes a
dataset folder (rad, rad/s, N m, one CSV per run and dataset.toml); ``lookalike_dataset(folder, ...)`` does
both; ``lookalike_experiments(...)`` makes a thermofriction Dataset in memory (no files), loaded as a folder
would be (the motion chosen, the sign checked). Every default is a measured number (tests/data/README.md), so ``lookalike_runs()`` looks like the
OpenArm/CICESE logs; tests set what they study.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import tomli_w
from scipy.integrate import solve_ivp

from thermofriction.data.experiments import Dataset
from thermofriction.data.force import force_experiment


@dataclasses.dataclass(frozen=True)
class Truth:
    """The friction that made the data: LuGre with direction-dependent levels [N m, rad, s]:
    ``g(v) = fc_dir + (fs_dir - fc_dir) exp(-(v/vs)^2)``, ``z' = v - sigma0 |v| z / g(v)``,
    ``F = sigma0 z + sigma1 z' + sigma2 v`` (+ the position ripple ``ripple sin(2 pi x / ripple_period)``)."""

    fc_pos: float = 0.363
    fc_neg: float = 0.406
    fs_pos: float = 0.45
    fs_neg: float = 0.50
    vs: float = 0.08
    sigma0: float = 100.0
    sigma1: float = 0.5
    sigma2: float = 0.10
    ripple: float = 0.01
    ripple_period: float = 2 * math.pi / 50

    def g(self, v):
        v = np.asarray(v, float)
        fc = np.where(v >= 0, self.fc_pos, self.fc_neg)
        fs = np.where(v >= 0, self.fs_pos, self.fs_neg)
        return fc + (fs - fc) * np.exp(-(v / self.vs) ** 2)

    def steady(self, v):
        """The steady-sliding friction at constant velocity v (closed form; no ripple)."""
        v = np.asarray(v, float)
        return np.sign(v) * self.g(v) + self.sigma2 * v


@dataclasses.dataclass
class Run:
    """One look-alike run: what the logger wrote (``time``, ``position``, ``velocity``, ``force``) and the
    truth (``true_position``, ``true_velocity``, ``true_force``: friction without offset or noise), its
    ``offset`` and its noise (``noise``, AR(1) before quantisation)."""

    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    force: np.ndarray
    true_position: np.ndarray
    true_velocity: np.ndarray
    true_force: np.ndarray
    offset: float
    noise: np.ndarray
    role: str = "fit"
    temperature: float = 25.0


def sample_times(n, rate, jitter, rng):
    """``n`` strictly increasing times at ``rate`` on average, each interval ``(1 + jitter u)/rate`` with u
    uniform in [-1, 1] (a UART or USB logger's uneven cycle); starting at 0."""
    dt = (1.0 + jitter * rng.uniform(-1.0, 1.0, n - 1)) / rate
    return np.concatenate([[0.0], np.cumsum(dt)])


def motion(t, amplitude, frequency, harmonic=0.3):
    """(position, velocity) of ``amplitude (sin(w t) + harmonic sin(2 w t + 0.7)) / (1 + harmonic)``: a smooth
    back-and-forth with unequal halves, analytic."""
    w = 2 * math.pi * frequency
    s = amplitude / (1.0 + harmonic)
    x = s * (np.sin(w * t) + harmonic * np.sin(2 * w * t + 0.7)) - s * harmonic * math.sin(0.7)
    v = s * w * (np.cos(w * t) + 2 * harmonic * np.cos(2 * w * t + 0.7))
    return x, v


def true_friction(truth: Truth, t, amplitude, frequency, harmonic=0.3, rtol=1e-9, start=0.0):
    """The truth's friction at times ``t`` under :func:`motion` from the angle ``start``, the bristles at rest at
    t = 0: LuGre integrated by SciPy's LSODA (stiff where the bristles are), the ripple added at the absolute
    angle. (absolute position, velocity, F)."""
    def vel(tt):
        return motion(np.asarray(tt, float), amplitude, frequency, harmonic)[1]

    def rhs(tt, z):
        v = float(vel(tt))
        return [v - truth.sigma0 * abs(v) * z[0] / float(truth.g(v))]

    def jac(tt, z):
        v = float(vel(tt))
        return [[-truth.sigma0 * abs(v) / float(truth.g(v))]]

    zmax = max(truth.fs_pos, truth.fs_neg, truth.fc_pos, truth.fc_neg) / truth.sigma0
    sol = solve_ivp(rhs, (float(t[0]), float(t[-1])), [0.0], method="LSODA", t_eval=t, rtol=rtol,
                    atol=1e-9 * zmax, jac=jac, max_step=0.25 / frequency / 20)
    if not sol.success:
        raise RuntimeError(sol.message)
    z = sol.y[0]
    x, v = motion(t, amplitude, frequency, harmonic)
    x = x + start
    zdot = v - truth.sigma0 * np.abs(v) * z / truth.g(v)
    F = truth.sigma0 * z + truth.sigma1 * zdot + truth.sigma2 * v
    return x, v, F + truth.ripple * np.sin(2 * math.pi * x / truth.ripple_period)


def ar1(n, rho, sd, rng):
    """AR(1) noise, stationary: e[k] = rho e[k-1] + sqrt(1 - rho^2) sd w[k], e[0] ~ N(0, sd^2)."""
    w = rng.normal(0.0, sd, n)
    e = np.empty(n)
    e[0] = w[0]
    c = math.sqrt(1.0 - rho * rho)
    for k in range(1, n):
        e[k] = rho * e[k - 1] + c * w[k]
    return e


def _quantise(a, step):
    return np.round(a / step) * step if step else np.asarray(a, float)


def lookalike_runs(*, truth: Truth = Truth(), offsets=(0.02, -0.015, 0.03), roles=None, temperatures=None,
                   rate=66.7, jitter=0.1, duration=8.0, amplitude=0.6, frequency=0.25, lag=0.005,
                   velocity_scale=1.0, velocity_step=0.0098, position_step=3.834e-4, force_step=0.0137,
                   noise=0.02, rho=0.5, reaction=False, seed=0, start_angles=None, relative=False) -> list:
    """Look-alike runs, one per entry of ``offsets`` (the sensor offset of each run [N m]); run k moves with
    amplitude ``amplitude (1 + 0.15 k)`` [rad] and frequency ``frequency (1 + 0.1 k)`` [Hz] so that runs
    differ. ``roles`` (default: the last run "validate" when there are three or more, the others "fit") and
    ``temperatures`` [C] (default 25) per run. Steps of 0 mean no quantisation. Every default is measured
    (tests/data/README.md). ``start_angles`` [rad]: the joint's absolute angle where each run starts (default 0),
    the ripple's argument; the recorded position is that absolute angle, or with ``relative`` the angle moved
    since the run's start (an encoder zeroed per run, no homing)."""
    rng = np.random.default_rng(seed)
    k_runs = len(offsets)
    if roles is None:
        roles = ["fit"] * k_runs if k_runs < 3 else ["fit"] * (k_runs - 1) + ["validate"]
    temperatures = [25.0] * k_runs if temperatures is None else list(temperatures)
    runs = []
    for k, offset in enumerate(offsets):
        n = int(round(duration * rate)) + 1
        t = sample_times(n, rate, jitter, rng)
        A, f = amplitude * (1 + 0.15 * k), frequency * (1 + 0.1 * k)
        x0 = 0.0 if start_angles is None else float(start_angles[k])
        x, v, F = true_friction(truth, t, A, f, start=x0)
        x = x - x0 if relative else x
        v_late = motion(t - lag, A, f)[1]
        e = ar1(n, rho, noise, rng)
        sign = -1.0 if reaction else 1.0
        runs.append(Run(time=t, position=_quantise(x, position_step),
                        velocity=_quantise(velocity_scale * v_late, velocity_step),
                        force=_quantise(sign * (F + offset + e), force_step), true_position=x, true_velocity=v,
                        true_force=F, offset=float(offset), noise=e, role=roles[k], temperature=float(temperatures[k])))
    return runs


def write_dataset(folder, runs, *, velocity=True, manifest_extra=None, entry_extra=None) -> Path:
    """A dataset folder of ``runs``: ``run{k}.csv`` (time[s], position[rad], velocity[rad/s] when ``velocity``,
    friction_torque[N*m]) and dataset.toml, with ``manifest_extra`` keys at its top and ``entry_extra`` in every
    [[experiment]] entry."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    entries = []
    for k, r in enumerate(runs):
        head = ["time[s]", "position[rad]"] + (["velocity[rad/s]"] if velocity else []) + ["friction_torque[N*m]"]
        cols = [r.time, r.position] + ([r.velocity] if velocity else []) + [r.force]
        name = f"run{k}.csv"
        np.savetxt(folder / name, np.column_stack(cols), delimiter=",", header=",".join(head), comments="",
                   fmt="%.12g")
        entries.append({"file": name, "temperature": r.temperature, "role": r.role, **(entry_extra or {})})
    (folder / "dataset.toml").write_text(tomli_w.dumps({"name": "lookalike", **(manifest_extra or {}),
                                                        "experiment": entries}))
    return folder


def lookalike_dataset(folder, *, velocity=True, manifest_extra=None, entry_extra=None, **params):
    """(folder, runs): :func:`lookalike_runs` with ``params``, written by :func:`write_dataset`."""
    runs = lookalike_runs(**params)
    return write_dataset(folder, runs, velocity=velocity, manifest_extra=manifest_extra,
                         entry_extra=entry_extra), runs


def lookalike_experiments(*, motion="auto", flip_sign=False, **params):
    """(a thermofriction Dataset of ForceExperiments in memory, the runs): :func:`lookalike_runs` with
    ``params``, each run read as a dataset's force experiment would be (``motion`` chosen, ``flip_sign``
    applied, the sign checked), without files."""
    runs = lookalike_runs(**params)
    exps = []
    for k, r in enumerate(runs):
        columns = {"time": r.time, "position": r.position, "velocity": r.velocity, "force": r.force,
                   "rotary": True, "headers": {"time": "time[s]", "position": "position[rad]",
                                               "velocity": "velocity[rad/s]", "force": "friction_torque[N*m]"}}
        exps.append(force_experiment(f"lookalike run{k}", f"run{k}.csv", temperature=r.temperature, role=r.role,
                                     description="look-alike (tests/lookalike.py)", from_zero=lambda t, i: (t, i),
                                     motion=motion, flip_sign=flip_sign, columns=columns))
    return Dataset(name="lookalike", experiments=exps), runs
