"""The linear terms and the delay of a drive's command (measurements/command.py explains the measurement): the
motion's acceleration (Savitzky-Golay, :func:`accel_window`) and its mean over each held sample
(:func:`held_acceleration`), the quadrature of the friction's mean over each held sample (:func:`hold_nodes`,
:func:`hold_means`), the command shifted in time, the columns of the linear first estimate and their least squares
over candidate delays (:func:`delay_scan`), the inertia's and the offsets' columns (:func:`nuisance_columns`) and the
delay profiled out of a fit (:class:`DelaySearch`)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._lazy import lazy
from ..data.motion import motion_waveform, on_uniform_grid
from ..fitting.problem import Trace
from .delay import search_range

signal = lazy("scipy.signal")

#: the Savitzky-Golay acceleration's polynomial degree, and its window's bounds [samples, odd] (accel_window)
ACCEL_ORDER = 2
MIN_ACCEL_WINDOW, MAX_ACCEL_WINDOW = 3, 51
#: the acceleration's noise may bias J by at most this fraction (its variance over the acceleration's)
ACCEL_BIAS = 1e-3
#: the delay is read off the sliding samples, faster than this fraction of the 95th percentile speed
SCAN_SPEED_FRACTION = 0.2
#: sliding samples for the sign of the velocity in the linear first estimate: faster than this fraction of the
#: 95th percentile speed (slower ones ramp linearly through zero, so that noise at rest does not flip it)
SIGN_FRACTION = 0.02
#: ``auto``: a delay read off the data within this many sampling intervals is not applied (0). A quarter: the delay
#: of point samples of a torque, read as held ones, is their transport delay less half a sample (-T/2 without
#: one: applied), and a held command's without a transport delay is 0 (not applied)
MIN_DELAY_SAMPLES = 0.25
#: the friction's mean over a held sample [t_k, t_k+1]: Gauss-Legendre's three nodes on each half of it (where the
#: driving velocity, piecewise constant, changes: data/motion.py motion_waveform), as fractions of the interval, and
#: their weights (summing to 1). Exact for a polynomial of degree 5 on each half; on a bristle's relaxation
#: exp(-lambda t) within each half (h = dt/2) the error is 1e-5 of its amplitude for lambda h <= 2, 1e-4 at 3 and at
#: most 2 % (lambda h 20 to 50; a relaxation that fast is over before the first node, its area 1/(lambda h) of the
#: half's)
_GAUSS = 0.5 * (1.0 + np.array([-math.sqrt(0.6), 0.0, math.sqrt(0.6)]))
HOLD_FRACTIONS = np.concatenate([0.5 * _GAUSS, 0.5 + 0.5 * _GAUSS])
HOLD_WEIGHTS = np.tile(np.array([5.0, 8.0, 5.0]) / 36.0, 2)


@dataclasses.dataclass
class CommandTrace(Trace):
    """A trace of a drive's command: ``measured`` is the command as recorded, ``acceleration`` the motion's mean
    over each held sample [m/s^2 or rad/s^2] (:func:`held_acceleration`), ``angle`` the recorded position at the
    middle of each held sample (a position ripple's, :func:`midpoints`); for point samples (``nodes`` None) both
    at the samples."""

    acceleration: np.ndarray | None = None
    #: the command as recorded, and the delay of the model it was made with (auto: the fit searches where it is not 0)
    command: np.ndarray | None = None
    delay: float = 0.0
    velocity: np.ndarray | None = None
    #: the times the friction is evaluated at, HOLD_FRACTIONS of each held sample (:func:`hold_nodes`); None: the
    #: samples (point samples of a continuous torque, ``[plant] command_hold = "none"``)
    nodes: np.ndarray | None = None


def velocity_noise(v, resolution=None) -> float:
    """The standard deviation of white noise on a uniformly sampled velocity: the median absolute deviation of
    its third differences (robust: a smooth motion's are ~dt^3 times its third derivative, a reversal's few are
    outliers), over sqrt(20) (a third difference of white noise has 20 times its variance); at least a quantised
    velocity's step over sqrt(12)."""
    d = np.diff(np.asarray(v, float), 3)
    mad = 1.4826 * float(np.median(np.abs(d - np.median(d)))) / math.sqrt(20.0) if d.size else 0.0
    return max(mad, (resolution or 0.0) / math.sqrt(12.0))


def accel_window(exp, held: bool = False) -> int:
    """The acceleration's Savitzky-Golay window for an experiment: the narrowest (odd, from MIN_ACCEL_WINDOW to
    MAX_ACCEL_WINDOW) whose noise -- the velocity's (:func:`velocity_noise`) through the window's coefficients h,
    variance sigma_v^2 sum h^2 -- is at most ACCEL_BIAS of the acceleration's own variance, else the widest.
    Why: noise in the regressor ``a`` biases J by the ratio of the two variances (attenuation), and a window
    wider than that needs blurs the fast motion after reversals into the friction's presliding (sigma1, the
    delay); the window depends only on the record, so that a fit and its validation take the same. ``held``: the
    window of :func:`held_acceleration` (h: the difference of the smoothing's coefficients one sample apart)."""
    dt, (v,) = on_uniform_grid(exp.time, exp.drive_velocity)
    noise2 = velocity_noise(v, getattr(exp, "velocity_resolution", None)) ** 2
    widest = min(MAX_ACCEL_WINDOW, v.size - (1 - v.size % 2))
    for w in range(MIN_ACCEL_WINDOW, widest + 1, 2):
        if held:
            s = signal.savgol_coeffs(w, ACCEL_ORDER)
            h2 = float(np.sum((np.append(s, 0.0) - np.append(0.0, s)) ** 2)) / dt ** 2
            a = np.diff(signal.savgol_filter(v, w, ACCEL_ORDER)) / dt
        else:
            h2 = float(np.sum(signal.savgol_coeffs(w, ACCEL_ORDER, deriv=1, delta=dt) ** 2))
            a = signal.savgol_filter(v, w, ACCEL_ORDER, deriv=1, delta=dt)
        if noise2 * h2 <= ACCEL_BIAS * max(float(np.var(a)) - noise2 * h2, 0.0):
            return w
    return max(widest, MIN_ACCEL_WINDOW)


def acceleration(exp, window: int | None = None) -> np.ndarray:
    """The acceleration of an experiment's driving motion at its samples (Savitzky-Golay, zero-phase; ``window``
    None: :func:`accel_window`)."""
    t = np.asarray(exp.time, float)
    dt, (v,) = on_uniform_grid(t, exp.drive_velocity)
    w = min(window or accel_window(exp), v.size - (1 - v.size % 2))
    if w <= ACCEL_ORDER:
        return np.gradient(np.asarray(exp.drive_velocity, float), t)
    a = signal.savgol_filter(v, w, ACCEL_ORDER, deriv=1, delta=dt)
    return np.interp(t, t[0] + dt * np.arange(v.size), a)


def held(model) -> bool:
    """Whether ``model`` reads a drive's command as held for a sample (``[plant] command_hold = "zero-order"``: the
    mean over the sample), not as point samples ("none")."""
    return getattr(model.plant, "command_hold", "zero-order") == "zero-order"


def held_acceleration(exp, window: int | None = None) -> np.ndarray:
    """The mean of the acceleration over each held sample [t_k, t_k+1]: ``(v(t_k+1) - v(t_k)) / (t_k+1 - t_k)``
    of the driving velocity smoothed by Savitzky-Golay (degree ACCEL_ORDER; ``window`` None: ``accel_window(exp,
    held=True)``; the narrowest, 3 samples, leaves the velocity as it is: the exact mean), the last sample's the one
    before's."""
    t, raw = np.asarray(exp.time, float), np.asarray(exp.drive_velocity, float)
    dt, (v,) = on_uniform_grid(t, raw)
    w = min(window or accel_window(exp, held=True), v.size - (1 - v.size % 2))
    smooth = signal.savgol_filter(v, w, ACCEL_ORDER) if w > ACCEL_ORDER else v
    # the smoothing's change moved back to the samples (the grid may end a rounding short of the last one)
    vt = raw + np.interp(t, t[0] + dt * np.arange(v.size), smooth - v)
    a = np.diff(vt) / np.diff(t)
    return np.append(a, a[-1:])


def hold_nodes(time) -> np.ndarray:
    """The times the friction's mean over each held sample [t_k, t_k+1] is taken from: HOLD_FRACTIONS of each
    interval, len(HOLD_FRACTIONS) (len(time) - 1) of them, increasing."""
    t = np.asarray(time, float)
    return (t[:-1, None] + np.diff(t)[:, None] * HOLD_FRACTIONS[None, :]).ravel()


def hold_means(values, n: int) -> np.ndarray:
    """The means over each held sample of ``values`` at :func:`hold_nodes` (a vector, or a matrix of columns) of a
    record of ``n`` samples: n rows, the last sample's the one before's (its interval lies beyond the record)."""
    y = np.asarray(values, float)
    m = np.tensordot(HOLD_WEIGHTS, y.reshape((n - 1, HOLD_WEIGHTS.size) + y.shape[1:]), axes=(0, 1))
    return np.concatenate([m, m[-1:]])


def node_experiment(exp):
    """``exp`` sampled at its hold nodes (the friction's simulation there): the same driving motion, its columns
    interpolated."""
    t, nodes = np.asarray(exp.time, float), hold_nodes(exp.time)

    def at(x):
        return None if x is None else np.interp(nodes, t, np.asarray(x, float))
    return dataclasses.replace(exp, time=nodes, displacement=at(exp.displacement), velocity=at(exp.velocity),
                               force=at(exp.force), temperature_signal=at(exp.temperature_signal),
                               input=exp.input if exp.input is not None else motion_waveform(
                                   t, exp.drive_velocity, float(exp.displacement[0])))


def midpoints(x) -> np.ndarray:
    """A sampled signal at the middle of each held sample: the mean of its ends, the last one extended."""
    x = np.asarray(x, float)
    mid = 0.5 * (x[:-1] + x[1:])
    return np.append(mid, x[-1] + 0.5 * (x[-1] - x[-2])) if x.size > 1 else x.copy()


def shifted(time, values, delay: float) -> np.ndarray:
    """``values(t - delay)`` at the sample times: linear interpolation, the end values held beyond the record."""
    t = np.asarray(time, float)
    return np.interp(t - delay, t, np.asarray(values, float)) if delay else np.asarray(values, float)


def sign_of(velocity) -> np.ndarray:
    """The velocity's sign, ramping linearly through zero below SIGN_FRACTION of the 95th percentile speed."""
    v = np.asarray(velocity, float)
    top = float(np.quantile(np.abs(v), 0.95)) if v.size else 0.0
    return np.clip(v / (SIGN_FRACTION * top), -1.0, 1.0) if top > 0 else np.zeros_like(v)


def coulomb_columns(exp, held: bool = True) -> np.ndarray:
    """The regressors of the linear first estimate ``u = J a + b + fc sgn(v) + sigma2 v``: over each held sample
    (a: :func:`held_acceleration`; v at its middle), else at the samples (point samples)."""
    if not held:
        v = exp.drive_velocity
        return np.column_stack([acceleration(exp), np.ones(v.size), sign_of(v), v])
    v = midpoints(exp.drive_velocity)
    return np.column_stack([held_acceleration(exp), np.ones(v.size), sign_of(v), v])


def sliding(exp) -> np.ndarray:
    """The samples faster than SCAN_SPEED_FRACTION of the 95th percentile speed (True)."""
    speed = np.abs(np.asarray(exp.drive_velocity, float))
    return speed > SCAN_SPEED_FRACTION * float(np.quantile(speed, 0.95))


def linear_fit(experiments, columns, delay: float, rows=None):
    """Least squares of the commands on ``columns`` (one matrix per experiment) at ``t + delay``, over
    ``rows`` (one mask per experiment; None: all): (coefficients, the sum of squared residuals, the number of
    samples)."""
    rows = rows or [slice(None)] * len(columns)
    A = np.vstack([np.column_stack([shifted(e.time, c, -delay) for c in cols.T])[m]
                   for e, cols, m in zip(experiments, columns, rows)])
    u = np.concatenate([np.asarray(e.force, float)[m] for e, m in zip(experiments, rows)])
    coef, *_ = np.linalg.lstsq(A, u, rcond=None)
    res = u - A @ coef
    return coef, float(res @ res), u.size


def delay_scan(experiments, columns, grid):
    """The delay of the commands on the motion: the sum of squared residuals of :func:`linear_fit` on the
    candidate delays of ``grid`` (dt, the integers k of the delays k dt: :func:`search_range`), a parabola
    through the least and its neighbours for the fraction. Only the sliding samples count (:func:`sliding`):
    around a reversal the friction's own lag (presliding) is what a rough friction model gets wrong, and a delay
    would take it up. Returns (delay [s], its standard error from the parabola's curvature, the coefficients
    there, the index of the least cost in the grid)."""
    exps = list(experiments)
    dt, ks = grid
    rows = [sliding(e) for e in exps]
    cost = np.array([linear_fit(exps, columns, k * dt, rows)[1] for k in ks])
    i = int(np.argmin(cost))
    frac, curvature = 0.0, math.nan
    if 0 < i < ks.size - 1:
        curvature = (cost[i - 1] - 2 * cost[i] + cost[i + 1]) / dt ** 2
        if curvature > 0:
            frac = float(np.clip(0.5 * (cost[i - 1] - cost[i + 1]) / (cost[i - 1] - 2 * cost[i] + cost[i + 1]),
                                 -0.5, 0.5))
    delay = (ks[i] + frac) * dt
    coef, S, n = linear_fit(exps, columns, delay, rows)
    dof = max(n - len(coef) - 1, 1)
    se = math.sqrt(2 * S / dof / curvature) if curvature > 0 else math.nan  # (S'' = 2 sum (dr/dd)^2)
    return delay, se, coef, i


def applied_delay(delay: float, dt: float) -> float:
    """The delay applied: ``delay`` where it exceeds MIN_DELAY_SAMPLES sampling intervals, else 0."""
    return delay if abs(delay) > MIN_DELAY_SAMPLES * dt else 0.0


def nuisance_columns(traces, policy: str) -> np.ndarray:
    """The linear parameters' columns over all traces: the acceleration (J), and the offsets the policy fits."""
    a = np.concatenate([tr.acceleration for tr in traces])
    sizes = [tr.n_residuals for tr in traces]
    if policy == "shared":
        offsets = [np.ones(a.size)]
    elif policy == "per-experiment":
        edges = np.cumsum([0] + sizes)
        offsets = [((np.arange(a.size) >= lo) & (np.arange(a.size) < hi)).astype(float)
                   for lo, hi in zip(edges[:-1], edges[1:])]
    else:
        offsets = []
    return np.column_stack([a] + offsets)


class DelaySearch:
    """The delay that leaves the least residuals ``P_d (y(t + d) - u(t))`` (y: the friction, P_d: the projection
    that profiles J and the offsets out, on the acceleration at t + d) over candidate delays ``k dt`` (``grid``:
    (dt, the integers k), delay.py search_range), refined by a parabola through the least cost and its
    neighbours; ``grid`` None: the one delay ``held`` [s]. The model's side is shifted, not the command:
    interpolating a noisy record between its samples would average its noise, and a delay half a sample off
    would look better than the true one. ``at``: the index of the least cost in the grid (its ends: no
    estimate)."""

    def __init__(self, traces, policy: str, grid=None, held: float = 0.0):
        self.traces = traces
        self.edges = np.cumsum([0] + [tr.n_residuals for tr in traces])
        self.dt = float(np.median(np.concatenate([np.diff(tr.time) for tr in traces])))
        self.ks = np.array([0]) if grid is None else grid[1]
        self.held = held if grid is None else 0.0
        offsets = [tr.held_offset if policy == "none" else 0.0 for tr in traces]
        self.u = np.concatenate([tr.command - h for tr, h in zip(traces, offsets)])
        self.X = nuisance_columns(traces, policy)
        self._Q = {}
        self.at = 0

    def shift(self, y, delay: float):
        """A concatenated vector (or matrix) at each trace's ``t + delay``."""
        if not delay:
            return y
        out = np.empty_like(y)
        for tr, lo, hi in zip(self.traces, self.edges[:-1], self.edges[1:]):
            seg = y[lo:hi].reshape(hi - lo, -1)
            out[lo:hi] = np.column_stack([shifted(tr.time, c, -delay) for c in seg.T]).reshape(y[lo:hi].shape)
        return out

    def project(self, y, delay: float = 0.0):
        if delay not in self._Q:
            self._Q[delay] = np.linalg.qr(self.shift(self.X, delay))[0]
        Q = self._Q[delay]
        return y - Q @ (Q.T @ y)

    def residuals(self, F, delay: float):
        """``P_d (F(t + d) - u(t))``."""
        return self.project(self.shift(F, delay) - self.u, delay)

    @property
    def searched(self) -> bool:
        """Whether the delay is searched (profiled out), not held."""
        return self.ks.size > 1

    def slope(self, F, delay: float):
        """The derivative by the delay of the model's side ``F + J a`` at ``t + delay`` (J by least squares there;
        central differences over half a sampling interval either way)."""
        J = float(np.linalg.lstsq(self.shift(self.X, delay), self.u - self.shift(F, delay), rcond=None)[0][0])
        side, h = F + J * self.X[:, 0], 0.5 * self.dt
        return (self.shift(side, delay + h) - self.shift(side, delay - h)) / (2 * h)

    def jacobian(self, F, J, delay: float):
        """The Jacobian of the residuals with J, the offsets and, where it is searched, the delay profiled out:
        ``P_d J(t + d)``, then projected off the delay's column ``P_d slope`` (variable projection, Kaufman's
        form: the delay moves with the parameters, and an interval that held it would be too narrow)."""
        out = self.project(self.shift(J, delay), delay)
        if self.searched:
            g = self.project(self.slope(F, delay), delay)
            gg = float(g @ g)
            if gg > 0:
                out = out - np.outer(g, g @ out) / gg
        return out

    def best(self, F):
        """(the best delay, the residuals there, its standard error) for the friction ``F`` at the samples."""
        cost = np.array([float(np.sum(self.residuals(F, self.held + k * self.dt) ** 2)) for k in self.ks])
        i = self.at = int(np.argmin(cost))
        frac, se = 0.0, math.nan
        if 0 < i < cost.size - 1:
            den = cost[i - 1] - 2 * cost[i] + cost[i + 1]
            if den > 0:
                frac = float(np.clip(0.5 * (cost[i - 1] - cost[i + 1]) / den, -0.5, 0.5))
                dof = max(F.size - self.X.shape[1] - 1, 1)
                se = math.sqrt(2 * cost[i] / dof / (den / self.dt ** 2))  # (S'' = 2 sum (dr/dd)^2)
        delay = float(self.held + (self.ks[i] + frac) * self.dt)
        return delay, self.residuals(F, delay), se


def delay_search(traces, policy: str, spec, model_delay: float) -> DelaySearch:
    """The search the spec asks for (delay.py): a value or none held; a range searched; auto searched over its
    range where the initial model has a delay (one beyond MIN_DELAY_SAMPLES was read off the data), else 0."""
    if spec.kind == "value" or spec.kind == "none" or (spec.kind == "auto" and not model_delay):
        return DelaySearch(traces, policy, held=spec.lo if spec.kind == "value" else 0.0)
    return DelaySearch(traces, policy, search_range(spec, [tr.time for tr in traces],
                                                    [tr.velocity for tr in traces],
                                                    [tr.acceleration for tr in traces]))


__all__ = ["CommandTrace", "DelaySearch", "delay_search", "acceleration", "held_acceleration", "hold_nodes",
           "hold_means", "held", "node_experiment", "midpoints", "HOLD_FRACTIONS", "HOLD_WEIGHTS", "shifted", "sign_of", "sliding", "delay_scan", "linear_fit", "coulomb_columns", "applied_delay", "nuisance_columns", "accel_window", "velocity_noise", "ACCEL_ORDER", "MIN_ACCEL_WINDOW", "MAX_ACCEL_WINDOW", "ACCEL_BIAS", "MIN_DELAY_SAMPLES", "SCAN_SPEED_FRACTION", "SIGN_FRACTION"]
