"""Self-heating over long runs (docs/models.md#self-heating): ``simulate_heating(model, duration, solver=...)``.

Minutes of stepping at hundreds of hertz are 10^4-10^6 cycles of fast, stiff contact dynamics
under a thermal time constant of seconds to minutes. Two methods behind one entry point:

``TwoTimeScale()``
    Averaging: the fast model is run at fixed temperatures on a grid (a few cycles each, to the
    periodic steady state) to tabulate the step per cycle s(T) and the friction work per cycle
    E(T); then only the slow heat balance is integrated,
    ``C_th T' = eta E(T) f - (T - T_amb)/R_th + P_ext(t)``, with ``x' = s(T) f`` and
    ``W' = E(T) f``. Valid while the temperature changes little within one cycle (R_th C_th f >> 1).
``Full()``
    The whole coupled model (``simulate`` with the [heat] model) through every cycle: the
    reference the averaging is checked against, and affordable for minutes at hundreds of hertz.

Both return a :class:`HeatingResult` on the same grid of cycle starts.
"""

from __future__ import annotations

import dataclasses
import math
import time as _time
import warnings
from dataclasses import dataclass, field

import numpy as np

from ._lazy import lazy
from .errors import InputError, SolverError, TemperatureRangeWarning
from .figures.study_plots import heating_figure
from . import _args
from .models import Model
from .results import Result, Summary, collecting, emit
from .drive import input_of
from .simulation import MAX_SAMPLES, StepSizeController, check_heated_temperatures, simulate
from .waveforms import Waveform

integrate, interpolate = lazy("scipy.integrate"), lazy("scipy.interpolate")


@dataclass(frozen=True)
class TwoTimeScale:
    """Tabulate s(T), E(T) from the fast model at ``points`` temperatures (``warmup_cycles`` to reach
    the periodic state, then the mean over ``measure_cycles``), then integrate the slow heat
    balance alone (at ``controller``'s relative tolerance, default 1e-8). The table spans the start and ambient
    temperatures and the steady state the heat balance predicts; it grows by itself if the temperature leaves
    it. (``rtol=``, the earlier way to give the tolerance, still works with a DeprecationWarning: tolerances are
    given by a StepSizeController everywhere.)

    Parameters
    ----------
    points : int, default 17
        The table's temperatures (>= 4).
    warmup_cycles : int, default 6
        Cycles to reach the periodic state at each (>= 1).
    measure_cycles : int, default 4
        Cycles averaged over at each (>= 1).
    controller : StepSizeController, optional
        Its relative tolerance is the heat balance's; default 1e-8.
    rtol : float, optional
        Deprecated (DeprecationWarning): the earlier way to give the tolerance.

    Raises
    ------
    InputError
        Fewer points or cycles than said, named.
    """

    points: int = 17
    warmup_cycles: int = 6
    measure_cycles: int = 4
    controller: StepSizeController | None = None
    rtol: float | None = None
    name = "two-time-scale"

    def __post_init__(self):
        if self.points < 4 or self.warmup_cycles < 1 or self.measure_cycles < 1:
            raise InputError("TwoTimeScale: points >= 4, warmup_cycles >= 1 and measure_cycles >= 1")
        if self.rtol is not None:
            warnings.warn("TwoTimeScale(rtol=...) is now TwoTimeScale(controller=StepSizeController(rtol=...))",
                          DeprecationWarning, stacklevel=3)

    @property
    def tolerance(self) -> float:
        """The slow heat balance's relative tolerance."""
        return self.controller.rtol if self.controller is not None else self.rtol if self.rtol is not None else 1e-8


@dataclass(frozen=True)
class Full:
    """The fully coupled simulation through every cycle (``simulate`` with the heat model).

    Parameters
    ----------
    controller : StepSizeController, optional
        Tolerances and step limits of the simulation; default ``simulate``'s.
    """

    controller: StepSizeController | None = None
    name = "full"


@dataclass(eq=False)
class CycleTable:
    """Per-cycle quantities of the fast model at fixed temperatures (periodic steady state).

    Parameters
    ----------
    temperature : numpy.ndarray
        The temperatures [C].
    step_size : numpy.ndarray
        The end effector's displacement per cycle [m] at each.
    cycle_work : numpy.ndarray
        The friction work per cycle, the integral of abs(F v_r) [J], at each.
    frequency : float
        The input's frequency [Hz].
    startup : numpy.ndarray, optional
        The warm-up's displacement from rest beyond its periodic steps [m], at each.
    """

    temperature: np.ndarray  # [degC]
    step_size: np.ndarray    # end-effector displacement per cycle [m]
    cycle_work: np.ndarray   # friction work per cycle, integral of |F v_r| [J]
    frequency: float         # [Hz]
    startup: np.ndarray | None = None  # displacement of the warm-up from rest beyond its periodic steps [m]

    def interpolants(self):
        return (interpolate.PchipInterpolator(self.temperature, self.step_size, extrapolate=False),
                interpolate.PchipInterpolator(self.temperature, self.cycle_work, extrapolate=False))


@dataclass(eq=False)
class HeatingResult(Result):
    """A long heated run, sampled at cycle starts (plain arrays, SI; temperature in degC).

    ``displacement`` is the end effector's at each sampled cycle start; ``step_size`` the step of
    the cycle that starts there (two-time-scale: s(T) at that temperature; full: the simulated
    cycle, the last sample repeating the last cycle's); ``friction_work`` the work of friction
    from the start. ``table`` is the two-time-scale method's CycleTable (None for ``Full``);
    ``stats`` its costs (seconds, fast cycles simulated).

    Parameters
    ----------
    time : numpy.ndarray
        The sampled cycle starts [s].
    temperature : numpy.ndarray
        The interface temperature [C] there.
    displacement : numpy.ndarray
        The end effector's displacement [m] there.
    step_size : numpy.ndarray
        The step [m] of the cycle that starts there.
    friction_work : numpy.ndarray
        The friction work [J] from the start.
    frequency : float
        The input's frequency [Hz].
    method : str
        "two-time-scale" or "full".
    table : CycleTable, optional
        The two-time-scale method's table; None for ``Full``.
    stats : dict, default {}
        The method's costs (seconds, fast cycles simulated).
    """

    time: np.ndarray
    temperature: np.ndarray
    displacement: np.ndarray
    step_size: np.ndarray
    friction_work: np.ndarray
    frequency: float
    method: str
    table: CycleTable | None = None
    stats: dict = field(default_factory=dict)

    title = "heated run"

    def summary(self) -> Summary:
        return Summary([("method", self.method), ("duration", f"{self.time[-1] - self.time[0]:.6g} s"),
                        ("temperature", f"{self.temperature[0]:.4g} -> {self.temperature[-1]:.4g} C "
                                        f"(max {np.max(self.temperature):.4g} C)"),
                        ("displacement", f"{self.displacement[-1] * 1e3:.6g} mm"),
                        ("step per cycle", f"{self.step_size[0] * 1e6:.4g} -> {self.step_size[-1] * 1e6:.4g} um"),
                        ("friction work", f"{self.friction_work[-1]:.4g} J")])

    def _frame(self) -> dict:
        return {"time": self.time, "temperature": self.temperature, "displacement": self.displacement,
                "step_size": self.step_size, "friction_work": self.friction_work}

    def to_dict(self) -> dict:
        return {"method": self.method, "frequency": self.frequency, "summary": dict(self.summary()),
                "stats": self.stats, "samples": self._frame()}

    def plot(self):
        """A matplotlib figure: the interface temperature and the step per cycle against time."""
        return heating_figure(self)


def _periodic_input(model: Model, input: Waveform | None) -> Waveform:
    waveform = input_of(model, input)
    if waveform.period is None:
        raise InputError("simulate_heating needs a periodic input (e.g. a sawtooth): the two-time-scale method "
                         "averages over its cycles")
    return waveform


def _sample_cycles(n_cycles: int, samples: int) -> np.ndarray:
    """Indices of the sampled cycle starts: 0..n_cycles, at most samples + 1 of them."""
    return np.unique(np.round(np.linspace(0, n_cycles, min(samples, n_cycles) + 1)).astype(np.int64))


def cycle_table(model: Model, input: Waveform, temperatures, warmup_cycles: int = 6,
                measure_cycles: int = 4) -> CycleTable:
    """Step per cycle and friction work per cycle of ``model`` (its heat model removed) at each
    fixed temperature: simulated from rest for warmup + measure cycles, averaged over the last
    ``measure_cycles``. ``startup`` is the extra displacement of the first warmup cycles from rest
    over the periodic steps (one value per temperature).

    Parameters
    ----------
    model : Model
        The model.
    input : Waveform
        A periodic drive.
    temperatures : sequence of float
        The fixed temperatures [C].
    warmup_cycles : int, default 6
        Cycles simulated to reach the periodic state (>= 0).
    measure_cycles : int, default 4
        Cycles averaged over (>= 1).

    Returns
    -------
    CycleTable

    Raises
    ------
    InputError
        An argument of the wrong type or value, named.
    SolverError
        A simulation failed.
    """
    _args.model(model, Model)
    _args.instance(input, Waveform, "input", "a periodic Waveform")
    temperatures = _args.number_list(temperatures, "temperatures", "C")
    # the cycle starts are the run's output times: as many as simulate's max_samples allows
    warmup_cycles = _args.whole(warmup_cycles, "warmup_cycles", low=0, high=MAX_SAMPLES - 2)
    measure_cycles = _args.whole(measure_cycles, "measure_cycles", low=1, high=MAX_SAMPLES - 1 - warmup_cycles)
    fast = dataclasses.replace(model, heat=None)
    period = input.period
    n = warmup_cycles + measure_cycles
    steps, works, startup = [], [], []
    found = []
    try:
        with collecting() as found:  # the range the run really visits is checked once, afterwards
            for T in temperatures:
                res = simulate(fast, t_eval=np.arange(n + 1) * period, input=input, temperature=float(T),
                               friction_work=True)
                s = float(np.mean(res.step_sizes[warmup_cycles:]))
                steps.append(s)
                works.append(float(res.friction_work[-1] - res.friction_work[warmup_cycles]) / measure_cycles)
                startup.append(float(res.displacement[warmup_cycles] - res.displacement[0]) - warmup_cycles * s)
    finally:  # the other findings (passivity) as the runs said them
        emit([f for f in found if not issubclass(f.category, TemperatureRangeWarning)])
    return CycleTable(np.asarray(temperatures, float), np.array(steps), np.array(works), 1.0 / period,
                      np.array(startup))


def simulate_heating(model: Model, duration: float, *, input: Waveform | None = None, temperature=None,
                     solver=None, samples: int = 1000, method=None) -> HeatingResult:
    """Simulates ``duration`` seconds of periodic operation of a model with a [heat] section.

    Parameters
    ----------
    model : Model
        A model with a heat model (docs/models.md#self-heating).
    duration : float
        The run's length [s], > 0 and at least one cycle of the input.
    input : Waveform, optional
        The periodic drive; default the model's ``[input]``.
    temperature : float, optional
        The ambient temperature [C]; default the model's T_amb.
    solver : TwoTimeScale or Full, optional
        ``TwoTimeScale()`` (default) or ``Full()``.
    samples : int, default 1000
        The result holds about this many cycle starts, evenly spread.
    method : TwoTimeScale or Full, optional
        Deprecated (DeprecationWarning): ``solver``'s earlier name.

    Returns
    -------
    HeatingResult
        Temperature, displacement, step per cycle and friction work at the sampled cycle starts.

    Raises
    ------
    InputError
        An argument of the wrong type or value, named; a model without a [heat] section; a duration shorter
        than one cycle; both ``solver`` and ``method``.
    SolverError
        A simulation failed.
    """
    if method is not None:
        warnings.warn("simulate_heating(method=...) is now simulate_heating(solver=...)", DeprecationWarning,
                      stacklevel=2)
        if solver is not None:
            raise InputError("give solver= (method= is its earlier name), not both")
        solver = method
    method = solver
    _args.model(model, Model)
    duration = _args.number(duration, "duration", "s", positive=True)
    _args.instance(input, Waveform, "input", "a periodic Waveform", none=True)
    temperature = _args.number(temperature, "temperature", "degC", none=True)
    _args.instance(method, (TwoTimeScale, Full), "solver", "TwoTimeScale() or Full()", none=True)
    _args.whole(samples, "samples", low=1)
    if model.heat is None:
        raise InputError("simulate_heating needs a model with a [heat] section (docs/models.md#self-heating)")
    method = method or TwoTimeScale()
    waveform = _periodic_input(model, input)
    heat = model.heat.resolved(temperature)
    f = 1.0 / waveform.period
    n_cycles = int(math.floor(duration * f + 1e-9))
    if n_cycles < 1:
        raise InputError(f"duration {duration:g} s is shorter than one cycle ({waveform.period:g} s)")
    idx = _sample_cycles(n_cycles, samples)
    t_samples = idx * waveform.period
    if isinstance(method, Full):
        return _full(model, heat, waveform, n_cycles, idx, method)
    if isinstance(method, TwoTimeScale):
        return _two_time_scale(model, heat, waveform, t_samples, method)
    raise InputError(f"solver must be TwoTimeScale() or Full(), got {method!r}")


def _full(model, heat, waveform, n_cycles, idx, method: Full) -> HeatingResult:
    t0 = _time.perf_counter()
    # a long run needs more steps than simulate's default limit: ~70 per cycle for the paper's actuator
    controller = method.controller or StepSizeController(max_steps=max(10_000_000, 1000 * n_cycles))
    res = simulate(dataclasses.replace(model, heat=heat), t_eval=np.arange(n_cycles + 1) * waveform.period,
                   input=waveform, controller=controller, max_samples=None)
    seconds = _time.perf_counter() - t0
    steps = np.append(res.step_sizes, res.step_sizes[-1])
    return HeatingResult(res.time[idx], res.temperature[idx], res.displacement[idx], steps[idx],
                         res.friction_work[idx], 1.0 / waveform.period, "full",
                         stats={"seconds": seconds, "cycles_simulated": n_cycles, "solver_steps": res.stats["steps"]})


def _two_time_scale(model, heat, waveform, t_samples, method: TwoTimeScale) -> HeatingResult:
    t0 = _time.perf_counter()
    f = 1.0 / waveform.period
    C, R, eta, T_amb, T_0 = (heat.heat_capacity, heat.thermal_resistance, heat.heat_fraction,
                             heat.ambient_temperature, heat.initial_temperature)
    P_ext = heat.external_heat
    t_end = float(t_samples[-1])
    p_ext = P_ext(np.linspace(0, t_end, 4097)) if P_ext is not None else np.zeros(1)
    per_point = method.warmup_cycles + method.measure_cycles
    # the start-up from rest, and a first guess of the rise, from the fast model at T_0
    probe = cycle_table(model, waveform, [T_0], method.warmup_cycles, method.measure_cycles)
    cycles = per_point
    # the table spans [lo, hi]; heating only (P_ext >= 0) never takes T below min(T_0, T_amb)
    lo = min(T_0, T_amb)
    can_cool = float(p_ext.min()) < 0
    rise = R * (eta * float(probe.cycle_work[0]) * f + float(p_ext.max()))
    hi = max(T_0, T_amb) + max(0.5 * rise, 0.1)
    for _ in range(12):
        span = hi - lo
        below = 0.05 * span if can_cool else 0.0
        table = cycle_table(model, waveform, np.linspace(lo - below, hi + 0.05 * span, method.points),
                            method.warmup_cycles, method.measure_cycles)
        cycles += method.points * per_point
        step_of, work_of = table.interpolants()
        T_min, T_max = table.temperature[0], table.temperature[-1]

        def rates(t, y):
            T = min(max(y[0], T_min), T_max)  # rounding at the table's ends; escapes are events
            E, s = float(work_of(T)), float(step_of(T))
            P = float(P_ext(np.array([t]))[0]) if P_ext is not None else 0.0
            return [(eta * E * f - (y[0] - T_amb) / R + P) / C, s * f, E * f]

        def leaves(t, y):  # leaving [lo, hi] (cooling below lo only where the heater cools)
            return min(y[0] - (lo - below / 2 if can_cool else T_min - 1.0), hi + 0.025 * span - y[0])
        leaves.terminal = True
        corners = P_ext.corners(0.0, t_end) if P_ext is not None else np.empty(0)
        bounds = np.union1d([0.0, t_end], corners)
        y = np.array([T_0, 0.0, 0.0])
        out = np.empty((t_samples.size, 3))
        out[0] = y
        escaped = None
        for a, b in zip(bounds[:-1], bounds[1:]):
            if b <= a:
                continue
            sol = integrate.solve_ivp(rates, (a, b), y, method="LSODA", rtol=method.tolerance, atol=[1e-9, 1e-15, 1e-15],
                            events=leaves, dense_output=True)
            if sol.status < 0:
                raise SolverError(f"two-time-scale: the slow heat balance failed at t = {sol.t[-1]:.6g} s: "
                                  f"{sol.message}", time=float(sol.t[-1]))
            if sol.status == 1:
                escaped = float(sol.y[0, -1])
                break
            sel = (t_samples > a) & (t_samples <= b)
            out[sel] = sol.sol(t_samples[sel]).T
            y = sol.y[:, -1]
        if escaped is None:
            break
        if escaped > hi:
            hi += max(0.5 * span, 0.1)
        else:
            lo -= max(0.5 * span, 0.1)
    else:
        raise SolverError("two-time-scale: the temperature keeps leaving the tabulated range (thermal runaway?)")
    T = out[:, 0]
    # the first cycles from rest step differently from the periodic state: add their excess
    x = out[:, 1] + np.where(t_samples >= method.warmup_cycles / f, probe.startup[0], 0.0)
    check_heated_temperatures(model, t_samples, T)
    return HeatingResult(t_samples, T, x, step_of(np.clip(T, T_min, T_max)), out[:, 2], f, "two-time-scale",
                         table, stats={"seconds": _time.perf_counter() - t0, "cycles_simulated": cycles,
                                       "table_points": table.temperature.size})
__all__ = ["simulate_heating", "TwoTimeScale", "Full", "HeatingResult", "CycleTable", "cycle_table"]
