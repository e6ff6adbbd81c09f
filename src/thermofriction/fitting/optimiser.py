"""The optimiser (the layer above the problem): trust-region least squares on residuals in the data's noise
scale and in fitted coordinates (log for positive parameters), a coarse-then-fine tolerance schedule, a
multi-start global phase, and the linearized last step."""

from __future__ import annotations

import dataclasses
import functools
import math
import os
import time

import numpy as np

from .._lazy import lazy
from ..errors import ComputationError, InputError
from ..models import Model
from .parameters import Parameters
from .problem import Problem, in_context, pool
from .quality import ADEQUATE_RATIO, noise_level

optimize, stats = lazy("scipy.optimize"), lazy("scipy.stats")

#: RMSE within this factor of the noise: a fit at the noise, where the multi-start stops
AT_NOISE = 1.1
#: a direction of the parameters whose singular value is below this fraction of the largest is not determined by
#: the data (the column-scaled Jacobian's; uncertainty() gives the parameters on it an infinite error)
UNDETERMINED = 1e-9


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
#: on the linearized model (linearized_step). The linearization's error grows as the step's square: a poorly
#: determined sigma1 (a standard error of a third of its value) left 0.72 standard errors of a 0.58 one,
#: so 0.2 leaves ~0.08 at worst, under the 0.1 this rule stopped at, without the step, before
SMALL_STEP = 0.2
#: the same for a fit that only starts another one, and the step under which the first, coarse stage
#: (rtol 1e-6) ends once it stops converging: its integration error alone can make the Gauss-Newton step
#: ~0.1-1 standard errors (0.1-0.2 on the identification benchmark's Model II data)
COARSE_STEP = 1.0


#: the fine stage after a coarse one stops where its cost fell by less than STALL_COST times the misfit's
#: variance (in units of the noise's; cost = half the sum of squares in units of the noise) over its last
#: STALL_EVALUATIONS steps (improvements; refused trials do not count): a chi-square change of 0.2 s^2 in three
#: steps, where one standard error along any direction is 1 s^2. Look-alike force data (never at the noise) ran
#: the fine stage to its 15 evaluations moving the parameters by 1e-4 of their values, SciPy's relative ftol
#: (1e-7) under the integration's own noise
STALL_COST, STALL_EVALUATIONS = 0.1, 3
#: a run of the multi-start that comes within this many standard errors (the intervals' own, at the optimum's
#: misfit) of an optimum already found has landed on it: it stops there (_Landed), and that optimum is kept
LANDED = 1.0


class _Converged(Exception):
    """Raised inside the least-squares iteration at a point that is already the optimum."""

    def __init__(self, phi, step, why=None):
        self.phi, self.step, self.why = phi, step, why


class _Landed(Exception):
    """Raised inside the least-squares iteration at a point within LANDED standard errors of a known optimum."""

    def __init__(self, phi):
        self.phi = phi


@dataclasses.dataclass
class _Known:
    """An optimum already found, in fitted coordinates: phi, the R factor of its compressed Jacobian (residuals in
    units of the noise), and its misfit over the noise (its standard errors are that many times the noise's)."""

    phi: np.ndarray
    R: np.ndarray
    ratio: float

    def distance(self, phi) -> float:
        """How far ``phi`` is from this optimum, in its standard errors (the joint, Mahalanobis, sense)."""
        return float(np.linalg.norm(self.R @ (phi - self.phi))) / max(self.ratio, 1.0)


def gauss_newton_length(qr, R) -> float:
    """The length of the Gauss-Newton step from where residuals r = Q qr + (the rest) and Jacobian
    J = Q R were taken, in standard errors: on residuals in units of the noise, |J dx| (the cost it
    would remove is half its square) bounds every parameter's move divided by its standard error."""
    dx, *_ = np.linalg.lstsq(R, -qr, rcond=None)
    return float(np.linalg.norm(R @ dx))


def compressed(r, J, transform: Transform, theta, scale):
    """The residuals r and their Jacobian J = dr/dtheta at theta, in units of the noise (``scale``) and
    in the fitted coordinates phi: (f, G), n + 1 rows, with |f| = |r|, G^T f = J^T r and G^T G = J^T J
    (r, J so scaled). Everything the trust-region iteration uses, so that it takes the same steps, but
    at the cost of n + 1 rows instead of one per sample (its SVD and products on 10^5 x 6 matrices cost
    more than a short simulation). One QR of [J r], R alone (_r_factor): its last column is Q^T r and the part of r
    outside J's columns (the same numbers as forming Q and projecting r with it, at less than half the cost: on a
    joint's 20,000 samples the QR with Q took longer than the exact stepping of the whole record)."""
    r = r / scale
    J = J * (transform.dtheta_dphi(theta)[None, :] / scale)
    p = J.shape[1]
    if J.shape[0] <= p:  # (fewer samples than parameters: Q as it is)
        Q, R = np.linalg.qr(J)
        qr = Q.T @ r
        return np.append(qr, float(np.linalg.norm(r - Q @ qr))), np.vstack([R, np.zeros((1, p))])
    Ra = _r_factor(np.column_stack([J, r]))
    return np.append(Ra[:p, p], abs(float(Ra[p, p]))), np.vstack([Ra[:p, :p], np.zeros((1, p))])


#: rows of each block of the QR of a tall Jacobian (a block and its R factor stay in the cache)
QR_BLOCK = 2048


def _r_factor(A) -> np.ndarray:
    """The R factor of A's QR (its rows' signs aside, which change no product R^T R nor R^T of the last column): the
    blocks' R factors stacked and factored again (the tall-skinny QR). Orthogonal transforms as the one QR is, to
    rounding, in a third of the time on a joint's 20,000 x 11 (the one Householder QR streams the whole matrix from
    memory once per column)."""
    if A.shape[0] <= 2 * QR_BLOCK:
        return np.linalg.qr(A, mode="r")
    return np.linalg.qr(np.vstack([np.linalg.qr(A[i:i + QR_BLOCK], mode="r")
                                   for i in range(0, A.shape[0], QR_BLOCK)]), mode="r")


def _least_squares(problem: Problem, transform: Transform, phi0, bounds, max_nfev, tight, scale,
                   small_step=SMALL_STEP, stall_step=None, known=(), polish=False):
    """SciPy's trust-region least squares on residuals divided by ``scale`` (the data's noise level):
    its stopping tests then mean the same on every dataset, whatever the units and magnitudes
    (on residuals in metres, an absolute gradient test is met at any start).

    Besides SciPy's tests, it stops at the first evaluated point whose misfit is at the noise and from
    which the Gauss-Newton step is below ``small_step`` standard errors (not when ``tight``), and takes that
    step on the linearized model (linearized_step) instead of simulating it. With ``stall_step``
    (a coarse stage), also where the step is below that and no shorter than half the last one: the
    stage's own integration error is then what is left, for the next stage to remove. Where the misfit is above
    the noise (a model the data contradict, look-alike data), the steps are measured in standard errors at that
    misfit (the intervals', uncertainty.py: s^2 from the residuals): at 1.5 times the noise, a step of 0.2 of them
    is 0.3 of the noise's; the fine stage otherwise ran to its limit moving the parameters by 1e-4 of their values.
    With ``polish`` (the fine stage after a coarse one), also where its cost stalls (STALL_COST).
    With ``known`` (_Known optima), it stops at the first evaluated point within LANDED standard errors of one
    of them (``res.landed``): a run of the multi-start that lands on an optimum already found. The returned
    result carries ``evaluated``: the last few points' unscaled (r, J), so that the caller's
    evaluation at the optimum (for the intervals) is not simulated twice."""
    cache = {}
    best_cost, history = [math.inf], []  # history: the cost after each improvement
    last_step = [math.inf]
    n_residuals = max(sum(t.n_residuals for t in problem.traces), 1)

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
                f, G = compressed(r, J, transform, theta, scale)
            cache[key] = (f, G, r, J)
            cost = 0.5 * float(f @ f)
            if r is not None and any(k.distance(phi) < LANDED for k in known):
                raise _Landed(phi.copy())
            if r is not None and not tight and cost <= best_cost[0] + 0.5:
                ratio = math.sqrt(2.0 * cost / max(r.size, 1))
                step = gauss_newton_length(f[:-1], G[:-1]) / (1.0 if ratio <= AT_NOISE else ratio)
                if step < small_step or (stall_step is not None and last_step[0] / 2 < step < stall_step):
                    raise _Converged(phi.copy(), step)
                last_step[0] = step
            if r is not None and cost < best_cost[0]:  # an improvement: a step the trust region takes
                best_cost[0] = cost
                history.append(cost)
                # (refused trials do not count: a Model II fine stage with runs of them between real progress
                # stopped 0.2 % short of its optimum, and a refit downstream saw 0.2 % gain where it saw 4.3 %)
                if (polish and len(history) > STALL_EVALUATIONS
                        and history[-1 - STALL_EVALUATIONS] - cost < STALL_COST * max(2 * cost / n_residuals, 1)):
                    raise _Converged(phi.copy(), math.inf, f"the cost fell by less than {STALL_COST:g} of the "
                                     f"misfit's variance in {STALL_EVALUATIONS} steps")
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
        res.landed = False
    except _Converged as stop:
        # the step itself is taken where the linearization holds it (a longer one, where a coarse
        # stage or a fit that only starts another one stops, is left to what follows)
        linear = stop.step < SMALL_STEP
        x, f = linearized_step(cache, transform, stop.phi, bounds) if linear else (stop.phi, cache[stop.phi.tobytes()][0])
        res = optimize.OptimizeResult(
            x=x, fun=f, cost=0.5 * float(f @ f), success=True, status=1,
            message=stop.why or (f"the Gauss-Newton step is below {small_step:g} standard errors"
                                 + ("; taken on the linearized model" if linear else "")))
        res.landed = False
    except _Landed as stop:
        f = cache[stop.phi.tobytes()][0]
        res = optimize.OptimizeResult(x=stop.phi, fun=f, cost=0.5 * float(f @ f), success=True, status=1,
                                      message=f"within {LANDED:g} standard errors of an optimum already found")
        res.landed = True
    res.evaluated = {k: v[2:] for k, v in cache.items()}
    res.known = _known(cache, res.x)
    return res


def _given_run(first, names, transform, scale) -> list:
    """[(result, None)]: the optimum ``first`` (names, theta, r, J) of another fit of the same ``names`` as a run of
    this one would have ended there (``x``, ``cost``, ``known``, its residuals in ``evaluated``); [] where there is
    none, or it fits other parameters."""
    if first is None or list(first[0]) != list(names) or first[2] is None or first[3] is None:
        return []
    _, theta, r, J = first
    theta = np.asarray(theta, float)
    phi = transform.to_phi(theta)
    f, G = compressed(r, J, transform, theta, scale)
    res = optimize.OptimizeResult(x=phi, fun=f, cost=0.5 * float(f @ f), success=True, status=1, landed=False,
                                  message="the Gauss-Newton step is below the fit's threshold (the fit it was given)",
                                  moved=True, evaluated={phi.tobytes(): (r, J)})
    res.known = _Known(phi, G[:-1], float(np.linalg.norm(f)) / math.sqrt(max(len(r), 1)))
    return [(res, None)]


def _known(cache, phi):
    """The optimum ``phi`` as a _Known, from its compressed residuals in ``cache`` (None where they are not)."""
    if phi.tobytes() not in cache or cache[phi.tobytes()][2] is None:
        return None
    f, G = cache[phi.tobytes()][:2]
    return _Known(phi.copy(), G[:-1], float(np.linalg.norm(f)) / math.sqrt(max(len(cache[phi.tobytes()][2]), 1)))


def linearized_step(cache, transform: Transform, phi, bounds):
    """The Gauss-Newton step from the evaluated point phi, taken on the linearized model (within the
    bounds), with its residuals r + J dx: taken where that step is below SMALL_STEP standard errors, a
    length at which the linearization's error is well under the step (see SMALL_STEP). Simulating the point
    again would only confirm it; the Jacobian is kept (it changes by a fraction of that). Returns
    the new point and its compressed residuals; the cache gets its (f, G, r, J)."""
    f, G, r, J = cache[phi.tobytes()]
    # no step along a direction the data do not determine (a singular value below UNDETERMINED of the largest,
    # where uncertainty() gives an infinite error): there the linearized model says nothing, and the
    # least-squares step along it is as large as rounding makes it (a heat fit without a heater went from
    # R_th 1.6e4 to 1.5e-9 in one such step on one machine, not on another)
    dphi, *_ = np.linalg.lstsq(G[:-1], -f[:-1], rcond=UNDETERMINED)
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
    #: per parameter: "lower" / "upper" where the optimum is at a bound, else None; and the bounds in its units
    at_bound: list = dataclasses.field(default_factory=list)
    bounds: tuple = ()


_BLAS = []  # the threadpoolctl controller, made once: finding the loaded BLAS libraries took 5-12 ms a call


def _blas_controller():
    if not _BLAS:
        from threadpoolctl import ThreadpoolController
        optimize.OptimizeResult  # noqa: B018  (SciPy's BLAS loaded first: the fits use it)
        _BLAS.append(ThreadpoolController())
    return _BLAS[0]


def one_blas_thread(function):
    """Runs ``function`` with BLAS on one thread. The fits' linear algebra is on a few columns, and the
    cores belong to the simulations running beside it: OpenBLAS's threads, spinning between calls,
    took them (the benchmark's Model II: 1.7 s with them, 1.2 s without)."""
    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with _blas_controller().limit(limits=1, user_api="blas"):
            return function(*args, **kwargs)
    return wrapper


def _screened_starts(screen: Problem, transform: Transform, phi0, bounds, starts, seed, one_trace, progress):
    """The global phase: screen a Latin hypercube around ``phi0`` (a decade either way for log parameters,
    +-100 % for the others) by cost alone, and return the best few to refine (one per core on one trace, else
    one) with the number screened. (A start off in a direction the data hardly determine, sigma1, can screen
    best and yet take ten times longer to converge to the same optimum.)"""
    lo, hi = bounds
    width = np.where(transform.log, math.log(10.0), 1.0)
    sample = stats.qmc.LatinHypercube(d=len(phi0), seed=seed).random(starts - 1)
    candidates = [np.clip(phi0 + (2 * u - 1) * width, lo + 1e-9, hi - 1e-9) for u in sample]

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
    return chosen, len(candidates)


@one_blas_thread
def fit(model: Model, params: Parameters, traces, *, rtol=1e-8, starts=8, seed=0, max_nfev=None,
        tight=False, progress=None, near=False, small_step=SMALL_STEP, first=None, found=None) -> FitOutcome:
    """Fits the varying parameters; returns the optimum with its residuals and Jacobian.

    Parameters
    ----------
    model : Model
        The model the parameters are set in.
    params : Parameters
        The parameters; the varying ones are fitted, from their values, within their bounds.
    traces : list of Trace
        The measured runs (``make_traces``).
    rtol : float, default 1e-8
        The simulations' relative tolerance.
    starts : int, default 8
        The multi-start size (1: the local fit only).
    seed : int, default 0
        The multi-start's seed.
    max_nfev : int, optional
        The most evaluations of each least-squares stage (default: 40 for the coarse stage, 15 for the fine
        one, 60 for a ``near`` or ``tight`` fit; a fit at rtol 1e-6 or looser has only the coarse stage, with
        its 40: with 15, a start 2-3x off ran out of evaluations and went on to the multi-start, three times as
        many).
    tight : bool, default False
        Down to the solver's own floor (for checks against noise-free data), not only to the data's noise.
    progress : callable, optional
        Called with one line of text at each stage.
    near : bool, default False
        The start is known to be within a standard error or so of the optimum (a refinement from fits that
        already converged): no coarse stage at rtol 1e-6, whose integration error is of that size.
    small_step : float, default SMALL_STEP
        The fit stops where the Gauss-Newton step is below this many standard errors (at the fit's own misfit)
        (COARSE_STEP for a fit that only starts another one).
    first : tuple, optional
        (names, theta, r, J): the optimum of another fit of the same parameters on the same traces that started
        from these initial values (the records' heads' fit, refined on the whole records: model_i.py), which
        stands for the first run from them: the multi-start goes on from it, as from its own first run, and its
        runs stop where they land on it (a first run from the initial values walked 41 evaluations to it).
    found : list, optional
        Where given, the fit appends its optimum to it as ``first`` takes one.

    Returns
    -------
    FitOutcome
        The optimum, its residuals and Jacobian, the counts, and where it is at a bound.

    Raises
    ------
    InputError
        Bad arguments (an unknown parameter name, no parameter to fit, an initial value outside its bounds),
        named.
    ComputationError
        The fit failed (SolverError where a simulation stopped).
    """
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

    def run(phi_start, known=()):
        # far from the optimum the Jacobian need not be precise: converge at rtol 1e-6 (about
        # half the cost per run), then polish at the requested tolerance
        problem = Problem(model, names, traces, rtol=rtol, parallel=not one_trace)
        phi_first = phi_start
        coarse_only = rtol >= COARSE_RTOL and not near  # at the coarse tolerance: its one stage is the coarse one
        if rtol < COARSE_RTOL and not near:
            coarse = Problem(model, names, traces, rtol=COARSE_RTOL, parallel=not one_trace)
            first = _least_squares(coarse, transform, phi_start, (lo, hi), 40 if max_nfev is None else max_nfev, False, scale,
                                   stall_step=COARSE_STEP, known=known)
            problem.nfev, problem.njev = coarse.nfev, coarse.njev
            if first.landed:
                first.moved = True
                return first, problem
            phi_start = first.x
        fine = max_nfev if max_nfev is not None else 60 if tight or near else 40 if coarse_only else 15
        res = _least_squares(problem, transform, phi_start, (lo, hi), fine, tight, scale, small_step, known=known,
                             polish=rtol < COARSE_RTOL and not near and not tight)
        res.moved = bool(np.any(res.x != phi_first))
        return res, problem

    def at_noise(res):  # residuals at the data's noise: another start cannot do meaningfully better
        return math.sqrt(2.0 * res.cost / max(residual_count, 1)) <= AT_NOISE

    # The initial guess first. Only if it does not reach the noise, the global phase (_screened_starts).
    runs = _given_run(first, names, transform, scale) or [run(phi0)]
    screen = Problem(model, names, traces, rtol=max(rtol, COARSE_RTOL), parallel=not one_trace)
    n_candidates = 1
    if starts > 1 and not at_noise(runs[0][0]):
        chosen, n_screened = _screened_starts(screen, transform, phi0, (lo, hi), starts, seed, one_trace, progress)
        n_candidates += n_screened
        # a start that lands on the first run's optimum stops there: it would only have found that one again
        # (only an optimum: a first run stopped by its evaluation limit is still walking, and the start that
        # walks on past it was the multi-start's better answer)
        known = [runs[0][0].known] if runs[0][0].known is not None and runs[0][0].status > 0 else []
        each = functools.partial(run, known=known)
        if one_trace and len(chosen) > 1:  # (their evaluations count in the caller's tallies)
            runs += list(pool().map(in_context(each), chosen))
        else:
            runs += [each(c) for c in chosen]
    best, best_problem = min((rp for rp in runs if not rp[0].landed), key=lambda rp: rp[0].cost)
    theta = transform.to_theta(best.x)
    # the residuals and Jacobian at the optimum, on the full data at the requested tolerance: the last
    # iteration's, if it evaluated them there
    r, J = best.evaluated.get(best.x.tobytes()) or best_problem.evaluate(theta, jac=True)
    if found is not None:
        found.append((list(names), theta, r, J))
    if r is None:
        raise ComputationError("the fit ended where the model cannot be simulated; try another initial guess")
    nfev = screen.nfev + sum(p.nfev for _, p in runs if p is not None)
    njev = sum(p.njev for _, p in runs if p is not None)
    success, message = bool(best.success and best.status > 0), best.message
    if best.status == 0:
        message = f"{message} (the evaluation limit; raise it with --max-evaluations, max_evaluations=)"
    if not best.moved and math.sqrt(float(r @ r) / r.size) > ADEQUATE_RATIO * scale:
        # a small gradient at a start that does not fit the data is not convergence
        success, message = False, f"stopped at its starting point ({message})"
    span = np.where(np.isfinite(hi - lo), hi - lo, 1.0)
    at_bound = ["lower" if x <= a + 1e-9 * s else "upper" if x >= b - 1e-9 * s else None
                for x, a, b, s in zip(best.x, lo, hi, span)]
    return FitOutcome(theta, r, J, nfev, njev, success, message, n_candidates, time.perf_counter() - t_start,
                      at_bound, (transform.to_theta(lo), transform.to_theta(hi)))


__all__ = ["Transform", "fit", "FitOutcome", "residual_scale", "gauss_newton_length", "compressed",
           "linearized_step", "one_blas_thread", "AT_NOISE", "COARSE_RTOL", "SMALL_STEP", "COARSE_STEP", "LANDED",
           "STALL_COST", "STALL_EVALUATIONS"]
