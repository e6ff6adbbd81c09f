"""Temperature laws (docs/models.md#model-i, docs/formats.md#model-files), laws of temperature and load
(docs/models.md#laws-of-temperature-and-load) and the temperature and load signals, written again from their
definitions (SciPy's PCHIP for tables); the law objects are read as plain attributes, never evaluated."""

from __future__ import annotations

import numpy as np
from scipy.interpolate import PchipInterpolator

from thermofriction.models import PWL, Const, Exp, Linear, LoadLaw, Poly, Table
from thermofriction.waveforms import Sampled


def _pchip_with_linear_ends(x, y):
    p = PchipInterpolator(x, y, extrapolate=False)
    dp = p.derivative()
    d0, dn = float(dp(x[0])), float(dp(x[-1]))

    def value(T):
        T = np.asarray(T, float)
        inside = np.clip(T, x[0], x[-1])
        v = p(inside)
        return np.where(T < x[0], y[0] + d0 * (T - x[0]), np.where(T > x[-1], y[-1] + dn * (T - x[-1]), v))

    def slope(T):
        T = np.asarray(T, float)
        return np.where(T < x[0], d0, np.where(T > x[-1], dn, dp(np.clip(T, x[0], x[-1]))))

    return value, slope


_PCHIP_CACHE: dict = {}


def _pwl_extrapolated(x, y, T):
    T = np.asarray(T, float)
    if len(x) == 1:
        return np.full_like(T, y[0]), np.zeros_like(T)
    i = np.clip(np.searchsorted(x, T, side="right") - 1, 0, len(x) - 2)
    slope = (y[i + 1] - y[i]) / (x[i + 1] - x[i])
    return y[i] + slope * (T - x[i]), slope


def _law_value_slope(law, T):
    T = np.asarray(T, float)
    if isinstance(law, Const):
        return np.full_like(T, law.value), np.zeros_like(T)
    if isinstance(law, Linear):
        return law.a * T + law.b, np.full_like(T, law.a)
    if isinstance(law, Exp):
        v = law.a * np.exp(law.b * T)
        return v, law.b * v
    if isinstance(law, Poly):
        c = np.asarray(law.c, float)
        P = np.polynomial.polynomial
        return P.polyval(T, c), P.polyval(T, P.polyder(c))
    if isinstance(law, Table):  # (before PWL: Table subclasses PWL)
        x, y = np.asarray(law.T, float), np.asarray(law.values, float)
        if len(x) == 1:
            return np.full_like(T, y[0]), np.zeros_like(T)
        key = (id(law), x.tobytes(), y.tobytes())
        if key not in _PCHIP_CACHE:
            _PCHIP_CACHE.clear()  # one at a time: enough for a simulation, never stale
            _PCHIP_CACHE[key] = _pchip_with_linear_ends(x, y)
        value, slope = _PCHIP_CACHE[key]
        return value(T), slope(T)
    if isinstance(law, PWL):
        return _pwl_extrapolated(np.asarray(law.T, float), np.asarray(law.values, float), T)
    raise TypeError(f"reference: unknown law {law!r}")


def law_value(law, T, load=None):
    """The law at temperature T [degC] (scalar or array), and, for a law of temperature and load, at ``load``."""
    if isinstance(law, LoadLaw):
        return load_law_value(law, T, load)
    v = _law_value_slope(law, T)[0]
    return float(v) if np.ndim(T) == 0 else v


def load_law_value(law, T, load):
    """A law of temperature and load, from its definition: with s = |L| (S tanh(|L|/S) with a saturation S),
    f(T) s (proportional), f(T) (1 + k s) (affine product), f(T) + k s (affine sum), plus c T s with an
    interaction c."""
    if load is None or not np.all(np.isfinite(load)):
        raise ValueError("reference: a law of the load needs a finite load")
    f = _law_value_slope(law.base, T)[0]
    term = law.load
    s = np.abs(np.asarray(load, float))
    if term.saturation is not None:
        s = term.saturation * np.tanh(s / term.saturation)
    if term.kind == "proportional":
        v = s * f
    elif term.combine == "sum":
        v = f + term.k * s
    else:
        v = f + f * term.k * s
    if term.interaction is not None:
        v = v + term.interaction * s * np.asarray(T, float)
    return float(v) if np.ndim(v) == 0 else v


def law_slope(law, T):
    """d law / dT at T."""
    d = _law_value_slope(law, T)[1]
    return float(d) if np.ndim(T) == 0 else d


def temperature_value(temperature, t):
    """A constant temperature (or load), or a Sampled signal interpolated (held beyond its ends)."""
    if isinstance(temperature, Sampled):
        return float(np.interp(t, temperature.time, temperature.value))
    return float(temperature)
