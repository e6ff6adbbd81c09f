"""Simulation: ``simulate(model, duration, temperature=..., input=...)`` on the C core.

Solvers are objects you pass in (``Dopri5()``, ``Rodas4()``, ``AutoSwitch()``), separate from the
step-size controller (``StepSizeController(rtol=..., atol=...)``). Results come on a uniform
output grid from the solver's dense output, with per-cycle step sizes for periodic inputs.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from . import _core
from ._io import atomic_write
from .errors import ConditioningWarning, InputError, PassivityWarning, SolverError, TemperatureRangeWarning
from .models import (GMS, PARAMETERS, PLANT_CODES, MassPlant, Model, ModelI, ModelII, PrescribedMotion, StickSlipPlant,
                     check_friction_values, dissipativity_violation)
from .waveforms import Sampled, Sawtooth, Step, Waveform, Zero

# ---------------------------------------------------------------------------------------------
# Solvers and the step-size controller
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Dopri5:
    """Dormand-Prince 5(4), explicit, 4th-order dense output. Best for non-stiff models."""

    code = 1
    name = "dopri5"


@dataclass(frozen=True)
class Rodas4:
    """Rodas4 (Hairer-Wanner), a 4(3) L-stable Rosenbrock method with analytic Jacobian and
    3rd-order dense output. For stiff models (stiff bristles, light end effectors)."""

    code = 2
    name = "rodas4"


@dataclass(frozen=True)
class AutoSwitch:
    """Dopri5 until its stiffness test fires, then Rodas4 for the rest of the run (default)."""

    code = 0
    name = "auto"


SOLVERS = {"auto": AutoSwitch, "dopri5": Dopri5, "rodas4": Rodas4}


@dataclass(frozen=True)
class StepSizeController:
    """Error control: a step is accepted when the RMS over states of
    ``err_i / (atol_i + rtol * |y_i|)`` is at most 1.

    ``atol=None`` scales the absolute tolerance to each state: ``rtol`` times its characteristic
    magnitude (stage stroke for positions, stroke x natural frequency for velocities, fc/sigma0
    for the bristle deflection), so that micrometre motions are controlled as tightly as metres.
    """

    rtol: float = 1e-6
    atol: float | tuple | None = None
    first_step: float | None = None
    max_step: float | None = None
    max_steps: int = 10_000_000

    def __post_init__(self):
        if not (isinstance(self.rtol, (int, float)) and 0 < self.rtol < 1):
            raise InputError(f"rtol must be between 0 and 1, got {self.rtol!r}")
        if self.max_steps < 1:
            raise InputError(f"max_steps must be positive, got {self.max_steps!r}")


# ---------------------------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------------------------

_CHANNELS = ("time", "input", "stage_displacement", "stage_velocity", "displacement", "velocity",
             "relative_displacement", "relative_velocity", "friction_force", "temperature")


@dataclass(eq=False)
class SimulationResult:
    """Plain arrays with named fields (SI units; temperature in degC).

    ``displacement``/``velocity`` are the driven body's (the end effector's, the mass's, or the
    prescribed motion); ``relative_displacement`` is x_e - x_p (the stage fields are None for
    plants without a stage); ``states`` holds the friction model's internal
    states (columns named by ``state_names``). For periodic inputs ``cycle_times`` are the
    period starts, ``step_sizes[k]`` the displacement over cycle k, ``mean_velocity`` the mean
    of the step sizes times the frequency. ``friction_work`` [J] is the friction force's work
    integral of |F v_r| dt from the start (with a heat model, or ``friction_work=True``; else
    None); with a heat model ``temperature`` is the interface temperature state."""

    time: np.ndarray
    input: np.ndarray
    stage_displacement: np.ndarray | None
    stage_velocity: np.ndarray | None
    displacement: np.ndarray
    velocity: np.ndarray
    relative_displacement: np.ndarray
    relative_velocity: np.ndarray
    friction_force: np.ndarray
    temperature: np.ndarray
    states: np.ndarray
    state_names: tuple
    state_units: tuple
    cycle_times: np.ndarray
    step_sizes: np.ndarray
    mean_velocity: float
    input_unit: str = "V"
    stats: dict = field(default_factory=dict)
    friction_work: np.ndarray | None = None

    def columns(self) -> dict:
        """The CSV columns of SPEC 7, header -> array."""
        cols = {
            "time[s]": self.time,
            f"input[{self.input_unit}]": self.input,
            "stage_displacement[m]": self.stage_displacement,  # stick-slip only (SPEC 7)
            "displacement[m]": self.displacement,
            "velocity[m/s]": self.velocity,
            "friction_force[N]": self.friction_force,
            "temperature[C]": self.temperature,
        }
        for j, (name, unit) in enumerate(zip(self.state_names, self.state_units)):
            cols[f"{name}[{unit}]"] = self.states[:, j]
        cols["friction_work[J]"] = self.friction_work
        return {k: v for k, v in cols.items() if v is not None}

    def to_dataframe(self):
        """A pandas DataFrame of every output (pandas is an optional dependency)."""
        try:
            import pandas as pd
        except ImportError:  # pragma: no cover - depends on the environment
            raise ImportError("to_dataframe() needs pandas: pip install 'thermofriction[dataframe]'") from None
        data = {name: getattr(self, name) for name in _CHANNELS if getattr(self, name) is not None}
        for j, name in enumerate(self.state_names):
            data[name] = self.states[:, j]
        if self.friction_work is not None:
            data["friction_work"] = self.friction_work
        return pd.DataFrame(data)

    def to_csv(self, path):
        """Writes the SPEC 7 simulation CSV atomically."""
        cols = self.columns()
        table = np.column_stack(list(cols.values()))
        with atomic_write(path, "w", newline="") as fh:
            fh.write(",".join(cols) + "\n")
            np.savetxt(fh, table, delimiter=",", fmt="%.12g")

    def _repr_html_(self):
        rows = [("samples", f"{len(self.time)}"), ("duration", f"{self.time[-1] - self.time[0]:.6g} s"),
                ("final displacement", f"{self.displacement[-1] * 1e6:.6g} µm"),
                ("peak friction force", f"{np.max(np.abs(self.friction_force)):.4g} N")]
        if self.step_sizes.size:
            rows += [("cycles", f"{self.step_sizes.size}"),
                     ("mean step per cycle", f"{self.step_sizes.mean() * 1e6:.6g} µm"),
                     ("mean velocity", f"{self.mean_velocity * 1e6:.6g} µm/s")]
        rows.append(("solver", f"{self.stats.get('solver', '?')}: {self.stats.get('steps', '?')} steps"))
        body = "".join(f"<tr><th style='text-align:left'>{k}</th><td>{v}</td></tr>" for k, v in rows)
        return f"<table><caption>SimulationResult</caption>{body}</table>"

    def __repr__(self):
        return (f"SimulationResult({len(self.time)} samples over {self.time[-1] - self.time[0]:.6g} s, "
                f"final displacement {self.displacement[-1]:.6g} m, {len(self.step_sizes)} cycles)")


# ---------------------------------------------------------------------------------------------
# The model as the C core sees it
# ---------------------------------------------------------------------------------------------

def core_spec(model: Model, temperature=None, input: Waveform | None = None, friction_work: bool = False) -> dict:
    """The dict the binding unpacks into a tf_model (see _core.c). With a heat model the
    temperature, if given, is the ambient one (a number)."""
    plant = model.plant
    c = k = T_em = m_e = k_s = v_0 = 0.0
    m = 1.0
    if isinstance(plant, StickSlipPlant):
        c, k, T_em = plant.physical()
        m, m_e = plant.mass, plant.end_effector_mass
    elif isinstance(plant, MassPlant):
        m, k_s, v_0 = plant.mass, plant.spring_stiffness, plant.pull_velocity
    values = {k_: v for k_, v in model.friction.values().items() if k_ not in model.friction.arrays}
    values.setdefault("fs", values.get("fc", 0.0))
    values.setdefault("vs", 1e-3)
    params = np.zeros(len(PARAMETERS))
    for i, name in enumerate(PARAMETERS):
        v = values.get(name)
        params[i] = 0.0 if v is None else v
    laws = None
    if isinstance(model.thermal, ModelI):
        laws = [model.thermal.laws[n]._core_tuple() if n in model.thermal.laws else None for n in PARAMETERS]
    T_const, T_t, T_v = math.nan, None, None
    heat = None
    if model.heat is not None:
        h = model.heat.resolved(temperature)
        heat = (h.heat_capacity, h.thermal_resistance, h.heat_fraction, h.ambient_temperature,
                h.initial_temperature, h.external_heat._core_tuple() if h.external_heat is not None else None)
    elif isinstance(temperature, Sampled):
        T_t, T_v = temperature.time, temperature.value
    elif temperature is not None:
        T_const = float(temperature)
    waveform = input if input is not None else (model.input or Zero())
    return {
        "plant": PLANT_CODES[plant.type], "m": m, "c": c, "k": k, "T_em": T_em, "m_e": m_e, "k_s": k_s, "v_0": v_0,
        "friction": model.friction.core_code, "params": params,
        "gms_k": np.array(model.friction.k, float) if isinstance(model.friction, GMS) else None,
        "gms_w": np.array(model.friction.w, float) if isinstance(model.friction, GMS) else None,
        "fs_follows_fc": int(getattr(model.friction, "fs", None) is None and "fs" not in model.laws),
        "thermal": 1 if isinstance(model.thermal, ModelI) else 2 if isinstance(model.thermal, ModelII) else 0,
        "laws": laws,
        "dF": model.thermal.dF._core_tuple() if isinstance(model.thermal, ModelII) else None,
        "dF_form": 1 if isinstance(model.thermal, ModelII) and model.thermal.form == "offset" else 0,
        "input": waveform._core_tuple(), "T_const": T_const, "T_t": T_t, "T_v": T_v,
        "heat": heat, "work": int(bool(friction_work)),
    }


def as_temperature(temperature):
    """A number, a ``Sampled`` signal, or a (times, values) pair -> number or Sampled."""
    if temperature is None or isinstance(temperature, Sampled):
        return temperature
    if isinstance(temperature, (tuple, list)) and len(temperature) == 2:
        return Sampled(np.asarray(temperature[0], float), np.asarray(temperature[1], float))
    try:
        T = float(temperature)
    except (TypeError, ValueError):
        raise InputError(f"temperature must be a number [degC] or (times, values), got {temperature!r}") from None
    if not math.isfinite(T):
        raise InputError(f"temperature must be finite, got {temperature!r}")
    return T


#: The plant's mechanical states, before the friction model's (C core order).
MECHANICAL_STATES = {"stick-slip": ("x_p", "v_p", "x_e", "v_e"), "mass": ("x", "v"), "prescribed": ()}


def check_prescribed_motion(waveform: Waveform):
    """Prescribed motion needs a continuous displacement: its slope is the sliding velocity."""
    if isinstance(waveform, Zero):
        raise InputError("prescribed motion needs an input waveform, the displacement x_r(t) in metres "
                         "(e.g. --input sine:amplitude=1e-6,frequency=1)")
    if isinstance(waveform, Step) and waveform.slew <= 0:
        raise InputError("prescribed motion: an ideal step has no finite velocity; give the step a slew time")
    if isinstance(waveform, Sawtooth) and waveform.rise in (0.0, 1.0):
        raise InputError("prescribed motion: a sawtooth with rise 0 or 1 jumps; use 0 < rise < 1")


def check_passivity(model: Model, temperatures=(math.nan,)):
    """Warns (PassivityWarning) when a LuGre-type model can create energy at these temperatures."""
    for T in temperatures:
        found = dissipativity_violation(model.friction.model, model.parameters_at(T))
        if found:
            where = f" at {T:g} C" if isinstance(model.thermal, ModelI) else ""
            warnings.warn(f"{model.friction.model}{where}: {found[1]}", PassivityWarning, stacklevel=4)
            return


def check_temperatures(model: Model, temperature):
    """Warns for temperatures outside a law's calibrated range; raises where the model is
    invalid there (Model II's lambda <= 0, a Model I parameter out of its physical domain).
    Warns where a LuGre-type model is not dissipative."""
    if model.thermal is None:
        check_passivity(model)
        return
    if temperature is None:
        raise InputError("the model depends on temperature: give a temperature (e.g. --temperature 35)")
    if isinstance(temperature, Sampled):
        lo, hi = float(temperature.value.min()), float(temperature.value.max())
        Ts = np.unique(np.concatenate([temperature.value, np.linspace(lo, hi, 201)]))
    else:
        Ts = np.array([float(temperature)])
    laws = dict(model.laws)
    if isinstance(model.thermal, ModelII):
        laws["dF"] = model.thermal.dF
    outside = [f"'{name}' ({law.range[0]:g}..{law.range[1]:g} C)" for name, law in laws.items()
               if not law.in_range(Ts)]
    if outside:
        span = f"{Ts[0]:g} C" if len(Ts) == 1 else f"{Ts.min():g}..{Ts.max():g} C"
        warnings.warn(f"temperature {span} is outside the calibrated range of the law(s) for "
                      f"{', '.join(outside)}", TemperatureRangeWarning, stacklevel=3)
    if isinstance(model.thermal, ModelI):
        for T in (Ts.min(), Ts.max()) if len(Ts) > 1 else Ts:
            check_friction_values(model.parameters_at(T), f"Model I at {T:g} C")
        if len(Ts) > 2:
            for name, law in model.laws.items():
                vals = law(Ts)
                if name in ("sigma0", "fc") and np.any(vals <= 0):
                    T_bad = Ts[np.argmax(vals <= 0)]
                    raise InputError(f"Model I: '{name}' is not positive at {T_bad:g} C ({law(T_bad):g})")
    check_passivity(model, (Ts.min(), Ts.max()) if isinstance(model.thermal, ModelI) else (math.nan,))
    if isinstance(model.thermal, ModelII) and model.thermal.form == "scale":
        lam = np.atleast_1d(model.thermal_factor(Ts))
        if np.any(lam <= 0):
            i = int(np.argmin(lam))
            raise InputError(f"Model II: lambda(T) = 1 + dF(T)/F_ref is {lam[i]:.4g} <= 0 at {Ts[i]:g} C "
                             f"(dF = {model.thermal.dF(Ts[i]):.4g} N, F_ref = fc = {model.reference_force():.4g} N): "
                             f"the thermal term would reverse friction")
    if isinstance(model.thermal, ModelII) and model.thermal.form == "offset":
        # dF(T) tanh(v / v_smooth) with dF < 0 is a negative damping dF/v_smooth near v = 0; stronger
        # than the bristles' own damping it makes the sticking state repelling (found by the
        # differential tests: the explicit solver needs rtol <= 1e-7 there, an L-stable one
        # finds another solution).
        dF = np.atleast_1d(model.thermal.dF(Ts))
        i = int(np.argmin(dF))
        p = model.parameters_at(Ts[i])
        # the base model's own damping at v = 0: bristle and viscous damping (models without
        # sigma1 have none), and for a static map the slope of its smoothed sign, fs / v_smooth
        damping = p.get("sigma1", 0.0) + p.get("sigma2", 0.0)
        what = "sigma1 + sigma2"
        if model.friction.model in ("coulomb", "stribeck"):
            damping += p["fs"] / p["v_smooth"]
            what = "sigma2 + fs/v_smooth"
        if dF[i] < 0 and -dF[i] / p["v_smooth"] > damping:
            warnings.warn(f"Model II offset form: dF = {dF[i]:.4g} N at {Ts[i]:g} C is anti-damped near v = 0 "
                          f"(dF/v_smooth = {dF[i] / p['v_smooth']:.3g} N s/m against {what} = "
                          f"{damping:.3g} N s/m); the solution is ill-conditioned: use Dopri5 with rtol <= 1e-8, "
                          f"or the scale form", ConditioningWarning, stacklevel=3)


def _check_heated_temperatures(model: Model, time, temperature):
    """With self-heating the temperature range is known only after the run: warn where it left a
    law's calibrated range, refuse a run that crossed a temperature where the model is invalid."""
    lo, hi = float(np.min(temperature)), float(np.max(temperature))
    try:
        check_temperatures(model, Sampled(np.array([0.0, 1.0]), np.array([lo, hi])) if hi > lo else lo)
    except InputError as e:
        raise SolverError(f"self-heating took the temperature to {lo:.4g}..{hi:.4g} C, where the model is "
                          f"invalid: {e}") from None


# ---------------------------------------------------------------------------------------------
# simulate
# ---------------------------------------------------------------------------------------------

#: Default limit on output samples: each takes ~8 x (8 + internal states) bytes of outputs and about
#: twice that at the peak (README "Speed": 184 MB for 1,000,001 samples), so 10 million need ~2 GB.
MAX_SAMPLES = 10_000_000


def _check_samples(n, max_samples, what):
    if max_samples is not None and n > max_samples:
        raise InputError(f"{n} output samples requested ({what}), above the limit of {max_samples} "
                         f"(~{n * 184 / 1e9:.3g} GB of memory): lower the duration or the sample rate, or raise "
                         f"the limit (--max-samples N; max_samples=N in Python, None for no limit)")


def _grid(duration, sample_rate, max_samples=MAX_SAMPLES):
    if not (duration > 0 and math.isfinite(duration)):
        raise InputError(f"duration must be a positive number of seconds, got {duration!r}")
    if not (sample_rate > 0 and math.isfinite(sample_rate)):
        raise InputError(f"sample rate must be positive, got {sample_rate!r}")
    x = duration * sample_rate * (1 + 1e-12)
    if not math.isfinite(x) or x >= 2.0 ** 62:
        raise InputError(f"duration {duration:g} s x sample rate {sample_rate:g} Hz is too many output samples: lower the duration or the sample rate")
    n = int(math.floor(x)) + 1
    _check_samples(n, max_samples, f"duration {duration:g} s x sample rate {sample_rate:g} Hz + 1")
    t = np.arange(n) / sample_rate
    return t


def simulate(model: Model, duration: float | None = None, *, temperature=None, input: Waveform | None = None,
             sample_rate: float = 10_000.0, t_eval=None, solver=None,
             controller: StepSizeController | None = None, max_samples: int | None = MAX_SAMPLES,
             friction_work: bool = False) -> SimulationResult:
    """Simulates ``model`` from rest.

    temperature: constant [degC], a ``Sampled`` signal, or (times, values); required for
        thermal models. With a heat model (``model.heat``) the temperature is a state: a number
        given here is the ambient temperature T_amb (overriding the model's).
    input: a waveform overriding the model's ``[input]``.
    duration, sample_rate: a uniform output grid from 0 to duration; or t_eval, any
        non-decreasing grid starting at the initial time.
    solver: ``AutoSwitch()`` (default), ``Dopri5()`` or ``Rodas4()``.
    controller: ``StepSizeController`` (tolerances, step limits).
    max_samples: the most output samples allowed (default 10 million, ~2 GB); None for no limit.
    friction_work: also integrate the friction work W = integral |F v_r| dt (always done with a
        heat model), returned as ``friction_work``.
    """
    solver = solver or AutoSwitch()
    if isinstance(solver, str):
        if solver not in SOLVERS:
            raise InputError(f"unknown solver '{solver}' (one of: {', '.join(SOLVERS)})")
        solver = SOLVERS[solver]()
    controller = controller or StepSizeController()
    temperature = as_temperature(temperature)
    heat = None
    if model.heat is not None:
        if isinstance(temperature, Sampled):
            raise InputError("the model has a [heat] section, so its temperature is a state: give the ambient "
                             "temperature as a number (--temperature C), not a temperature signal")
        heat = model.heat.resolved(temperature)
        T_start = sorted({heat.initial_temperature, heat.ambient_temperature})
        check_temperatures(model, T_start[0] if len(T_start) == 1 else Sampled(np.array([0.0, 1.0]),
                                                                                np.array(T_start)))
    else:
        check_temperatures(model, temperature)
    friction_work = bool(friction_work) or heat is not None
    waveform = input if input is not None else (model.input or Zero())
    if t_eval is not None:
        t_grid = np.ascontiguousarray(t_eval, dtype=float)
        if t_grid.ndim != 1 or t_grid.size < 1 or np.any(np.diff(t_grid) < 0) or not np.all(np.isfinite(t_grid)):
            raise InputError("t_eval must be a non-empty, non-decreasing array of finite times")
        _check_samples(t_grid.size, max_samples, "t_eval")
    else:
        if duration is None:
            raise InputError("give a duration (seconds) or t_eval")
        t_grid = _grid(float(duration), float(sample_rate), max_samples)
    t0, t1 = float(t_grid[0]), float(t_grid[-1])

    # period boundaries join the grid so that per-cycle step sizes are exact, not interpolated
    period = waveform.period
    cycle_times = np.empty(0)
    if period is not None:
        k0 = math.ceil(t0 / period - 1e-9)
        cycle_times = np.arange(k0, math.floor(t1 / period + 1e-9) + 1) * period
    # cycle starts usually fall on the grid already; only the others are inserted (O(n), no sort)
    tol = 1e-12 * max(1.0, abs(t1))
    on_grid_at = np.minimum(np.searchsorted(t_grid, cycle_times - tol), t_grid.size - 1)
    hit = np.abs(t_grid[on_grid_at] - cycle_times) <= tol
    extra = cycle_times[~hit]
    t_all = np.insert(t_grid, np.searchsorted(t_grid, extra), extra) if extra.size else t_grid
    if isinstance(model.plant, PrescribedMotion):
        check_prescribed_motion(waveform)
    nmech = MECHANICAL_STATES[model.plant.type]
    extra_states = ("T",) * (heat is not None) + ("W",) * friction_work
    nstate = len(nmech) + model.friction.nstate + len(extra_states)
    nch = _core.NFIXED_OUTPUTS + model.friction.nstate + friction_work
    out = np.empty((t_all.size, nch))
    atol = controller.atol
    if atol is not None:
        atol = np.broadcast_to(np.asarray(atol, float), (nstate,)).copy()
        if np.any(atol <= 0):
            raise InputError("atol must be positive")
    spec = core_spec(model, temperature, waveform, friction_work)
    try:
        stats = _core.simulate(spec, t_all, out, solver.code, float(controller.rtol), atol,
                               float(controller.first_step or 0.0), float(controller.max_step or 0.0),
                               int(controller.max_steps))
    except _core.SolverError as e:
        message, status, t_fail, h_fail, state, stiff = e.args
        names = nmech + tuple(model.friction.state_names) + extra_states
        where = ", ".join(f"{n} = {v:.6g}" for n, v in zip(names, state))
        try:
            u = float(waveform(t_fail)[0])
            where += f"; input {u:.6g}"
        except Exception:  # noqa: BLE001 - the input value is a courtesy, never a second error
            pass
        stiff_hint = ("the problem looks stiff: use the stiff solver, Rodas4() or AutoSwitch() "
                      "(--method rodas4 or --method auto)")
        explicit = isinstance(solver, Dopri5)
        if status == 3:
            hint = (f"{stiff_hint}; or " if stiff else
                    "the run is long for its time scales: " if not explicit else
                    "the run is long for its time scales or stiff (try --method rodas4 or auto): ")
            hint += f"raise max_steps (--max-steps, now {controller.max_steps}) or shorten the duration"
        elif status == 1:
            hint = ("likely cause: extreme parameter or input values (an overflow) or a model that is "
                    "unstable with these parameters; check them")
        elif status == 2:
            hint = ("likely cause: extreme parameter or input values, or a solution that blows up or "
                    "jumps faster than the time resolution; check them")
            if stiff and explicit:
                hint = f"{stiff_hint}; or {hint}"
        elif status == 5:
            hint = "out of memory: lower the duration or the sample rate"
        else:
            hint = "this is a bug if the inputs were checked; please report it"
        raise SolverError(f"integration failed at t = {t_fail:.9g} s (step {h_fail:.3g} s, {solver.name}): "
                          f"{message}; state {where}; {hint}", time=t_fail, state=state) from None
    stats["solver"] = {0: "auto", 1: "dopri5", 2: "rodas4"}[stats.pop("method")]
    # the C core keeps the states finite; an output computed from finite but extreme values
    # (e.g. a 1e165 m amplitude) may still overflow: refuse it rather than return it
    finite = np.isfinite(out)
    finite[:, _CHANNELS.index("temperature")] = True  # NaN by design without a thermal part
    if not finite.all():
        row, col = np.argwhere(~finite)[0]
        raise SolverError(f"the output '{(_CHANNELS + tuple(model.friction.state_names) + ('friction_work',))[col]}' "
                          f"is not finite at "
                          f"t = {t_all[row]:.9g} s ({out[row, col]}): likely cause: extreme parameter or input "
                          f"values (an overflow); check them", time=float(t_all[row]))
    if cycle_times.size:
        at_cycles = np.searchsorted(t_all, cycle_times - tol)
        x_cycles = out[at_cycles, 4]
        if extra.size:
            inserted = np.searchsorted(t_grid, extra) + np.arange(extra.size)
            out = np.delete(out, inserted, axis=0)
    else:
        x_cycles = np.empty(0)
    steps = np.diff(x_cycles)
    cols = {name: np.ascontiguousarray(out[:, i]) for i, name in enumerate(_CHANNELS)}
    if not isinstance(model.plant, StickSlipPlant):  # no stage: the driving surface is fixed (or the motion given)
        cols["stage_displacement"] = cols["stage_velocity"] = None
    if temperature is None and heat is None:
        cols["temperature"][:] = math.nan
    if heat is not None and model.thermal is not None:
        _check_heated_temperatures(model, cols["time"], cols["temperature"])
    nfric = model.friction.nstate
    return SimulationResult(
        **cols,
        friction_work=np.ascontiguousarray(out[:, len(_CHANNELS) + nfric]) if friction_work else None,
        states=np.ascontiguousarray(out[:, len(_CHANNELS):len(_CHANNELS) + nfric]),
        state_names=model.friction.state_names,
        state_units=model.friction.state_units,
        cycle_times=cycle_times,
        step_sizes=steps,
        mean_velocity=float(steps.mean() / period) if steps.size else math.nan,
        input_unit={"stick-slip": "V", "mass": "N", "prescribed": "m"}[model.plant.type],
        stats=stats,
    )


__all__ = ["simulate", "SimulationResult", "Dopri5", "Rodas4", "AutoSwitch", "StepSizeController", "SOLVERS",
           "core_spec", "MAX_SAMPLES"]
