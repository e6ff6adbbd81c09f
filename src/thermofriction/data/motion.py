"""The motion that drives a force experiment's model (docs/force-data.md#the-motion-that-drives-the-model):
with "auto" (the default) a ``velocity`` column drives the model when it is the position's derivative -- the lag
between them (cross-correlation, sub-sample) at most LAG_LIMIT samples, their scales within SCALE_TOLERANCE, their
correlation at least MIN_CORRELATION (:func:`check_motion`); otherwise, and without a velocity column, the
position's derivative does (``numpy.gradient``, second order on irregular samples), with a MotionWarning giving
the numbers. Either way the driving waveform is a piecewise-linear position whose velocity goes linearly from sample to
sample in SUBSTEPS steps per interval, the step around each sample its own velocity (:func:`motion_waveform`), so
that the model sees at each sample time exactly the velocity used there, with no half-sample lag.

**Velocity resolution**: a quantised velocity (a firmware's fixed steps) makes static friction models chatter at
rest when their ``v_smooth`` is far below a step; :func:`velocity_resolution` estimates the step and
:func:`with_v_smooth` sets a model's ``v_smooth`` from it."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..errors import InputError, shorten
from ..results import Finding, emit
from ..waveforms import Sampled

#: What drives the model: "auto" (the velocity column where it is the position's derivative, else the
#: position), "position" (its derivative, the velocity column ignored), "velocity" (the column, as it is).
MOTIONS = ("auto", "position", "velocity")
#: "auto" rejects a velocity column lagging (or leading) the position's derivative by more than this many
#: sampling intervals ...
LAG_LIMIT = 1.0
#: ... or whose scale departs from the derivative's by more than this fraction ...
SCALE_TOLERANCE = 0.05
#: ... or whose correlation with the derivative (at the best lag) is below this.
MIN_CORRELATION = 0.5
#: "auto" drives by the position instead of a column that agrees but lags by at least this many sampling intervals
#: where the position's step over the median interval is finer than the column's step (a fine encoder beside a
#: firmware's late, coarse estimate): a lag biases the presliding (a LuGre fit of a joint with a 17-bit encoder,
#: its column 10 ms = 0.66 intervals late: sigma0 +50 %, fs -20 %; 2 ms: sigma0 +9 %; by the position: within
#: 1 %, 10 %; issue 40)
LATE_SAMPLES = 0.1
#: The lag search spans at most this long either way [s] (and a quarter of the record).
MAX_LAG = 2.0
#: The integrated velocity may depart from the recorded position by this fraction of the position's range
#: before it is an error (a wrong unit in a header, typically), unless the position drives the model.
POSITION_MISMATCH_ERROR = 0.5
#: with_v_smooth: v_smooth = this many velocity steps (the data resolve no slower sliding than one step).
V_SMOOTH_STEPS = 1.0
#: motion_waveform: constant-velocity steps per sampling interval (the velocity linear between samples)
SUBSTEPS = 2


class SamplingWarning(UserWarning):
    """A force experiment's record has a gap, or its velocity and position disagree."""


class MotionWarning(SamplingWarning):
    """A velocity column is not the position's derivative (lag, scale or shape): the numbers and the motion
    that drives the model. ``path``, ``problems`` and ``outcome`` (what drives the model) let a dataset's loader say
    the files that share an outcome in one warning (:func:`one_motion_warning`)."""

    def __init__(self, message, path="", problems="", outcome=""):
        super().__init__(message)
        self.path, self.problems, self.outcome = path, problems, outcome


def _finding(warning: MotionWarning) -> Finding:
    return Finding(MotionWarning, str(warning), warning)


def one_motion_warning(found) -> list:
    """``found`` (collected findings) with the MotionWarnings that share an outcome said once, each file with its
    numbers: a dataset of 20 runs whose velocity columns lag gave 20 warnings on every command."""
    def grouped(f):
        return isinstance(f.warning, MotionWarning) and f.warning.outcome
    motion = [f.warning for f in found if grouped(f)]
    out = [f for f in found if not grouped(f)]
    for outcome in dict.fromkeys(m.outcome for m in motion):
        same = [m for m in motion if m.outcome == outcome]
        if len(same) == 1:
            out.append(_finding(same[0]))
            continue
        files = "; ".join(f"{m.path}: {m.problems}" for m in same)
        out.append(_finding(MotionWarning(
            f"the velocity column is not the position's derivative in {len(same)} files ({files}); {outcome}")))
    return out


@dataclasses.dataclass(frozen=True)
class MotionCheck:
    """How a velocity column compares with the position's derivative (:func:`check_motion`).

    ``lag`` [s]: how late the column is (positive: it lags the derivative); ``lag_samples``: the same in median
    sampling intervals; ``scale``: the column over the derivative (1 for the same quantity in the same unit);
    ``correlation``: their correlation coefficient at that lag."""

    lag: float
    lag_samples: float
    scale: float
    correlation: float

    @property
    def problems(self) -> list:
        """Why the column is not the position's derivative, as phrases ([] when it is)."""
        out = []
        if not self.correlation >= MIN_CORRELATION:
            out.append(f"it correlates with the position's derivative only at r = {self.correlation:.2f} "
                       f"(below {MIN_CORRELATION:g})")
        if not abs(self.lag_samples) <= LAG_LIMIT:
            out.append(f"it {'lags' if self.lag > 0 else 'leads'} the position's derivative by "
                       f"{abs(self.lag) * 1e3:.3g} ms ({abs(self.lag_samples):.3g} sampling intervals; the limit is "
                       f"{LAG_LIMIT:g})")
        if not math.isfinite(self.scale):
            out.append("its scale against the derivative cannot be measured")
        elif not abs(self.scale - 1.0) <= SCALE_TOLERANCE:
            out.append(f"its scale is {self.scale:.4g} times the derivative's (more than {100 * SCALE_TOLERANCE:g} % "
                       f"off)")
        return out

    @property
    def agrees(self) -> bool:
        return not self.problems


def velocity_of(time, position, velocity):
    if velocity is not None:
        return np.asarray(velocity, float)
    return np.gradient(np.asarray(position, float), np.asarray(time, float))


def motion_waveform(time, velocity, start: float = 0.0) -> Sampled:
    """A continuous position whose velocity goes linearly from sample to sample, as a staircase of
    SUBSTEPS constant slopes per sampling interval, each the linear interpolation at its middle; the step around
    each sample time is that sample's own velocity, so the model sees it exactly there. Positions at the samples
    are the trapezoidal rule's (the staircase integrates the linear velocity exactly), from ``start`` (a run's
    first recorded position: the joint's own angle, which a position ripple's phase needs); the motion goes on
    half an interval beyond the last sample at its velocity. (One step per half-interval, the sample's velocity
    held up to the midpoints, biased a Stribeck fit: at 66.7 Hz on a smooth joint's reversals fs came out 5 %
    high and vs 5 % low on noise-free data; with 2 steps 1 %, with 4 0.03 %, but from 3 steps on the core's exact
    stepping of GMS departs from its integrator where the velocity dips without reversing, as
    tests/test_prescribed_exact.py finds.)"""
    t = np.asarray(time, float)
    v = np.asarray(velocity, float)
    dt = np.diff(t)
    m = SUBSTEPS
    # the steps' middles: each sample and m - 1 points evenly between it and the next; the steps' ends between them
    mid = np.concatenate([(t[:-1, None] + dt[:, None] * (np.arange(m) / m)).ravel(), t[-1:]])
    slope = np.interp(mid, t, v)
    ends = np.concatenate([0.5 * (mid[:-1] + mid[1:]), [t[-1] + 0.5 * dt[-1]]])
    at_end = float(start) + np.cumsum(np.diff(np.concatenate([mid[:1], ends])) * slope)
    knots = np.empty(2 * len(mid))
    values = np.empty_like(knots)
    knots[0::2], knots[1::2] = mid, ends
    values[0::2] = np.concatenate([[float(start)], at_end[:-1] + (mid[1:] - ends[:-1]) * slope[1:]])
    values[1::2] = at_end
    return Sampled(knots, values)


# -- the velocity column against the position ----------------------------------------------------

def on_uniform_grid(time, *signals):
    """The signals linearly interpolated onto a uniform grid at the median sampling interval: (dt, arrays)."""
    t = np.asarray(time, float)
    dt = float(np.median(np.diff(t)))
    n = int(math.floor((t[-1] - t[0]) / dt)) + 1
    tu = t[0] + dt * np.arange(n)
    return dt, [np.interp(tu, t, np.asarray(s, float)) for s in signals]


def velocity_lag(time, position, velocity, max_lag: float = MAX_LAG):
    """How late ``velocity`` is on the position's derivative: (lag [s], lag in median sampling intervals,
    correlation coefficient at that lag). Both signals are interpolated onto a uniform grid at the median
    interval, the derivative taken there by central differences (no lag of its own); the lag is the peak of
    their cross-correlation within ``max_lag`` either way (and a quarter of the record), refined to a fraction
    of an interval by a parabola through the peak and its neighbours. A positive lag means the column comes
    late: velocity(t) ~ d position/dt (t - lag)."""
    dt, (x, v) = on_uniform_grid(time, position, velocity)
    a = np.gradient(x, dt)
    a = a - a.mean()
    b = v - v.mean()
    n = a.size
    if n < 4 or not (np.any(a) and np.any(b)):
        return 0.0, 0.0, 0.0
    k_max = max(1, min(n // 4, int(round(max_lag / dt))))
    size = 1 << int(math.ceil(math.log2(2 * n)))
    r = np.fft.irfft(np.fft.rfft(b, size) * np.conj(np.fft.rfft(a, size)), size)  # r[k] = sum_j b[j + k] a[j]
    lags = np.arange(-k_max, k_max + 1)
    # each lag normalised by the energies of its own overlap (j and j + k both in the record): a correlation
    # coefficient at every lag, without the taper of a plain sum that pulls the peak towards lag 0
    ca, cb = np.concatenate([[0.0], np.cumsum(a * a)]), np.concatenate([[0.0], np.cumsum(b * b)])
    lo_a, hi_a = np.maximum(0, -lags), n - np.maximum(0, lags)
    ea, eb = ca[hi_a] - ca[lo_a], cb[hi_a + lags] - cb[lo_a + lags]
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.nan_to_num(r[lags % size] / np.sqrt(ea * eb))
    i = int(np.argmax(c))
    frac = 0.0
    if 0 < i < c.size - 1:
        den = c[i - 1] - 2 * c[i] + c[i + 1]
        if den < 0:
            frac = float(np.clip(0.5 * (c[i - 1] - c[i + 1]) / den, -0.5, 0.5))
    k = float(lags[i]) + frac
    return k * dt, k, float(c[i])


def velocity_scale(time, position, velocity, lag: float = 0.0, window: int = 5) -> float:
    """The velocity column's scale on the position's derivative: the position's increments over ``window``
    samples regressed on the column's integral over the same spans (trapezoidal, shifted by ``lag``), with a
    constant; the scale is one over the slope. Integrating averages the column's quantisation and noise out;
    the position's noise enters the response only, so it biases nothing (a regression on the differentiated
    position would be biased low by it), and the constant takes up a bias of the column (a drift that the
    whole record's integral would accumulate)."""
    t = np.asarray(time, float)
    x = np.asarray(position, float)
    v = np.asarray(velocity, float)
    V = np.concatenate([[0.0], np.cumsum(0.5 * np.diff(t) * (v[:-1] + v[1:]))])
    keep = (t + lag >= t[0]) & (t + lag <= t[-1])
    ts, xs = t[keep], x[keep]
    Vs = np.interp(ts + lag, t, V)
    m = max(1, min(int(window), ts.size // 4))
    dx, dV = xs[m:] - xs[:-m], Vs[m:] - Vs[:-m]
    if dV.size < 3 or not np.ptp(dV) > 0:
        return math.nan
    A = np.column_stack([dV - dV.mean(), np.ones(dV.size)])
    slope = float(np.linalg.lstsq(A, dx, rcond=None)[0][0])
    return 1.0 / slope if slope != 0 else math.inf


def check_motion(time, position, velocity) -> MotionCheck:
    """The velocity column against the position's derivative: lag, scale and correlation (:class:`MotionCheck`)."""
    lag, lag_samples, corr = velocity_lag(time, position, velocity)
    return MotionCheck(lag=lag, lag_samples=lag_samples, scale=velocity_scale(time, position, velocity, lag),
                       correlation=corr)


def check_motion_option(value, where: str) -> str:
    """``value`` as a motion option, or one InputError naming ``where``."""
    if value not in MOTIONS:
        raise InputError(f"{where}: 'motion' must be one of {', '.join(repr(m) for m in MOTIONS)}, got "
                         f"{shorten(value)}")
    return value


def choose_motion(path, time, position, velocity, motion: str = "auto", headers=None):
    """What drives the model of one experiment: ("velocity" | "position", the MotionCheck or None). With
    "auto" a velocity column drives it when it agrees with the position's derivative; a column that does not
    is named with its numbers in one MotionWarning. A column that, integrated, departs from the position by
    more than POSITION_MISMATCH_ERROR of its range is an InputError (a wrong unit, typically) unless the
    position was asked for."""
    motion = check_motion_option(motion, str(path))
    if velocity is None:
        if motion == "velocity":
            raise InputError(f"{path}: motion = \"velocity\" asks for a velocity column, and the file has none")
        return "position", None
    if motion == "position":
        return "position", None
    head = headers or {}
    vname, xname = head.get("velocity", "velocity"), head.get("position", "position")
    t, x, v = (np.asarray(a, float) for a in (time, position, velocity))
    span = float(np.ptp(x))
    moved = np.concatenate([[0.0], np.cumsum(0.5 * np.diff(t) * (v[:-1] + v[1:]))])
    dev = float(np.max(np.abs(moved - (x - x[0])))) if span > 0 else 0.0
    check = check_motion(t, x, v)
    if span > 0 and dev > POSITION_MISMATCH_ERROR * span:
        raise InputError(f"{path}: the velocity column {vname}, integrated over time, departs from the position "
                         f"column {xname} by {dev / span:.3g} of the position's range (the velocity is "
                         f"{check.scale:.4g} times the position's derivative): check the units in the header, or "
                         f"give motion = \"position\" to drive the model from the position alone")
    if check.agrees:
        finer = _position_finer(t, x, v, check) if motion == "auto" else None
        if finer is None:
            return "velocity", check
        emit([_finding(MotionWarning(
            f"{path}: the velocity column {vname} lags the position's derivative by {check.lag * 1e3:.3g} ms "
            f"({check.lag_samples:.3g} sampling intervals) and the position resolves the velocity more finely "
            f"({finer}): the position drives the model (motion = \"auto\"; motion = \"velocity\" uses the column)"))],
             stacklevel=3)
        return "position", check
    problems = "; ".join(check.problems)
    if motion == "velocity":
        outcome = "it drives the model as asked (motion = \"velocity\")"
        emit([_finding(MotionWarning(f"{path}: the velocity column {vname} is not the position's derivative: "
                                     f"{problems}; {outcome}", str(path), problems, outcome))], stacklevel=3)
        return "velocity", check
    outcome = ("the position drives the model (motion = \"auto\"; motion = \"velocity\" uses the column as it "
               "is)")
    emit([_finding(MotionWarning(f"{path}: the velocity column {vname} is not the position's derivative: {problems}; "
                                 f"{outcome}", str(path), problems, outcome))], stacklevel=3)
    return "position", check


def _position_finer(t, x, v, check: MotionCheck) -> str | None:
    """Where a quantised column that agrees with the position's derivative lags it by LATE_SAMPLES or more and the
    position's least change over the median interval is finer than the column's step: the two, said; else None.
    The least change is the smaller of the least move between samples and the least spacing of the distinct
    positions (not :func:`quantum`: a fine encoder's counts between samples are mostly more than 20 steps apart, too
    far for its lattice to be read; and a fast run moves many counts between samples even at its reversals, where
    its positions still resolve a count: a 17-bit encoder at 0.35 Hz made the column drive, 10 ms late, fs +193 %)."""
    qv = quantum(v)
    moves = np.abs(np.diff(x))
    spacings = np.diff(np.unique(x))
    least = np.concatenate([moves[moves > 0], spacings[spacings > 0]])
    if not abs(check.lag_samples) >= LATE_SAMPLES or qv is None or not least.size:
        return None
    per_interval = float(least.min()) / float(np.median(np.diff(t)))
    return f"{per_interval:.3g} per interval against the column's step {qv:.3g}" if per_interval < qv else None


def driven_by(exp, motion: str):
    """``exp`` driven by its position or its velocity column (``motion``: "position", "velocity"; "auto" leaves it
    as it was read): a model is scored on held-out runs driven as its fit runs were (the fit record). An experiment
    without a velocity column, or not a force experiment, is returned as it is."""
    if getattr(exp, "force", None) is None or motion == "auto" or exp.motion_source == motion \
            or (motion == "velocity" and exp.velocity is None):
        return exp
    drive_v = velocity_of(exp.time, exp.displacement, exp.velocity if motion == "velocity" else None)
    return dataclasses.replace(exp, motion=motion, input=motion_waveform(exp.time, drive_v, exp.displacement[0]))


# -- quantisation ----------------------------------------------------------------------------------

def quantum(values, tolerance: float = 0.05, share: float = 0.9) -> float | None:
    """The step of a quantised signal (a firmware's fixed-point velocity, an encoder's counts), or None when
    it is not quantised. The step is the median of the spacings of its distinct values that are single steps
    (below 1.5 times the smallest spacing); the signal is quantised when ``share`` of those spacings are whole
    multiples of the step (up to 20) to within ``tolerance`` steps (a continuous signal's smallest spacing is
    far below its typical one, which then is no small multiple of it). (Spacings rather than a global lattice: a logger's float32 numbers, or counts scaled
    by a gear ratio, drift off any one lattice by a fraction of a step over thousands of steps.)"""
    a = np.asarray(values, float)
    a = a[np.isfinite(a)]
    u = np.unique(a)
    if u.size < 3:
        return None
    span = float(u[-1] - u[0])
    d = np.diff(u)
    d = d[d > 1e-9 * span]
    if not d.size:
        return None
    q = float(np.median(d[d < 1.5 * d.min()]))
    k = d / q
    whole = (np.abs(k - np.round(k)) <= tolerance) & (k < 20.5)
    return q if float(np.mean(whole)) >= share else None


def velocity_resolution(time, position, velocity=None) -> float | None:
    """The resolution of the velocity that drives a model [m/s or rad/s]: the step of a quantised velocity
    column; without one (the position drives), the position's step over the median sampling interval, the
    smallest velocity its derivative resolves. None when neither is quantised."""
    if velocity is not None:
        return quantum(velocity)
    qx = quantum(position)
    if qx is None:
        return None
    return qx / float(np.median(np.diff(np.asarray(time, float))))


def v_smooth_for(experiments, steps: float = V_SMOOTH_STEPS) -> float | None:
    """The sign smoothing ``v_smooth`` the data support: ``steps`` times the coarsest velocity resolution of the
    experiments (a dataset or a list), None when no experiment's velocity is quantised."""
    res = [e.velocity_resolution for e in getattr(experiments, "experiments", experiments)
           if getattr(e, "velocity_resolution", None) is not None]
    return steps * max(res) if res else None


def with_v_smooth(model, experiments, steps: float = V_SMOOTH_STEPS):
    """``model`` with its friction's ``v_smooth`` set from the data (:func:`v_smooth_for`), never below the
    model's own; the model unchanged when the data's velocity is not quantised or the friction model has no
    ``v_smooth``."""
    value = v_smooth_for(experiments, steps)
    current = getattr(model.friction, "v_smooth", None)
    if value is None or current is None or value <= current:
        return model
    return model.with_friction(v_smooth=value)


__all__ = ["MOTIONS", "POSITION_MISMATCH_ERROR", "on_uniform_grid", "MotionCheck", "MotionWarning", "SamplingWarning", "check_motion",
           "check_motion_option", "choose_motion", "driven_by", "one_motion_warning", "motion_waveform", "quantum", "v_smooth_for", "velocity_lag",
           "velocity_of", "velocity_resolution", "velocity_scale", "with_v_smooth"]
