"""A drive's command under a measured motion (docs/force-data.md#drives-without-a-torque-sensor): the force or
torque a drive was commanded (or its motor current times the torque constant) moves a single mass (a rotary
inertia) against friction, so that

    u(t - delay) = F(t) + J a(t) + offset

with F the friction of a prescribed-motion model driven by the measured motion, a the motion's acceleration, J
the mass (inertia), ``offset`` the command's bias and ``delay`` how late the drive realises its command. The
residuals are ``F + J a + offset - u(t - delay)``.

- **J and the offset** enter linearly: they are profiled out, as the force sensor's offset is -- the residuals
  and the Jacobian's columns projected onto the complement of the columns ``[a, 1]`` (per-experiment offsets:
  one column of ones per run; none: ``[a]`` and the model's own offset) -- and estimated with their standard
  errors at the optimum (identification/setup.py: command_finish). The fitted model keeps its prescribed motion and
  holds J, the offset and the delay in its ``[plant]`` (``inertia``, ``sensor_offset``, ``delay``), so that
  validation predicts a command from a model file alone.
- **The acceleration** is a Savitzky-Golay derivative (SciPy's ``savgol_filter``: a quadratic fitted by least
  squares over a window of samples, its slope at the centre) of the velocity that drives the model, on a uniform
  grid at the median sampling interval. A centred window is a symmetric (zero-phase) filter: it delays nothing,
  so that J a lines up with the friction; it averages the differentiation's noise over the window, and it blurs
  what changes within it (a lightly damped presliding ringing after a reversal: a 9-sample window shifted a 1 kHz
  servo's delay by 0.1 ms and doubled its sigma1). The window is chosen from each record (:func:`accel_window`):
  the narrowest whose noise biases J by at most ACCEL_BIAS. (Noise left in ``a`` is an error in a regressor and
  pulls J towards zero by its variance over the acceleration's: the position must resolve the acceleration.)
- **The delay** (identify's ``delay=``, measurements/delay.py): ``auto`` reads it off the data before the fit
  (:func:`delay_scan` over a range from the data) and uses it only where it exceeds about a sample
  (MIN_DELAY_SAMPLES), else it is 0, and the result says which; a range is searched within its bounds; a value
  is held; ``none`` is 0. The model's side is shifted (linear interpolation, the end values held beyond the
  record).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._lazy import lazy
from ..data.force import ForceExperiment
from ..data.motion import on_uniform_grid
from ..errors import InputError
from .base import Trace
from .delay import AUTO, search_range
from .force import Force

signal = lazy("scipy.signal")

#: the Savitzky-Golay acceleration's polynomial degree, and its window's bounds [samples, odd] (accel_window)
ACCEL_ORDER = 2
MIN_ACCEL_WINDOW, MAX_ACCEL_WINDOW = 3, 51
#: the acceleration's noise may bias J by at most this fraction (its variance over the acceleration's)
ACCEL_BIAS = 1e-3
#: a delay of less than this many sampling intervals is not applied (0)
MIN_DELAY_SAMPLES = 1.0
#: the delay is read off the sliding samples, faster than this fraction of the 95th percentile speed
SCAN_SPEED_FRACTION = 0.2
#: sliding samples for the sign of the velocity in the linear first estimate: faster than this fraction of the
#: 95th percentile speed (slower ones ramp linearly through zero, so that noise at rest does not flip it)
SIGN_FRACTION = 0.02


@dataclasses.dataclass
class CommandTrace(Trace):
    """A trace of a drive's command: ``measured`` is the command as recorded, ``acceleration`` the motion's
    [m/s^2 or rad/s^2]."""

    acceleration: np.ndarray | None = None
    #: the command as recorded, and whether the fit searches the delay (the model has one)
    command: np.ndarray | None = None
    search_delay: bool = False
    delay: float = 0.0
    velocity: np.ndarray | None = None


def velocity_noise(v, resolution=None) -> float:
    """The standard deviation of white noise on a uniformly sampled velocity: the median absolute deviation of
    its third differences (robust: a smooth motion's are ~dt^3 times its third derivative, a reversal's few are
    outliers), over sqrt(20) (a third difference of white noise has 20 times its variance); at least a quantised
    velocity's step over sqrt(12)."""
    d = np.diff(np.asarray(v, float), 3)
    mad = 1.4826 * float(np.median(np.abs(d - np.median(d)))) / math.sqrt(20.0) if d.size else 0.0
    return max(mad, (resolution or 0.0) / math.sqrt(12.0))


def accel_window(exp) -> int:
    """The acceleration's Savitzky-Golay window for an experiment: the narrowest (odd, from MIN_ACCEL_WINDOW to
    MAX_ACCEL_WINDOW) whose noise -- the velocity's (:func:`velocity_noise`) through the window's coefficients h,
    variance sigma_v^2 sum h^2 -- is at most ACCEL_BIAS of the acceleration's own variance, else the widest.
    Why: noise in the regressor ``a`` biases J by the ratio of the two variances (attenuation), and a window
    wider than that needs blurs the fast motion after reversals into the friction's presliding (sigma1, the
    delay); the window depends only on the record, so that a fit and its validation take the same."""
    dt, (v,) = on_uniform_grid(exp.time, exp.drive_velocity)
    noise2 = velocity_noise(v, getattr(exp, "velocity_resolution", None)) ** 2
    widest = min(MAX_ACCEL_WINDOW, v.size - (1 - v.size % 2))
    for w in range(MIN_ACCEL_WINDOW, widest + 1, 2):
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


def shifted(time, values, delay: float) -> np.ndarray:
    """``values(t - delay)`` at the sample times: linear interpolation, the end values held beyond the record."""
    t = np.asarray(time, float)
    return np.interp(t - delay, t, np.asarray(values, float)) if delay else np.asarray(values, float)


def sign_of(velocity) -> np.ndarray:
    """The velocity's sign, ramping linearly through zero below SIGN_FRACTION of the 95th percentile speed."""
    v = np.asarray(velocity, float)
    top = float(np.quantile(np.abs(v), 0.95)) if v.size else 0.0
    return np.clip(v / (SIGN_FRACTION * top), -1.0, 1.0) if top > 0 else np.zeros_like(v)


def coulomb_columns(exp) -> np.ndarray:
    """The regressors of the linear first estimate ``u = J a + b + fc sgn(v) + sigma2 v``."""
    v = exp.drive_velocity
    return np.column_stack([acceleration(exp), np.ones(v.size), sign_of(v), v])


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
    range where the initial model has a delay (one beyond about a sample was found before the fit), else 0."""
    if spec.kind == "value" or spec.kind == "none" or (spec.kind == "auto" and not model_delay):
        return DelaySearch(traces, policy, held=spec.lo if spec.kind == "value" else 0.0)
    return DelaySearch(traces, policy, search_range(spec, [tr.time for tr in traces],
                                                    [tr.velocity for tr in traces],
                                                    [tr.acceleration for tr in traces]))


def implied_friction(model, exp):
    """(velocity, friction) that a command record implies with ``model``'s inertia and delay: ``u(t) - J a(t +
    delay)`` against ``v(t + delay)`` (the offset left in, as a force sensor's is); a friction record as it is."""
    if not Command.recognises(exp):
        return exp.drive_velocity, exp.force
    d = model.plant.delay
    return (shifted(exp.time, exp.drive_velocity, -d),
            np.asarray(exp.force, float) - model.plant.inertia * shifted(exp.time, acceleration(exp), -d))


class Command(Force):
    """A drive's command (force, torque, or current times the torque constant) under a measured motion.

    Parameters
    ----------
    offset : {"shared", "per-experiment", "none"}, default "shared"
        The offset policy (OFFSETS): "shared", one fitted offset for all runs; "per-experiment", each run's own,
        estimated on it; "none", the model's own, held.
    ripple_phase : {"recorded", "per-run", "auto"}, default "recorded"
        The position ripple's angle, as for :class:`Force`.

    Raises
    ------
    InputError
        An offset policy that does not apply to these data; an unknown ripple phase.
    """

    name = "command"
    quantity = "drive command (force or torque)"
    #: how the fit takes the delay (delay.py; identify's delay=)
    delay = AUTO

    @staticmethod
    def recognises(exp) -> bool:
        return isinstance(exp, ForceExperiment) and exp.measured_quantity == "command"

    @property
    def removed(self) -> str:
        offset = {"shared": "the shared offset", "none": "the model's offset (held)",
                  "per-experiment": "each experiment's own offset"}[self.offset]
        return f"the inertia term J a and {offset} (fitted)"

    @property
    def caption(self) -> str:
        return super().caption.replace("the model's sensor offset removed", "the command predicted with the "
                                       "model's inertia term and offset")

    @property
    def footer(self) -> str:
        return super().footer.replace("the model's sensor offset ([plant] sensor_offset) removed", "the command "
                                      "predicted with the model's inertia term and offset ([plant] inertia, "
                                      "sensor_offset, at its delay)")

    @property
    def validation_removed(self) -> str:
        if self.offset == "per-experiment":
            return super().validation_removed
        return "the model's inertia term and offset ([plant] inertia, sensor_offset), as fitted"

    def offsets_in(self, traces) -> int:
        return super().offsets_in(traces) + 1  # the inertia

    def make_trace(self, exp, model) -> CommandTrace:
        tr = super().make_trace(exp, model)
        fields = {f.name: getattr(tr, f.name) for f in dataclasses.fields(tr)}
        return CommandTrace(**fields, acceleration=acceleration(exp), command=np.asarray(exp.force, float),
                            search_delay=model.plant.delay != 0, delay=model.plant.delay,
                            velocity=np.asarray(exp.drive_velocity, float))

    def profiled(self, traces, r, J):
        """The residuals and Jacobian with J and the offsets profiled out: projected onto the complement of the
        acceleration's and the offsets' columns (variable projection; the columns do not depend on the
        parameters, so the projected Jacobian is exact). Where the model has a delay, the delay is profiled out
        too: the one that leaves the least residuals for this friction (:class:`DelaySearch`), the friction and
        the acceleration taken at t + delay; the Jacobian is then that at the best delay (its gradient of the
        cost is exact, by the envelope theorem)."""
        search = self._search(traces)
        F = r + search.u  # (Force: r = F - measured, the command as recorded)
        delay = search.best(F)[0]
        return search.residuals(F, delay), None if J is None else search.project(search.shift(J, delay), delay)

    def _search(self, traces):
        key = (id(traces), len(traces), traces[0].delay, self.offset, self.delay)
        if getattr(self, "_cached", (None,))[0] != key:
            self._cached = (key, delay_search(traces, self.offset, self.delay, traces[0].delay))
        return self._cached[1]

    def checks(self, model, traces) -> list:
        return super().checks(model, traces) + [
            "for a drive's command: check the torque constant, and that the position resolves the acceleration "
            "(docs/force-data.md#drives-without-a-torque-sensor)"]

    def check_model(self, model, experiments):
        super().check_model(model, experiments)
        if not model.plant.inertia > 0:
            raise InputError("a drive's command is predicted with the moving part's inertia ([plant] inertia), and "
                             "this model has none: fit the model to command data (identify), or give it")

    def predicted(self, model, exp, rtol=1e-8, fast=False):
        """(predicted, measured): ``F + J a + offset`` at ``t + delay``, and the command as recorded."""
        pred = self.friction_of(model, exp, rtol, fast) + model.plant.inertia * acceleration(exp) + model.plant.sensor_offset
        return shifted(exp.time, pred, -model.plant.delay), np.asarray(exp.force, float)

    def validation_extras(self, model) -> dict:
        return {"sensor_offset": model.plant.sensor_offset, "inertia": model.plant.inertia,
                "delay": model.plant.delay}


__all__ = ["Command", "CommandTrace", "DelaySearch", "delay_search", "implied_friction", "acceleration", "shifted",
           "delay_scan", "linear_fit", "coulomb_columns", "applied_delay", "nuisance_columns", "accel_window",
           "velocity_noise", "ACCEL_BIAS", "MIN_DELAY_SAMPLES"]
