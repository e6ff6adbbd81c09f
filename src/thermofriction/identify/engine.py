"""The least-squares engine: residuals of simulated against measured displacement, their exact
Jacobian from the C core's forward sensitivities, a multi-start global phase, trust-region
Levenberg-Marquardt (SciPy ``least_squares``), and uncertainty from the Jacobian at the optimum."""

from __future__ import annotations

import dataclasses
import functools
import math
import os
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from .. import _bridge
from .._lazy import lazy
from ..drive import drive
from ..errors import ComputationError, InputError
from ..models import Const, Model, ModelII
from ..waveforms import Sampled, Waveform
from .parameters import _TARGET_DF as _DF
from .parameters import _TARGET_LAW as _LAW
from .parameters import _split as split_name
from .parameters import KNOT, Parameters, get_value, target_of, unit_of, with_values
from .quality import ADEQUATE_RATIO, noise_level

optimize, stats, special = lazy("scipy.optimize"), lazy("scipy.stats"), lazy("scipy.special")

_MAX_STEPS = 2_000_000
#: RMSE within this factor of the noise: a fit at the noise, where the multi-start stops
AT_NOISE = 1.1


@dataclasses.dataclass
class Trace:
    """One measured run, ready to fit: the model is driven by ``waveform`` at ``temperature``.

    With a heat model (docs/models.md#self-heating) ``temperature`` is the ambient one, the run starts at
    ``initial_temperature``, and ``measured_temperature`` (the record) is fitted too: its residuals
    are multiplied by ``temperature_weight`` [m/K] to share the displacement residuals' scale."""

    name: str
    time: np.ndarray
    displacement: np.ndarray
    temperature: float | Sampled
    waveform: Waveform
    role: str = "fit"
    nominal_temperature: float = math.nan
    measured_temperature: np.ndarray | None = None
    initial_temperature: float = math.nan
    temperature_weight: float = 1.0

    @property
    def n_residuals(self) -> int:
        return len(self.time) * (1 if self.measured_temperature is None else 2)

    @property
    def measured(self) -> np.ndarray:
        """The record the residuals are taken against (a force trace's is its force: identify/force.py)."""
        return self.displacement

    @staticmethod
    def offsets_in(traces) -> int:
        """Offsets fitted besides the parameters: one per trace (each record's zero)."""
        return len(traces)


def make_traces(experiments, model: Model):
    """One trace per experiment, driven as :func:`thermofriction.drive.drive` says (a self-heating run
    from where its record starts)."""
    traces = []
    for exp in experiments:
        if getattr(exp, "force", None) is not None:  # measured force under measured motion
            from .force import make_force_trace
            traces.append(make_force_trace(exp, model))
            continue
        d = drive(exp, model, start="record")
        trace = Trace(exp.file, np.ascontiguousarray(exp.time, float), np.ascontiguousarray(exp.displacement, float),
                      d.temperature, d.waveform, getattr(exp, "role", "fit"), float(exp.temperature))
        if model.heat is not None:
            trace.measured_temperature = d.measured_temperature
            trace.initial_temperature = d.initial_temperature
        traces.append(trace)
    return traces


_POOL = None


def pool() -> ThreadPoolExecutor:
    """One pool for all fits: the C core releases the GIL, so threads use every core."""
    global _POOL
    if _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=os.cpu_count() or 1, thread_name_prefix="thermofriction")
    return _POOL


class Problem:
    """Residuals r(theta) (offset of each trace profiled out) and their Jacobian dr/dtheta."""

    def __new__(cls, model=None, names=(), traces=(), *args, **kwargs):
        # traces of another kind of measurement bring their own residuals (force: identify/force.py)
        kind = getattr(traces[0], "problem_class", None) if cls is Problem and traces else None
        return super().__new__(kind or cls)

    def __init__(self, model: Model, names, traces, rtol=1e-8, parallel=True):
        self.model = model
        self.names = list(names)
        kinds = [target_of(model, n)[0] for n in self.names]
        self.targets = np.array([target_of(model, n) for n in self.names if target_of(model, n)[0] != KNOT],
                                dtype=np.int32).reshape(-1, 3)
        # At a constant temperature a temperature law (Model I's laws, Model II's dF) acts only through
        # its value there: the sensitivities to that value, times the law's derivatives in what is
        # fitted, are those to the coefficients at a fraction of the cost (Model I: 3 columns, not 6)
        # -- and the only way to a breakpoint's, which the core has no sensitivity to.
        self.chain = None
        thermal = [n for n, k in zip(self.names, kinds) if k in (_LAW, _DF, KNOT)]
        constant = model.heat is None and all(isinstance(t.temperature, (int, float)) for t in traces)
        if KNOT in kinds and not constant:
            raise InputError("dF's breakpoints can be fitted only on runs at constant temperature "
                             "(no temperature signal, no self-heating)")
        if thermal and constant:
            through = ["dF.value"] if isinstance(model.thermal, ModelII) else \
                sorted({split_name(n)[0] for n in thermal})
            self.chain = through + [n for n in self.names if n not in thermal]
            at = _at_temperature(model, float(traces[0].temperature))
            self.chain_targets = np.array([target_of(at, n) for n in self.chain], dtype=np.int32).reshape(-1, 3)
        self.traces = traces
        self.rtol = rtol
        self.parallel = parallel
        self.n_points = sum(len(t.time) for t in traces)
        self.nfev = 0
        self.njev = 0
        self._seconds = {}  # (trace, with sensitivities): its last run's wall time, for _run_all

    def _model(self, theta):
        """The model at theta, or None where it must not be simulated: built and checked once per
        evaluation, not once per trace."""
        try:
            model = with_values(self.model, dict(zip(self.names, theta)))
        except InputError:  # a step that breaks a rule between parameters (fs >= fc, z_ba < fc/sigma0)
            return None
        if model.unphysical_over_range():  # never step where the fitted model would not load or run
            return None
        return model

    def _run(self, model: Model, trace: Trace, theta, jac):
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
                _bridge.run(spec, trace.time, out, method="dopri5", rtol=self.rtol, max_steps=_MAX_STEPS)
                S = None
            else:
                targets = self.targets
                if self.chain is not None:  # the model at the run's temperature, sensitivities to its values
                    model_T = _at_temperature(model, float(trace.temperature))
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
                atol_y = self.rtol * scale
                atol_s = atol_y[:, None] / np.maximum(np.abs(theta), 1e-300)[None, :]
                nstate = len(scale)
                sens = np.empty((n_out, nstate, len(theta)))
                _bridge.run_sensitivities(spec, targets, trace.time, out, sens, rtol=self.rtol,
                                          atol=np.concatenate([atol_y, atol_s.ravel()]), max_steps=_MAX_STEPS)
                S = sens[:, _bridge.state_index(model, "x_e"), :]
                if self.chain is not None:
                    S = S @ self._chain_matrix(model, float(trace.temperature))
                S_T = sens[:, _bridge.state_index(model, "T"), :] if heated else None
        except _bridge.CoreFailure:
            return None, None
        d = out[:, _bridge.OUTPUT_COLUMN["displacement"]] - trace.displacement
        r = d - d.mean()
        if S is not None:
            S = S - S.mean(axis=0)
        if trace.measured_temperature is not None:
            w = trace.temperature_weight
            r = np.concatenate([r, w * (out[:, _bridge.OUTPUT_COLUMN["temperature"]] - trace.measured_temperature)])
            if S is not None:
                S = np.concatenate([S, w * S_T])
        return r, S

    def _chain_matrix(self, model: Model, T: float) -> np.ndarray:
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

    def evaluate(self, theta, jac=False):
        """(r, J) at theta; r is None when a simulation failed (the parameters are implausible)."""
        theta = np.asarray(theta, float)
        model = self._model(theta)
        self.nfev += 1
        self.njev += int(jac)
        if model is None:
            return None, None
        if self.parallel and len(self.traces) > 1:
            results = self._run_all(model, theta, jac)
        else:
            results = [self._run(model, tr, theta, jac) for tr in self.traces]
        if any(r is None for r, _ in results):
            return None, None
        r = np.concatenate([r for r, _ in results])
        J = np.concatenate([S for _, S in results]) if jac else None
        return r, J

    def _run_all(self, model, theta, jac):
        """Every trace's run on the pool, the longest first (by its last run's time, or its length):
        five runs on two cores, one of them twice as long as the others, take 3 units of time this way
        and up to 3.8 in the traces' order, where the long one can start last."""
        def timed(i):
            t0 = time.perf_counter()
            out = self._run(model, self.traces[i], theta, jac)
            self._seconds[(i, jac)] = time.perf_counter() - t0
            return out
        order = sorted(range(len(self.traces)),
                       key=lambda i: -self._seconds.get((i, jac), 1e-9 * len(self.traces[i].time)))
        results = [None] * len(self.traces)
        for i, out in zip(order, pool().map(timed, order)):
            results[i] = out
        return results

    def per_trace(self, theta):
        theta = np.asarray(theta, float)
        model = self._model(theta)
        if model is None:
            return [None] * len(self.traces)
        return [self._run(model, tr, theta, False)[0] for tr in self.traces]


def _at_temperature(model: Model, T: float) -> Model:
    """The model at one constant temperature: Model I's laws' values there as plain parameters,
    Model II's dF as a constant."""
    if isinstance(model.thermal, ModelII):
        return dataclasses.replace(model, thermal=ModelII(Const(float(model.thermal.dF(T)))))
    values = model.parameters_at(T)
    return dataclasses.replace(model, friction=dataclasses.replace(model.friction, **{n: values[n] for n in model.laws}),
                               thermal=None)


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


@dataclasses.dataclass
class Transform:
    """Positive parameters are fitted as log(theta), the others as theta / |theta0|."""

    log: np.ndarray
    scale: np.ndarray

    def to_phi(self, theta):
        theta = np.asarray(theta, float)
        return np.where(self.log, np.log(np.where(self.log, theta, 1.0)), theta / self.scale)

    def to_theta(self, phi):
        phi = np.asarray(phi, float)
        return np.where(self.log, np.exp(np.where(self.log, phi, 0.0)), phi * self.scale)

    def dtheta_dphi(self, theta):
        return np.where(self.log, theta, self.scale)

    def bounds(self, params, theta0):
        """Bounds in phi; a log parameter stays within e^+-30 of its initial value, so that
        a parameter the data do not determine cannot run off to 0 or infinity."""
        lo = np.array([p.min for p in params])
        hi = np.array([p.max for p in params])
        with np.errstate(divide="ignore"):
            lo_phi = np.where(self.log, np.log(np.maximum(lo, 0.0)), lo / self.scale)
            hi_phi = np.where(self.log, np.log(hi), hi / self.scale)
        start = self.to_phi(theta0)
        lo_phi = np.where(self.log, np.maximum(lo_phi, start - 30.0), lo_phi)
        hi_phi = np.where(self.log, np.minimum(hi_phi, start + 30.0), hi_phi)
        return lo_phi, hi_phi


#: the tolerance of the first, coarse stage of a fit, and of the fits that only start another one
COARSE_RTOL = 1e-6
#: a step that moves the parameters by less than this many standard errors (in the joint, Mahalanobis,
#: sense) is not worth its simulation: the fit stops there if its misfit is at the noise, and takes it
#: on the linearized model (_last_step). The linearization's error grows as the step's square: a poorly
#: determined sigma1 (a standard error of a third of its value) left 0.72 standard errors of a 0.58 one,
#: so 0.2 leaves ~0.08 at worst, under the 0.1 this rule stopped at, without the step, before
SMALL_STEP = 0.2
#: the same for a fit that only starts another one, and the step under which the first, coarse stage
#: (rtol 1e-6) ends once it stops converging: its integration error alone can make the Gauss-Newton step
#: ~0.1-1 standard errors (0.1-0.2 on the identification benchmark's Model II data)
COARSE_STEP = 1.0


class _Converged(Exception):
    """Raised inside the least-squares iteration at a point that is already the optimum."""

    def __init__(self, phi, step):
        self.phi, self.step = phi, step


def gauss_newton_length(qr, R) -> float:
    """The length of the Gauss-Newton step from where residuals r = Q qr + (the rest) and Jacobian
    J = Q R were taken, in standard errors: on residuals in units of the noise, |J dx| (the cost it
    would remove is half its square) bounds every parameter's move divided by its standard error."""
    dx, *_ = np.linalg.lstsq(R, -qr, rcond=None)
    return float(np.linalg.norm(R @ dx))


def _compressed(r, J, transform: Transform, theta, scale):
    """The residuals r and their Jacobian J = dr/dtheta at theta, in units of the noise (``scale``) and
    in the fitted coordinates phi: (f, G), n + 1 rows, with |f| = |r|, G^T f = J^T r and G^T G = J^T J
    (r, J so scaled). Everything the trust-region iteration uses, so that it takes the same steps, but
    at the cost of n + 1 rows instead of one per sample (its SVD and products on 10^5 x 6 matrices cost
    more than a short simulation)."""
    r = r / scale
    J = J * (transform.dtheta_dphi(theta)[None, :] / scale)
    Q, R = np.linalg.qr(J)
    qr = Q.T @ r
    rest = float(np.linalg.norm(r - Q @ qr))
    return np.append(qr, rest), np.vstack([R, np.zeros((1, J.shape[1]))])


def _least_squares(problem: Problem, transform: Transform, phi0, bounds, max_nfev, tight, scale,
                   small_step=SMALL_STEP, stall_step=None):
    """SciPy's trust-region least squares on residuals divided by ``scale`` (the data's noise level):
    its stopping tests then mean the same on every dataset, whatever the units and magnitudes
    (on residuals in metres, an absolute gradient test is met at any start).

    Besides SciPy's tests, it stops at the first evaluated point whose misfit is at the noise and from
    which the Gauss-Newton step is below ``small_step`` standard errors (not when ``tight``), and takes that
    step on the linearized model (_last_step) instead of simulating it. With ``stall_step``
    (a coarse stage), also where the step is below that and no shorter than half the last one: the
    stage's own integration error is then what is left, for the next stage to remove. The returned
    result carries ``evaluated``: the last few points' unscaled (r, J), so that the caller's
    evaluation at the optimum (for the intervals) is not simulated twice."""
    cache = {}
    best_cost = [math.inf]
    last_step = [math.inf]

    def both(phi):
        key = phi.tobytes()
        if key not in cache:
            if len(cache) >= 4:
                cache.pop(next(iter(cache)))
            theta = transform.to_theta(phi)
            r, J = problem.evaluate(theta, jac=True)
            if r is None:  # a failed simulation: a large, flat residual pushes the step back
                f = np.zeros(len(phi) + 1)
                f[-1] = 1e3 * max(_y_scale(problem), 1e-12) / scale * math.sqrt(problem.n_points)
                G = np.zeros((len(phi) + 1, len(phi)))
            else:
                f, G = _compressed(r, J, transform, theta, scale)
            cache[key] = (f, G, r, J)
            cost = 0.5 * float(f @ f)
            if (r is not None and not tight and cost <= best_cost[0] + 0.5
                    and math.sqrt(2.0 * cost / max(r.size, 1)) <= AT_NOISE):
                step = gauss_newton_length(f[:-1], G[:-1])
                if step < small_step or (stall_step is not None and last_step[0] / 2 < step < stall_step):
                    raise _Converged(phi.copy(), step)
                last_step[0] = step
            best_cost[0] = min(best_cost[0], cost)
        return cache[key]

    # stop where the objective's own noise (solver tolerance) starts: tighter only buys wandering
    # along directions the data do not determine
    # (tight: down to the solver's own floor, for checks against noise-free data)
    tol = 1e-15 if tight else max(1e-10, 10 * problem.rtol)
    # on residuals of unit noise, the scaled gradient is the residuals' projection on each parameter's
    # direction: below 1e-4 a further step would move the parameters by ~1e-4 of their standard errors
    try:
        res = optimize.least_squares(lambda p: both(p)[0], phi0, jac=lambda p: both(p)[1], bounds=bounds,
                                     method="trf", x_scale="jac", ftol=tol, xtol=tol,
                                     gtol=1e-15 if tight else 1e-4, max_nfev=max_nfev)
    except _Converged as stop:
        # the step itself is taken where the linearization holds it (a longer one, where a coarse
        # stage or a fit that only starts another one stops, is left to what follows)
        linear = stop.step < SMALL_STEP
        x, f = _last_step(cache, transform, stop.phi, bounds) if linear else (stop.phi, cache[stop.phi.tobytes()][0])
        res = optimize.OptimizeResult(
            x=x, fun=f, cost=0.5 * float(f @ f), success=True, status=1,
            message=f"the Gauss-Newton step is below {small_step:g} standard errors at a misfit at the noise"
                    + ("; taken on the linearized model" if linear else ""))
    res.evaluated = {k: v[2:] for k, v in cache.items()}
    return res


def _last_step(cache, transform: Transform, phi, bounds):
    """The Gauss-Newton step from the evaluated point phi, taken on the linearized model (within the
    bounds), with its residuals r + J dx: taken where that step is below SMALL_STEP standard errors, a
    length at which the linearization's error is well under the step (see SMALL_STEP). Simulating the point
    again would only confirm it; the Jacobian is kept (it changes by a fraction of that). Returns
    the new point and its compressed residuals; the cache gets its (f, G, r, J)."""
    f, G, r, J = cache[phi.tobytes()]
    dphi, *_ = np.linalg.lstsq(G[:-1], -f[:-1], rcond=None)
    x = np.clip(phi + dphi, bounds[0], bounds[1])
    dphi = x - phi
    f_new = np.append(f[:-1] + G[:-1] @ dphi, f[-1])
    r_new = r + (J * transform.dtheta_dphi(transform.to_theta(phi))[None, :]) @ dphi
    cache[x.tobytes()] = (f_new, G, r_new, J)
    return x, f_new


def _y_scale(problem):
    return max(float(np.ptp(t.measured)) for t in problem.traces)


def residual_scale(traces) -> float:
    """The scale residuals are measured in: the displacement noise estimated from the data (pooled
    over the traces), at least 1e-6 of the largest displacement range (noise-free data)."""
    noise = [noise_level(t.measured) for t in traces]
    noise = [s for s in noise if math.isfinite(s)]
    pooled = math.sqrt(sum(s * s for s in noise) / len(noise)) if noise else 0.0
    span = max(float(np.ptp(t.measured)) for t in traces)
    return max(pooled, 1e-6 * span, 1e-300)


@dataclasses.dataclass
class FitOutcome:
    theta: np.ndarray
    r: np.ndarray
    J: np.ndarray
    nfev: int
    njev: int
    success: bool
    message: str
    starts: int
    wall_time: float


def one_blas_thread(function):
    """Runs ``function`` with BLAS on one thread. The fits' linear algebra is on a few columns, and the
    cores belong to the simulations running beside it: OpenBLAS's threads, spinning between calls,
    took them (the benchmark's Model II: 1.7 s with them, 1.2 s without)."""
    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        from threadpoolctl import threadpool_limits
        with threadpool_limits(limits=1, user_api="blas"):
            return function(*args, **kwargs)
    return wrapper


@one_blas_thread
def fit(model: Model, params: Parameters, traces, *, rtol=1e-8, starts=8, seed=0, max_nfev=60,
        tight=False, progress=None, near=False, small_step=SMALL_STEP) -> FitOutcome:
    """Fits the varying parameters; returns the optimum with its residuals and Jacobian.

    ``near``: the start is known to be within a standard error or so of the optimum (a refinement from
    fits that already converged): no coarse stage at rtol 1e-6, whose integration error is of that size.
    ``small_step``: the fit stops where the Gauss-Newton step is below this many standard errors at a
    misfit at the noise (COARSE_STEP for a fit that only starts another one)."""
    t_start = time.perf_counter()
    varying = params.varying
    if not varying:
        raise InputError("no parameter to fit (all are fixed)")
    names = [p.name for p in varying]
    theta0 = np.array([p.value for p in varying])
    transform = Transform(np.array([p.positive for p in varying]),
                          np.array([abs(v) if v != 0 else 1.0 for v in theta0]))
    lo, hi = transform.bounds(varying, theta0)
    phi0 = np.clip(transform.to_phi(theta0), lo, hi)
    one_trace = len(traces) == 1

    scale = residual_scale(traces)
    residual_count = sum(t.n_residuals for t in traces)

    def run(phi_start):
        # far from the optimum the Jacobian need not be precise: converge at rtol 1e-6 (about
        # half the cost per run), then polish at the requested tolerance
        problem = Problem(model, names, traces, rtol=rtol, parallel=not one_trace)
        phi_first = phi_start
        if rtol < COARSE_RTOL and not near:
            coarse = Problem(model, names, traces, rtol=COARSE_RTOL, parallel=not one_trace)
            first = _least_squares(coarse, transform, phi_start, (lo, hi), min(max_nfev, 40), False, scale,
                                   stall_step=COARSE_STEP)
            phi_start = first.x
            problem.nfev, problem.njev = coarse.nfev, coarse.njev
        res = _least_squares(problem, transform, phi_start, (lo, hi), max_nfev if tight or near else 15, tight,
                             scale, small_step)
        res.moved = bool(np.any(res.x != phi_first))
        return res, problem

    def at_noise(res):  # residuals at the data's noise: another start cannot do meaningfully better
        return math.sqrt(2.0 * res.cost / max(residual_count, 1)) <= AT_NOISE

    # The initial guess first. Only if it does not reach the noise, the global phase: screen a Latin
    # hypercube around it (a decade either way for log parameters, +-100 % for the others) by cost
    # alone, then refine the best few. (A start off in a direction the data hardly determine, sigma1,
    # can screen best and yet take ten times longer to converge to the same optimum.)
    runs = [run(phi0)]
    screen = Problem(model, names, traces, rtol=max(rtol, COARSE_RTOL), parallel=not one_trace)
    n_candidates = 1
    if starts > 1 and not at_noise(runs[0][0]):
        width = np.where(transform.log, math.log(10.0), 1.0)
        sample = stats.qmc.LatinHypercube(d=len(phi0), seed=seed).random(starts - 1)
        candidates = [np.clip(phi0 + (2 * u - 1) * width, lo + 1e-9, hi - 1e-9) for u in sample]
        n_candidates += len(candidates)

        def cost(phi):
            r, _ = screen.evaluate(transform.to_theta(phi))
            return math.inf if r is None else float(r @ r)

        costs = list(pool().map(cost, candidates)) if one_trace else [cost(c) for c in candidates]
        order = np.argsort(costs)
        n_refine = min(max(os.cpu_count() or 1, 2), 3) if one_trace else 1  # one per core
        chosen = [candidates[i] for i in order[:n_refine] if math.isfinite(costs[i])]
        if progress:
            progress(f"the initial guess is not at the noise: {len(candidates)} more starts screened; refining "
                     f"{len(chosen)}")
        if one_trace and len(chosen) > 1:
            runs += list(pool().map(run, chosen))
        else:
            runs += [run(c) for c in chosen]
    best, best_problem = min(runs, key=lambda rp: rp[0].cost)
    theta = transform.to_theta(best.x)
    # the residuals and Jacobian at the optimum, on the full data at the requested tolerance: the last
    # iteration's, if it evaluated them there
    r, J = best.evaluated.get(best.x.tobytes()) or best_problem.evaluate(theta, jac=True)
    if r is None:
        raise ComputationError("the fit ended where the model cannot be simulated; try another initial guess")
    nfev = screen.nfev + sum(p.nfev for _, p in runs)
    njev = sum(p.njev for _, p in runs)
    success, message = bool(best.success and best.status > 0), best.message
    if not best.moved and math.sqrt(float(r @ r) / r.size) > ADEQUATE_RATIO * scale:
        # a small gradient at a start that does not fit the data is not convergence
        success, message = False, f"stopped at its starting point ({message})"
    return FitOutcome(theta, r, J, nfev, njev, success, message, n_candidates, time.perf_counter() - t_start)


def uncertainty(params: Parameters, outcome: FitOutcome, traces, model: Model):
    """Standard errors, 95 % intervals and correlations from the Jacobian at the optimum.

    cov = s^2 (J^T J)^-1 by SVD of the column-scaled Jacobian; a direction the data do not
    determine (singular value below 1e-9 of the largest) gives the parameters on it an infinite
    error instead of a falsely tight one. s^2 is inflated by (1 + rho)/(1 - rho), rho the residuals'
    lag-1 autocorrelation, so that coloured (non-white) residuals do not make the intervals
    too narrow. Returns the correlation matrix and warnings."""
    varying = params.varying
    theta, r, J = outcome.theta, outcome.r, outcome.J
    n, p = J.shape
    dof = max(n - p - traces[0].offsets_in(traces), 1)
    s2 = float(r @ r) / dof
    rhos, start = [], 0
    for tr in traces:
        seg = r[start:start + tr.n_residuals]
        start += tr.n_residuals
        if len(seg) > 3 and np.dot(seg, seg) > 0:
            rhos.append(float(np.dot(seg[1:], seg[:-1]) / np.dot(seg, seg)))
    rho = min(max(float(np.mean(rhos)) if rhos else 0.0, 0.0), 0.99)
    inflation = (1 + rho) / (1 - rho)
    col = np.linalg.norm(J, axis=0)
    col[col == 0] = 1.0
    U, S, Vt = np.linalg.svd(J / col, full_matrices=False)
    bad = S <= S[0] * 1e-9 if S.size and S[0] > 0 else np.ones_like(S, bool)
    inv = np.where(bad, 0.0, 1.0 / np.where(bad, 1.0, S) ** 2)
    cov = (Vt.T * inv) @ Vt / np.outer(col, col) * s2 * inflation
    var = np.diag(cov).copy()
    loading = (Vt[bad] ** 2).sum(axis=0) if bad.any() else np.zeros(p)
    var[loading > 1e-6] = math.inf
    se = np.sqrt(var)
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(se, se)
    corr[~np.isfinite(corr)] = np.nan
    np.fill_diagonal(corr, 1.0)
    tq = float(special.stdtrit(dof, 0.975))  # Student's t quantile (scipy.stats takes 0.3 s to import)
    warnings = []
    for i, par in enumerate(varying):
        par.value = float(theta[i])
        par.stderr = float(se[i])
        if not math.isfinite(se[i]):
            par.ci95 = (0.0 if par.positive else -math.inf, math.inf)
            warnings.append(f"'{par.name}' is not identifiable from these data (its interval is infinite)")
            continue
        if par.positive:
            f = math.exp(min(tq * se[i] / theta[i], 700.0))
            par.ci95 = (theta[i] / f, theta[i] * f)
        else:
            par.ci95 = (theta[i] - tq * se[i], theta[i] + tq * se[i])
        if se[i] > 0.5 * abs(theta[i]):
            rel = f"{100 * se[i] / abs(theta[i]):.0f} % of its value" if theta[i] else f"{se[i]:.3g} around 0"
            warnings.append(f"'{par.name}' is poorly determined by these data (standard error {rel})")
    for par in params.values():
        if not par.vary:
            par.stderr, par.ci95 = 0.0, (par.value, par.value)
        if not par.unit:
            par.unit = unit_of(model, par.name)
    return corr, warnings, {"dof": dof, "residual_std": math.sqrt(s2), "autocorrelation": rho,
                            "variance_inflation": inflation}
