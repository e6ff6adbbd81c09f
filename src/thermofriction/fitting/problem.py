"""The fitting problem (the lowest layer of the fitting engine, thermofriction/fitting/): measured traces, the
residuals of a model against them and their Jacobian. What a residual is -- displacement about each run's zero,
force about a sensor offset -- belongs to the trace's measurement, an object the trace carries (its ``residuals``
and ``per_trace``; thermofriction/measurements/ implements them): the engine never imports what it measures. The
problem turns parameter values into a model once per evaluation, runs the traces side by side, and supplies what
every measurement shares: simulation with forward sensitivities, and the chain rule from the values a run sees at
its temperature to the coefficients of temperature laws."""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import math
import os
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .. import _bridge
from ..errors import InputError
from ..models import Model, ModelII
from ..models.transforms import at_temperature
from ..waveforms import Sampled, Waveform
from .parameters import EXCESS, KNOT, TARGET_DF, TARGET_LAW, get_value, split_name, target_of, with_values

#: the most integration steps of one run during a fit
MAX_STEPS = 2_000_000
#: a run with sensitivities (a trial point of the trust region) may take at most this many times the steps of the
#: trace's first such run in the same problem (and at least STEP_FLOOR): a trial step to a far stiffer model
#: (sigma1 from 4 to 2e6 in one step from a start 2-3x off) otherwise ran to MAX_STEPS -- 2.1 s of CPU, 80 % of
#: the whole fit at one temperature -- only to be refused, as a failed run is
STEP_FACTOR = 20
STEP_FLOOR = 100_000


@dataclasses.dataclass
class Trace:
    """One measured run, ready to fit: the model is driven by ``waveform`` at ``temperature``; ``measured``
    is the record the residuals are taken against, in SI units, and ``measurement`` says how (any object with
    the measurement's ``residuals`` and ``per_trace``: the engine never asks what it measures).

    With a heat model (docs/models.md#self-heating) ``temperature`` is the ambient one, the run starts at
    ``initial_temperature``, and ``measured_temperature`` (the record) is fitted too: its residuals
    are multiplied by ``temperature_weight`` [m/K] to share the displacement residuals' scale.

    Parameters
    ----------
    name : str
        The experiment's file.
    time : numpy.ndarray
        The sample times [s].
    measured : numpy.ndarray
        The record, in ``unit``.
    temperature : float or Sampled
        The temperature [C] the model is driven at (the ambient one with a heat model).
    waveform : Waveform
        The drive.
    role : {"fit", "validate"}, default "fit"
        The experiment's role.
    nominal_temperature : float, default nan
        The manifest's temperature [C].
    measurement : Measurement, optional
        How the residuals are formed.
    measured_temperature : numpy.ndarray, optional
        The recorded temperature [C], fitted too with a heat model.
    initial_temperature : float, default nan
        The run's start temperature [C] with a heat model.
    temperature_weight : float, default 1.0
        The temperature residuals' weight [m/K].
    held_offset : float, default 0.0
        The offset held where the measurement's policy is "none" (a force sensor's, from the model), in ``unit``.
    unit : str, default "m"
        The SI unit of ``measured``.
    angle : numpy.ndarray, optional
        The recorded position at each sample (force data: the position ripple's angle, measurements/ripple.py).
    """

    name: str
    time: np.ndarray
    measured: np.ndarray
    temperature: float | Sampled
    waveform: Waveform
    role: str = "fit"
    nominal_temperature: float = math.nan
    measurement: object = None
    measured_temperature: np.ndarray | None = None
    initial_temperature: float = math.nan
    temperature_weight: float = 1.0
    #: the offset held where the measurement's policy is "none" (a force sensor's, from the model)
    held_offset: float = 0.0
    #: the SI unit of ``measured``
    unit: str = "m"
    #: the recorded position at each sample (force data: the position ripple's angle, measurements/ripple.py)
    angle: np.ndarray | None = None

    @property
    def n_residuals(self) -> int:
        return len(self.time) * (1 if self.measured_temperature is None else 2)


_POOL = None


def pool() -> ThreadPoolExecutor:
    """One pool for all fits: the C core releases the GIL, so threads use every core."""
    global _POOL
    if _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=os.cpu_count() or 1, thread_name_prefix="thermofriction")
    return _POOL


class Tally:
    """The model evaluations (``nfev``) and those with a Jacobian (``njev``) of every Problem made while it was open
    (:func:`counting`), in whatever thread the work was carried to (:func:`in_context`)."""

    def __init__(self):
        self.nfev = self.njev = 0
        self._lock = threading.Lock()

    def add(self, jac):
        """One evaluation (with its Jacobian where ``jac``)."""
        with self._lock:
            self.nfev += 1
            self.njev += int(jac)


_TALLIES = contextvars.ContextVar("thermofriction_tallies", default=())


@contextlib.contextmanager
def counting():
    """A :class:`Tally` of the evaluations made inside the block (nested blocks count in each): what a fit spent,
    its multi-starts, refits and tests included, whichever function made the Problem.

    Yields
    ------
    Tally
        Its ``nfev`` and ``njev`` grow with every evaluation of a Problem made while the block runs.
    """
    tally = Tally()
    token = _TALLIES.set(_TALLIES.get() + (tally,))
    try:
        yield tally
    finally:
        _TALLIES.reset(token)


def in_context(function):
    """``function`` run, in another thread, in a copy of the calling thread's context: the Problems it makes count
    in the caller's tallies (a thread pool's threads otherwise keep their own context).

    Parameters
    ----------
    function : callable
        What the pool runs.

    Returns
    -------
    callable
        ``function`` with the same arguments, run in a fresh copy of the caller's context at each call.
    """
    parent = contextvars.copy_context()
    return lambda *args: parent.copy().run(function, *args)


class Problem:
    """Residuals r(theta) of ``model`` with ``names`` set to theta against ``traces``, and their Jacobian
    dr/dtheta: formed by the traces' measurement (offsets removed as it says)."""

    def __init__(self, model: Model, names, traces, rtol=1e-8, parallel=True):
        self.model = model
        self.names = list(names)
        self.measurement = traces[0].measurement if traces else None
        kinds = [target_of(model, n)[0] for n in self.names]
        self.targets = np.array([target_of(model, n) for n in self.names if target_of(model, n)[0] != KNOT],
                                dtype=np.int32).reshape(-1, 3)
        # At a constant temperature a temperature law (Model I's laws, Model II's dF) acts only through
        # its value there: the sensitivities to that value, times the law's derivatives in what is
        # fitted, are those to the coefficients at a fraction of the cost (Model I: 3 columns, not 6)
        # -- and the only way to a breakpoint's, which the core has no sensitivity to.
        self.chain = None
        thermal = [n for n, k in zip(self.names, kinds) if k in (TARGET_LAW, TARGET_DF, KNOT)]
        constant = model.heat is None and all(isinstance(t.temperature, (int, float)) for t in traces)
        if KNOT in kinds and not constant:
            raise InputError("dF's breakpoints can be fitted only on runs at constant temperature "
                             "(no temperature signal, no self-heating)")
        if thermal and constant:
            through = ["dF.value"] if isinstance(model.thermal, ModelII) else \
                sorted({split_name(n)[0] for n in thermal})
            self.chain = through + [n for n in self.names if n not in thermal]
            at = at_temperature(model, float(traces[0].temperature))
            self.chain_targets = np.array([target_of(at, n) for n in self.chain], dtype=np.int32).reshape(-1, 3)
        self.traces = traces
        self.rtol = rtol
        self.parallel = parallel
        self.n_points = sum(len(t.time) for t in traces)
        self.nfev = 0
        self.njev = 0
        self._tallies = _TALLIES.get()  # the open tallies this problem's evaluations count in
        self._seconds = {}  # (trace, with sensitivities): its last run's wall time, for run_all
        self._steps = {}  # trace (by id) -> the steps of its first run with sensitivities: the budget's measure

    def model_at(self, theta):
        """The model at theta, or None where it must not be simulated: built and checked once per
        evaluation, not once per trace."""
        try:
            model = with_values(self.model, dict(zip(self.names, theta)))
        except InputError:  # a step that breaks a rule between parameters (fs >= fc, z_ba < fc/sigma0)
            return None
        if model.unphysical_over_range():  # never step where the fitted model would not load or run
            return None
        return model

    def evaluate(self, theta, jac=False):
        """(r, J) at theta; r is None when a simulation failed (the parameters are implausible)."""
        theta = np.asarray(theta, float)
        model = self.model_at(theta)
        self.nfev += 1
        self.njev += int(jac)
        for tally in self._tallies:
            tally.add(jac)
        if model is None:
            return None, None
        return self.measurement.residuals(self, model, theta, jac)

    def per_trace(self, theta):
        """Each trace's residuals at theta (no Jacobian); None for a run that failed."""
        theta = np.asarray(theta, float)
        model = self.model_at(theta)
        if model is None:
            return [None] * len(self.traces)
        return self.measurement.per_trace(self, model, theta)

    def run_all(self, run, jac):
        """``run(i)`` for every trace on the pool, the longest first (by its last run's time, or its length):
        five runs on two cores, one of them twice as long as the others, take 3 units of time this way
        and up to 3.8 in the traces' order, where the long one can start last."""
        if not (self.parallel and len(self.traces) > 1):
            return [run(i) for i in range(len(self.traces))]

        def timed(i):
            t0 = time.perf_counter()
            out = run(i)
            self._seconds[(i, jac)] = time.perf_counter() - t0
            return out
        order = sorted(range(len(self.traces)),
                       key=lambda i: -self._seconds.get((i, jac), 1e-9 * len(self.traces[i].time)))
        results = [None] * len(self.traces)
        for i, out in zip(order, pool().map(timed, order)):
            results[i] = out
        return results

    def simulate(self, model: Model, trace: Trace, theta, jac, *, method="dopri5", rtol=None):
        """One run of ``model`` on ``trace``: (outputs, sensitivities of every state to theta or None), or
        (None, None) where the core fails; sensitivities to what was simulated (see :meth:`in_names`). A self-heating model runs from the trace's own start (or the
        fitted T_0)."""
        rtol = self.rtol if rtol is None else rtol
        heated = model.heat is not None
        if heated:  # each run from its own start, unless the fit estimates one start for all (T_0)
            T0 = model.heat.initial_temperature if "T_0" in self.names else trace.initial_temperature
            model = dataclasses.replace(model, heat=dataclasses.replace(
                model.heat, ambient_temperature=trace.temperature, initial_temperature=T0))
        spec = _bridge.model_spec(model, trace.temperature, trace.waveform)
        n_out = len(trace.time)
        out = np.empty((n_out, _bridge.n_outputs(model, heated)))
        try:
            if not jac:
                _bridge.run(spec, trace.time, out, method=method, rtol=rtol, max_steps=MAX_STEPS)
                return out, None
            targets = self.targets
            if self.chain is not None:  # the model at the run's temperature, sensitivities to its values
                model_T = at_temperature(model, float(trace.temperature))
                spec = _bridge.model_spec(model_T, trace.temperature, trace.waveform)
                theta = np.array([get_value(model_T, n) for n in self.chain])
                targets = self.chain_targets
                if isinstance(model.thermal, ModelII):
                    # dF(T) at or near zero (the reference temperature, a start at zero): its
                    # sensitivity's tolerance in dF's scale, at least a tenth of the friction level
                    dF_scale = max(float(np.max(np.abs(model.thermal.dF.coefficients() or [0.0]))),
                                   0.1 * model_T.reference_force(), 1e-300)
                    theta[0] = max(abs(theta[0]), dF_scale)
            scale = _bridge.state_scale(spec)
            atol_y = rtol * scale
            atol_s = atol_y[:, None] / np.maximum(np.abs(theta), 1e-300)[None, :]
            sens = np.empty((n_out, len(scale), len(theta)))
            first = self._steps.get(id(trace))
            budget = MAX_STEPS if first is None else min(MAX_STEPS, max(STEP_FLOOR, STEP_FACTOR * first))
            stats = _bridge.run_sensitivities(spec, targets, trace.time, out, sens, rtol=rtol,
                                              atol=np.concatenate([atol_y, atol_s.ravel()]), max_steps=budget)
            self._steps.setdefault(id(trace), int(stats["steps"]))
        except (_bridge.CoreFailure, InputError):  # InputError: at this run's temperature the laws break a
            return None, None  # rule between parameters (fs below fc) that holds at the model's own checks
        return out, sens

    def in_names(self, S, model: Model, trace: Trace):
        """Sensitivities ``S`` of one output to what the run was simulated with, as sensitivities to the
        fitted names (the chain rule through the laws at the trace's temperature, where it applies)."""
        if self.chain is not None:
            return S @ self.chain_matrix(model, float(trace.temperature))
        if EXCESS in self.names and "fc" in self.names:  # fs = fc + excess: moving fc (excess held) moves fs too
            S = S.copy()
            S[..., self.names.index("fc")] += S[..., self.names.index(EXCESS)]
        return S

    def chain_matrix(self, model: Model, T: float) -> np.ndarray:
        """d(the simulated values)/d(the fitted names) at temperature T: a law's derivative in a
        coefficient by central differences (exact for the laws linear in them, 1e-8 relative for
        exp's rate), in a breakpoint analytically; one for a name simulated as itself."""
        M = np.zeros((len(self.chain), len(self.names)))
        for j, name in enumerate(self.names):
            if name in self.chain:
                M[self.chain.index(name), j] = 1.0
                continue
            base, coef = split_name(name)
            law = model.thermal.dF if base == "dF" else model.laws[base]
            row = 0 if base == "dF" else self.chain.index(base)
            kind, _, k = target_of(model, name)
            if kind == KNOT:
                M[row, j] = knot_derivative(law, k, T)
                continue
            c = np.array(law.coefficients(), float)
            h = 1e-4 * (abs(c[k]) if c[k] != 0 else max(float(np.max(np.abs(c))), 1e-300))
            up, down = c.copy(), c.copy()
            up[k] += h
            down[k] -= h
            M[row, j] = (float(law.with_coefficients(up)(T)) - float(law.with_coefficients(down)(T))) / (2 * h)
        return M


def knot_derivative(law, k, T) -> float:
    """d law(T) / d T[k] of a piecewise-linear law (extrapolated with its end segments)."""
    knots, values = law.T, law.values
    i = int(np.clip(np.searchsorted(knots, T, side="right") - 1, 0, len(knots) - 2))
    a, b = knots[i], knots[i + 1]
    slope_term = (values[i + 1] - values[i]) / (b - a) ** 2
    if k == i + 1:
        return float(-slope_term * (T - a))
    if k == i:
        return float(-slope_term * (b - T))
    return 0.0


__all__ = ["Trace", "Problem", "pool", "Tally", "counting", "in_context", "knot_derivative", "MAX_STEPS", "STEP_FACTOR",
           "STEP_FLOOR"]
