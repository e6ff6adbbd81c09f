"""Simulation: ``simulate(model, duration, temperature=..., input=..., load=...)`` on the C core.

Solvers are objects you pass in (``Dopri5()``, ``Rodas4()``, ``AutoSwitch()``), separate from the
step-size controller (``StepSizeController(rtol=..., atol=...)``). Results come on a uniform
output grid from the solver's dense output, with per-cycle step sizes for periodic inputs.

``simulate`` is four steps: the output grid (with the period starts joined to it), the run on the
core, the explanation of a failed run, and the packing of the outputs into a result.
"""

from __future__ import annotations

import functools
import math
import numbers
import os

import numpy as np

from .. import _bridge
from ..drive import input_of
from .. import _args
from ..errors import InputError, SolverError, shorten
from ..models import Model, PrescribedMotion, StickSlipPlant
from ..models.load_laws import load_laws
from ..waveforms import Sampled, Waveform
from ..results import emit
from .checks import (as_temperature, check_heated_temperatures, check_passivity, check_prescribed_motion,
                     check_temperatures, coverage_findings, heated_findings, temperature_findings)
from .loads import as_load, load_findings
from .result import SimulationResult
from .solvers import SOLVERS, AutoSwitch, Dopri5, Rodas4, StepSizeController

#: Default limit on output samples: each takes ~8 x (10 + internal states) bytes of outputs, ~1.1 times
#: that at the peak (docs/performance.md: 97 MB for 1,000,001 samples), so 10 million need ~1 GB.
MAX_SAMPLES = 10_000_000


#: Output times must lie within +-MAX_TIME s: the C core refuses others (solve.c, tf_solve),
#: as beyond it a double resolves time only to ~1e-4 s and periodic inputs lose their phase.
MAX_TIME = 1e12


def _count(n) -> str:
    return f"{n}" if n < 1e15 else f"{float(n):.3g}"


def _check_samples(n, max_samples, what, at_least=""):
    if max_samples is not None and n > max_samples:
        raise InputError(f"{at_least}{_count(n)} output samples requested ({what}), above the limit of {max_samples} "
                         f"(~{n * 100 / 1e9:.3g} GB of memory): lower the duration or the sample rate, or raise "
                         f"the limit (--max-samples N; max_samples=N in Python, None for no limit)")


def _check_span(t0, t1, what):
    if not (abs(t0) <= MAX_TIME and abs(t1) <= MAX_TIME):
        raise InputError(f"{what} reaches t = {max(abs(t0), abs(t1)):g} s, beyond the limit of {MAX_TIME:g} s (there "
                         f"a double resolves time only to ~1e-4 s): shorten the duration")


def _grid(duration, sample_rate, max_samples=MAX_SAMPLES):
    if not (duration > 0 and math.isfinite(duration)):
        raise InputError(f"duration must be a positive number of seconds, got {duration!r}")
    if not (sample_rate > 0 and math.isfinite(sample_rate)):
        raise InputError(f"sample rate must be positive, got {sample_rate!r}")
    _check_span(0.0, duration, f"duration {duration:g} s")
    x = duration * sample_rate * (1 + 1e-12)
    if not math.isfinite(x) or x >= 2.0 ** 62:
        raise InputError(f"duration {duration:g} s x sample rate {sample_rate:g} Hz is too many output samples: lower the duration or the sample rate")
    n = int(math.floor(x)) + 1
    _check_samples(n, max_samples, f"duration {duration:g} s x sample rate {sample_rate:g} Hz + 1")
    t = np.arange(n) / sample_rate
    return t


def output_grid(duration, sample_rate, t_eval, max_samples) -> np.ndarray:
    """The requested output times: ``t_eval``, or a uniform grid from 0 to ``duration``.

    Parameters
    ----------
    duration : float or None
        The grid's end [s] (with ``sample_rate``), where ``t_eval`` is None.
    sample_rate : float
        The uniform grid's rate [Hz].
    t_eval : array_like or None
        Any non-empty, non-decreasing array of finite times [s].
    max_samples : int or None
        The most samples allowed; None: no limit.

    Returns
    -------
    numpy.ndarray
        The times [s].

    Raises
    ------
    InputError
        Neither ``duration`` nor ``t_eval``; values that are not numbers, a grid that is not
        non-decreasing or finite, a span out of range, more than ``max_samples`` samples.
    """
    if t_eval is not None:
        try:
            t_grid = np.ascontiguousarray(t_eval, dtype=float)
        except (TypeError, ValueError):
            raise InputError("t_eval must be an array of times [s]") from None
        if t_grid.ndim != 1 or t_grid.size < 1 or np.any(np.diff(t_grid) < 0) or not np.all(np.isfinite(t_grid)):
            raise InputError("t_eval must be a non-empty, non-decreasing array of finite times")
        _check_span(float(t_grid[0]), float(t_grid[-1]), "t_eval")
        _check_samples(t_grid.size, max_samples, "t_eval")
        return t_grid
    if duration is None:
        raise InputError("give a duration (seconds) or t_eval")
    try:
        duration, sample_rate = float(duration), float(sample_rate)
    except (TypeError, ValueError):
        raise InputError(f"duration and sample_rate must be numbers, got {duration!r} and {sample_rate!r}") from None
    return _grid(duration, sample_rate, max_samples)


class _Grid:
    """The output grid with the input's period starts joined to it, so that per-cycle step sizes
    are exact, not interpolated; ``unjoin`` removes the joined rows again.

    Every joined row is stored too: their number is counted against ``max_samples`` before
    anything is allocated (a 1 MHz input on a 1 Hz grid joins a million rows per second)."""

    def __init__(self, t_grid: np.ndarray, period: float | None, max_samples=MAX_SAMPLES):
        self.requested = t_grid
        t0, t1 = float(t_grid[0]), float(t_grid[-1])
        self.cycle_times = np.empty(0)
        if period is not None:
            k0 = math.ceil(t0 / period - 1e-9)
            k1 = math.floor(t1 / period + 1e-9)
            n_cycles = max(k1 - k0 + 1, 0)
            what = f"{t_grid.size} requested + {{}} period starts of the {1 / period:g} Hz input joined to them"
            if n_cycles >= 2 ** 40:  # beyond any memory, with or without a limit
                raise InputError(f"{_count(t_grid.size + n_cycles)} output samples requested "
                                 f"({what.format(_count(n_cycles))}): shorten the duration or lower the input's "
                                 f"frequency")
            # each requested time can absorb at most one period start: more starts than the limit
            # exceed it whatever the grid (refused before they are allocated)
            if max_samples is not None and n_cycles > max_samples:
                _check_samples(n_cycles, max_samples, what.format(f"at least {_count(n_cycles - t_grid.size)}"),
                               at_least="at least ")
            self.cycle_times = np.arange(k0, k1 + 1) * period
        # cycle starts usually fall on the grid already; only the others are inserted (O(n), no sort)
        self.tol = 1e-12 * max(1.0, abs(t1))
        on_grid_at = np.minimum(np.searchsorted(t_grid, self.cycle_times - self.tol), t_grid.size - 1)
        hit = np.abs(t_grid[on_grid_at] - self.cycle_times) <= self.tol
        self.extra = self.cycle_times[~hit]
        if period is not None:
            _check_samples(t_grid.size + self.extra.size, max_samples, what.format(self.extra.size))
        self.times = (np.insert(t_grid, np.searchsorted(t_grid, self.extra), self.extra) if self.extra.size
                      else t_grid)

    def at_cycles(self, column: np.ndarray) -> np.ndarray:
        return column[np.searchsorted(self.times, self.cycle_times - self.tol)] if self.cycle_times.size else np.empty(0)

    def unjoin(self, out: np.ndarray) -> np.ndarray:
        """``out`` (a row per time) without the joined rows, in Fortran order (a contiguous column per
        output): one copy, and none when nothing was joined."""
        if not self.extra.size:
            return out
        keep = np.ones(out.shape[0], bool)
        keep[np.searchsorted(self.requested, self.extra) + np.arange(self.extra.size)] = False
        kept = np.empty((out.shape[1], self.requested.size))
        np.compress(keep, out.T, axis=1, out=kept)
        return kept.T


def _explain(e: _bridge.CoreFailure, model: Model, solver, controller, waveform, state_names) -> SolverError:
    """A failed run as one message: where, in which state, and what to try."""
    where = ", ".join(f"{n} = {v:.6g}" for n, v in zip(state_names, e.state))
    try:
        u = float(waveform(e.time)[0])
        where += f"; input {u:.6g}"
    except Exception:  # noqa: BLE001 - the input value is a courtesy, never a second error
        pass
    stiff_hint = ("the problem looks stiff: use the stiff solver, Rodas4() or AutoSwitch() "
                  "(--solver rodas4 or --solver auto)")
    explicit = isinstance(solver, Dopri5)
    if e.status == "max_steps":
        hint = (f"{stiff_hint}; or " if e.stiff else
                "the run is long for its time scales: " if not explicit else
                "the run is long for its time scales or stiff (try --solver rodas4 or auto): ")
        hint += f"raise max_steps (--max-steps, now {controller.max_steps}) or shorten the duration"
    elif e.status == "nonfinite":
        hint = ("likely cause: extreme parameter or input values (an overflow) or a model that is "
                "unstable with these parameters; check them")
    elif e.status == "step_underflow":
        hint = ("likely cause: extreme parameter or input values, or a solution that blows up or "
                "jumps faster than the time resolution; check them")
        if abs(e.time) >= 1e3:  # far from t = 0 a double's spacing, not the model, may be the limit
            hint += (f"; or a late start: at t = {e.time:.3g} s a double resolves time only to "
                     f"{np.spacing(abs(e.time)):.2g} s, so start the time at 0")
        if e.stiff and explicit:
            hint = f"{stiff_hint}; or {hint}"
    elif e.status == "no_memory":
        hint = "out of memory: lower the duration or the sample rate"
    else:
        hint = "this is a bug if the inputs were checked; please report it"
    return SolverError(f"integration failed at t = {e.time:.9g} s (step {e.step:.3g} s, {solver.name}): "
                       f"{e.core_message}; state {where}; {hint}", time=e.time, state=e.state)


def _check_arguments(model, input, controller, max_samples):
    """The public arguments' types, so that a wrong one is an InputError naming it (not an
    AttributeError deep inside)."""
    if not isinstance(model, Model):
        hint = " (tf.load_model(path) reads a model file or preset)" if isinstance(model, (str, os.PathLike)) else ""
        raise InputError(f"model must be a Model{hint}, got {shorten(model)}")
    if input is not None and not isinstance(input, Waveform):
        hint = f" (tf.parse_waveform({shorten(input)}) makes one from a spec)" if isinstance(input, str) else ""
        raise InputError(f"input must be a Waveform{hint}, got {shorten(input)}")
    if controller is not None and not isinstance(controller, StepSizeController):
        raise InputError(f"controller must be a StepSizeController, got {shorten(controller)}")
    _args.whole(max_samples, "max_samples", none=True, low=1)


def _check_types(duration, temperature, sample_rate, t_eval, solver, friction_work):
    """No coercion (_args.py): duration='2', temperature='35', sample_rate=True, t_eval='0.01' are refused."""
    _args.number(duration, "duration", "s", none=True)
    _args.number(sample_rate, "sample_rate", "Hz")
    _args.number_list(t_eval, "t_eval", "s", none=True)
    if _args.is_number(temperature):
        _args.number(temperature, "temperature", "degC")
    pair = isinstance(temperature, (tuple, list)) and len(temperature) == 2 and all(
        isinstance(x, (list, tuple, np.ndarray)) and np.ndim(x) == 1 for x in temperature)
    if not (temperature is None or _args.is_number(temperature) or isinstance(temperature, Sampled) or pair):
        _args.refuse("temperature", "a number [degC], a Sampled signal or (times, values), two arrays", temperature)
    if solver is not None and not isinstance(solver, str) and not isinstance(solver, tuple(SOLVERS.values())):
        _args.refuse("solver", "Dopri5(), Rodas4(), AutoSwitch() or one of their names", solver)
    _args.flag(friction_work, "friction_work")


def simulate(model: Model, duration: float | None = None, *, temperature=None, input: Waveform | None = None,
             sample_rate: float = 10_000.0, t_eval=None, solver=None,
             controller: StepSizeController | None = None, max_samples: int | None = MAX_SAMPLES,
             friction_work: bool = False, load=None) -> SimulationResult:
    """Simulates ``model`` from rest.

    Parameters
    ----------
    model : Model
        The model to run (``load_model`` reads one from a file or a preset).
    duration : float, optional
        The end of a uniform output grid from 0 [s], sampled at ``sample_rate``. Give it or ``t_eval``.
    temperature : float or Sampled or tuple of array_like, optional
        A constant temperature [C], a ``Sampled`` temperature signal, or (times [s], values [C]); required
        for thermal models. With a heat model (``model.heat``) the temperature is a state: a number given here
        is the ambient temperature T_amb (overriding the model's), and a signal is refused.
    input : Waveform, optional
        The drive, overriding the model's ``[input]`` (a voltage [V], or the motion of a ``PrescribedMotion``).
    sample_rate : float, default 10000.0
        The output grid's rate [Hz] with ``duration``.
    t_eval : array_like, optional
        Any non-decreasing output grid [s] starting at the initial time, instead of ``duration`` and
        ``sample_rate``.
    solver : AutoSwitch or Dopri5 or Rodas4 or str, optional
        The integrator, or its name (``"auto"``, ``"dopri5"``, ``"rodas4"``); default ``AutoSwitch()``.
    controller : StepSizeController, optional
        Tolerances and step limits; default ``StepSizeController()`` (rtol 1e-6).
    max_samples : int or None, default 10_000_000
        The most output samples allowed (10 million is ~1 GB); None for no limit.
    friction_work : bool, default False
        Also integrate the friction work W = integral of abs(F v_r) dt [J], returned as
        ``SimulationResult.friction_work`` (always done with a heat model).
    load : float or Waveform or tuple of array_like, optional
        The load the laws of the load read (a normal force [N] or a load torque [N m]: a preloaded stage's normal
        force, the stick-slip actuator's preload): a constant, a waveform (``Sampled`` for a recorded one) or
        (times, values); required by a model with a law of the load, ignored by one without.

    Returns
    -------
    SimulationResult
        Time [s], displacement [m], velocity [m/s], friction force [N], the friction states and the step sizes,
        as NumPy arrays in SI units.

    Raises
    ------
    InputError
        An argument of the wrong type or out of range, named (``duration must be a number [s], ...``); no
        temperature for a thermal model; no load for a model with a law of the load, naming the law; a
        temperature signal for a model with a heat model; an output grid over ``max_samples``.
    SolverError
        The integrator stopped (too many steps, a non-finite state): its ``time`` and ``state`` say where.

    Warns
    -----
    TemperatureRangeWarning
        A temperature (LoadRangeWarning: a load) outside the range a law was calibrated on.
    PassivityWarning
        Friction parameters that can create energy.

    Examples
    --------
    >>> import thermofriction as tf
    >>> model = tf.load_model("li2009-model-i")
    >>> res = tf.simulate(model, duration=0.01, temperature=35.7, sample_rate=1000.0)
    >>> res.time.shape
    (11,)
    >>> float(res.time[-1]), float(res.displacement[0])
    (0.01, 0.0)
    """
    _check_arguments(model, input, controller, max_samples)
    load = as_load(load)
    _check_types(duration, temperature, sample_rate, t_eval, solver, friction_work)
    solver = solver or AutoSwitch()
    if isinstance(solver, str):
        if solver not in SOLVERS:
            raise InputError(f"unknown solver {shorten(solver)} (one of: {', '.join(SOLVERS)})")
        solver = SOLVERS[solver]()
    if not isinstance(solver, tuple(SOLVERS.values())):
        raise InputError(f"solver must be Dopri5(), Rodas4(), AutoSwitch() or one of their names, got {shorten(solver)}")
    controller = controller or StepSizeController()
    temperature = as_temperature(temperature)
    heat = None
    if model.heat is not None:
        if isinstance(temperature, Sampled):
            raise InputError("the model has a [heat] section, so its temperature is a state: give the ambient "
                             "temperature as a number (--temperature C), not a temperature signal")
        heat = model.heat.resolved(temperature)
        T_start = sorted({heat.initial_temperature, heat.ambient_temperature})
        T_run = T_start[0] if len(T_start) == 1 else Sampled(np.array([0.0, 1.0]), np.array(T_start))
    else:
        T_run = temperature
    if load_laws(model):
        if T_run is None:
            raise InputError("the model depends on temperature: give a temperature (e.g. --temperature 35)")
        found = load_findings(model, T_run.value if isinstance(T_run, Sampled) else [T_run], load)
    else:
        found = temperature_findings(model, T_run)
    friction_work = bool(friction_work) or heat is not None
    waveform = input_of(model, input)
    grid = (_Grid(output_grid(duration, sample_rate, t_eval, max_samples), waveform.period, max_samples)
            if t_eval is not None or not (isinstance(duration, numbers.Real) and isinstance(sample_rate, numbers.Real))
            else _uniform_grid(float(duration), float(sample_rate), waveform.period, max_samples))
    if model.thermal is not None and heat is None:
        found += coverage_findings(temperature, float(grid.requested[0]), float(grid.requested[-1]))
    if isinstance(model.plant, PrescribedMotion):
        check_prescribed_motion(waveform)
    emit(found)  # the checks' findings, as warnings (before the run, which may fail), and on the result

    # run
    state_names = (_bridge.MECHANICAL_STATES[model.plant.type] + tuple(model.friction.state_names)
                   + ("T",) * (heat is not None) + ("W",) * friction_work)
    atol = controller.atol
    if atol is not None:
        try:
            atol = np.broadcast_to(np.asarray(atol, float), (len(state_names),)).copy()
        except ValueError:
            raise InputError(f"atol must be one number or one per state ({len(state_names)}: "
                             f"{', '.join(state_names)}), got {shorten(controller.atol)}") from None
    # one block in Fortran order: each output is a contiguous column, which the result holds as a view
    out = np.empty((_bridge.n_outputs(model, friction_work), grid.times.size)).T
    try:
        stats = _bridge.run(_bridge.model_spec(model, temperature, waveform, friction_work, load), grid.times, out,
                            method=solver.name, rtol=controller.rtol, atol=atol,
                            first_step=controller.first_step or 0.0, max_step=controller.max_step or 0.0,
                            max_steps=controller.max_steps)
    except _bridge.CoreFailure as e:
        raise _explain(e, model, solver, controller, waveform, state_names) from None
    stats["solver"] = stats.pop("method")
    res = _pack(model, out, grid, stats, temperature, heat, friction_work, waveform.period, load)
    emit(res.findings)  # self-heating's, known after the run
    res.findings[:0] = found
    return res


@functools.lru_cache(maxsize=16)
def _uniform_grid(duration, sample_rate, period, max_samples) -> _Grid:
    """The uniform grid of a run, built once for runs alike (identification and sweeps repeat them); its
    arrays are read-only, and a result copies what it keeps of them."""
    grid = _Grid(output_grid(duration, sample_rate, None, max_samples), period, max_samples)
    for a in (grid.requested, grid.times, grid.cycle_times, grid.extra):
        a.setflags(write=False)
    return grid


def _pack(model, out, grid, stats, temperature, heat, friction_work, period, load=None) -> SimulationResult:
    """The output array as a result: refuses non-finite outputs, reads the step sizes at the period
    starts, removes the joined rows, names the columns."""
    # the C core keeps the states finite; an output computed from finite but extreme values
    # (e.g. a 1e165 m amplitude) may still overflow: refuse it rather than return it
    outputs = _bridge.OUTPUTS
    finite, bad = np.empty(out.shape[0], bool), None  # column by column: no temporary of the block's size
    # one pass first: a NaN or an infinity makes its column's sum non-finite (so may an overflow of
    # finite values, which the exact test below then clears)
    suspects = np.flatnonzero(~np.isfinite(out.sum(axis=0)))
    for col in suspects:
        if col != _bridge.OUTPUT_COLUMN["temperature"]:  # NaN by design without a thermal part
            if not np.isfinite(out[:, col], out=finite).all():
                bad = min(bad or (math.inf, 0), (int(np.argmin(finite)), col))  # the earliest, as time goes
    if bad:
        row, col = bad
        raise SolverError(f"the output '{(outputs + tuple(model.friction.state_names) + ('friction_work',))[col]}' "
                          f"is not finite at "
                          f"t = {grid.times[row]:.9g} s ({out[row, col]}): likely cause: extreme parameter or input "
                          f"values (an overflow); check them", time=float(grid.times[row]))
    steps = np.diff(grid.at_cycles(out[:, _bridge.OUTPUT_COLUMN["displacement"]]))
    out = grid.unjoin(out)
    cols = {name: out[:, i] for i, name in enumerate(outputs)}  # views of the block's contiguous columns
    if not isinstance(model.plant, StickSlipPlant):  # no stage: the driving surface is fixed (or the motion given)
        cols["stage_displacement"] = cols["stage_velocity"] = None
    if temperature is None and heat is None:
        cols["temperature"][:] = math.nan
    found = heated_findings(model, cols["time"], cols["temperature"], load) if heat is not None and \
        model.thermal is not None else []
    nfric = model.friction.nstate
    return SimulationResult(
        **cols,
        friction_work=out[:, len(outputs) + nfric] if friction_work else None,
        states=np.ascontiguousarray(out[:, len(outputs):len(outputs) + nfric]),
        state_names=model.friction.state_names,
        state_units=model.friction.state_units,
        cycle_times=grid.cycle_times.copy(),
        step_sizes=steps,
        mean_velocity=float(steps.mean() / period) if steps.size else math.nan,
        input_unit={"stick-slip": "V", "mass": "N", "prescribed": "m"}[model.plant.type],
        stats=stats,
        model_name=model.name,
        rotary=bool(getattr(model.plant, "rotary", False)),
        findings=found,
    )


__all__ = ["simulate", "SimulationResult", "Dopri5", "Rodas4", "AutoSwitch", "StepSizeController", "SOLVERS",
           "MAX_SAMPLES", "as_temperature", "check_temperatures", "check_passivity", "check_prescribed_motion",
           "check_heated_temperatures", "output_grid"]
