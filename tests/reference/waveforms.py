"""Inputs (docs/formats.md#inputs): the waveforms' values, corners and right-hand slopes, written
again from their definitions (the waveform objects are read as plain attributes, never called)."""

from __future__ import annotations

import bisect
import math

import numpy as np

from thermofriction.waveforms import Sampled, Sawtooth, Sine, Square, Step, Zero


def _frac(x):
    return x - math.floor(x)


def _sawtooth_scalar(w, t):
    ph = _frac(t * w.frequency)
    r = w.rise
    if w.direction > 0:
        shape = ph / r if ph < r else (1.0 - ph) / (1.0 - r)
    else:  # mirrored in time: shape_plus(1 - ph); fast rise over 1 - rise, slow fall over rise
        if ph == 0.0:
            shape = 0.0
        elif ph < 1.0 - r:
            shape = ph / (1.0 - r)
        else:
            shape = (1.0 - ph) / r
    return w.offset + w.amplitude * shape


def _square_scalar(w, t):
    f = w.frequency
    tau = _frac(t * f) / f
    t_fall = w.duty / f
    if tau < w.slew:
        s = tau / w.slew
    elif tau < t_fall:
        s = 1.0
    elif tau < t_fall + w.slew:
        s = 1.0 - (tau - t_fall) / w.slew
    else:
        s = 0.0
    return w.offset + w.amplitude * s


def _step_scalar(w, t):
    if t < w.time:
        return w.offset
    if t < w.time + w.slew:
        return w.offset + w.amplitude * (t - w.time) / w.slew
    return w.offset + w.amplitude


def interp_scalar(x, y, t):
    """np.interp for one point (held constant beyond the ends), without NumPy's call overhead."""
    if t <= x[0]:
        return y[0]
    if t >= x[-1]:
        return y[-1]
    i = bisect.bisect_right(x, t) - 1
    return y[i] + (t - x[i]) * (y[i + 1] - y[i]) / (x[i + 1] - x[i])


def scalar_waveform(w):
    """A plain function t -> value for the waveform w (None means Zero)."""
    if w is None or isinstance(w, Zero):
        return lambda t: 0.0
    if isinstance(w, Sawtooth):
        return lambda t: _sawtooth_scalar(w, t)
    if isinstance(w, Sine):
        om, a, off = 2.0 * math.pi * w.frequency, w.amplitude, w.offset
        return lambda t: off + a * math.sin(om * t)
    if isinstance(w, Square):
        return lambda t: _square_scalar(w, t)
    if isinstance(w, Step):
        return lambda t: _step_scalar(w, t)
    if isinstance(w, Sampled):
        x, y = [float(v) for v in w.time], [float(v) for v in w.value]
        return lambda t: interp_scalar(x, y, t)
    raise TypeError(f"reference: unknown waveform {w!r}")


def waveform_value(w, t):
    """The waveform at t (scalar or array)."""
    if isinstance(w, Sampled):
        return np.interp(t, w.time, w.value) if np.ndim(t) else float(np.interp(t, w.time, w.value))
    f = scalar_waveform(w)
    if np.ndim(t) == 0:
        return f(float(t))
    return np.array([f(float(ti)) for ti in np.ravel(t)]).reshape(np.shape(t))


def waveform_corners(w, t0, t1, include_start=False):
    """Corner times (the waveform or its slope may jump there) in (t0, t1], or [t0, t1] with
    include_start. Sorted, unique."""
    if w is None or isinstance(w, (Zero, Sine)):
        c = np.empty(0)
    elif isinstance(w, (Sawtooth, Square)):
        f = w.frequency
        if isinstance(w, Sawtooth):
            per = [0.0, (1.0 - w.rise) if w.direction < 0 else w.rise]
        else:
            per = [0.0, w.slew * f, w.duty, w.duty + w.slew * f]
        ks = np.arange(math.floor(t0 * f) - 1, math.ceil(t1 * f) + 2)
        c = np.sort(np.concatenate([(ks + p) / f for p in per]))
    elif isinstance(w, Step):
        c = np.array([w.time, w.time + w.slew] if w.slew > 0 else [w.time])
    elif isinstance(w, Sampled):
        c = np.asarray(w.time, float)
    else:
        raise TypeError(f"reference: unknown waveform {w!r}")
    lo = (c >= t0) if include_start else (c > t0)
    return np.unique(c[lo & (c <= t1)])



def _sawtooth_slope(w, t):
    ph, r, af = _frac(t * w.frequency), w.rise, w.amplitude * w.frequency
    if w.direction > 0:
        return af / r if ph < r else -af / (1.0 - r)
    return af / (1.0 - r) if ph < 1.0 - r else -af / r


def _square_slope(w, t):
    f = w.frequency
    tau = _frac(t * f) / f
    t_fall = w.duty / f
    if tau < w.slew:
        return w.amplitude / w.slew
    if t_fall <= tau < t_fall + w.slew:
        return -w.amplitude / w.slew
    return 0.0


def _step_slope(w, t):
    return w.amplitude / w.slew if (w.slew > 0 and w.time <= t < w.time + w.slew) else 0.0


def _sampled_slope(x, y, t):
    if t < x[0] or t >= x[-1]:
        return 0.0
    i = bisect.bisect_right(x, t) - 1
    return (y[i + 1] - y[i]) / (x[i + 1] - x[i])


def scalar_waveform_slope(w):
    """A plain function t -> the waveform's right-hand slope d/dt (the slope over [t, t + dt))."""
    if w is None or isinstance(w, Zero):
        return lambda t: 0.0
    if isinstance(w, Sawtooth):
        return lambda t: _sawtooth_slope(w, t)
    if isinstance(w, Sine):
        om, a = 2.0 * math.pi * w.frequency, w.amplitude
        return lambda t: a * om * math.cos(om * t)
    if isinstance(w, Square):
        return lambda t: _square_slope(w, t)
    if isinstance(w, Step):
        return lambda t: _step_slope(w, t)
    if isinstance(w, Sampled):
        x, y = [float(v) for v in w.time], [float(v) for v in w.value]
        return lambda t: _sampled_slope(x, y, t)
    raise TypeError(f"reference: unknown waveform {w!r}")


def waveform_slope(w, t):
    """The waveform's right-hand slope at t (scalar or array)."""
    f = scalar_waveform_slope(w)
    if np.ndim(t) == 0:
        return f(float(t))
    return np.array([f(float(ti)) for ti in np.ravel(t)]).reshape(np.shape(t))
