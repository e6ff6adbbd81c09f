"""An independent reference implementation of the simulated physics, in plain Python/NumPy/SciPy.

It exists only to test the C core (tests/test_differential.py, benchmarks/bench_simulate.py):
the same equations (SPEC 3.1, 4, 5, 6) written out again, without calling the C core. It reads
parameters from thermofriction's model objects (attributes only) and never evaluates a law or
a waveform through them (no ``Law.__call__``/``evaluate``, no ``Waveform.__call__``/``corners``,
no ``thermofriction._core``).

    waveform_value(w, t), waveform_corners(w, t0, t1)     inputs (SPEC 6)
    law_value(law, T)                                       temperature laws (SPEC 5.1, 7)
    temperature_value(temperature, t)                       constant or Sampled temperature
    friction_force(model, t, y, temperature, input=None)    F' (LuGre + thermal extension)
    rhs(model, t, y, temperature, input=None)               dy/dt of [x_p, v_p, x_e, v_e, z]
    reference_simulate(model, t_eval, temperature, ...)     solve_ivp, restarted at every corner

States are y = [x_p, v_p, x_e, v_e, z], v = v_e - v_p (the end effector relative to the stage);
the stage feels +F, the end effector -F (SPEC 2).
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import PchipInterpolator

from thermofriction.models import PWL, Const, Exp, Linear, ModelI, ModelII, Poly, Table
from thermofriction.waveforms import Sampled, Sawtooth, Sine, Square, Step, Zero

__all__ = ["waveform_value", "waveform_corners", "law_value", "law_slope", "temperature_value",
           "ReferenceModel", "friction_force", "rhs", "reference_simulate", "default_atol", "ReferenceResult"]

# ---------------------------------------------------------------------------------------------
# Waveforms
# ---------------------------------------------------------------------------------------------


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


def _interp_scalar(x, y, t):
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
        return lambda t: _interp_scalar(x, y, t)
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


# ---------------------------------------------------------------------------------------------
# Temperature laws
# ---------------------------------------------------------------------------------------------


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


def law_value(law, T):
    """The law at temperature T [degC] (scalar or array)."""
    v = _law_value_slope(law, T)[0]
    return float(v) if np.ndim(T) == 0 else v


def law_slope(law, T):
    """d law / dT at T."""
    d = _law_value_slope(law, T)[1]
    return float(d) if np.ndim(T) == 0 else d


def temperature_value(temperature, t):
    """A constant temperature, or a Sampled signal interpolated (held beyond its ends)."""
    if isinstance(temperature, Sampled):
        return float(np.interp(t, temperature.time, temperature.value))
    return float(temperature)


# ---------------------------------------------------------------------------------------------
# The plant with LuGre friction and the thermal extensions
# ---------------------------------------------------------------------------------------------

_NAMES = ("sigma0", "sigma1", "sigma2", "fc", "fs", "vs", "delta", "vd", "v_smooth")


@dataclass(frozen=True)
class _Params:
    sigma0: float
    sigma1: float
    sigma2: float
    fc: float
    fs: float
    vs: float | None
    delta: float
    vd: float | None
    v_smooth: float
    lam: float          # Model II scale factor (1 otherwise)
    dF_offset: float    # Model II offset force (0 otherwise)


class ReferenceModel:
    """The model's right-hand side as plain scalar Python, for one temperature and input."""

    def __init__(self, model, temperature=None, input=None):
        if model.plant.type != "stick-slip":
            raise TypeError("reference: only the stick-slip plant")
        if model.friction.model != "lugre":
            raise TypeError("reference: only LuGre friction")
        self.model = model
        self.m = float(model.plant.mass)
        self.m_e = float(model.plant.end_effector_mass)
        self.c, self.k, self.T_em = (float(v) for v in model.plant.physical())
        self.input = input if input is not None else (model.input if model.input is not None else Zero())
        self.u = scalar_waveform(self.input)
        self.temperature = temperature
        self._last_T, self._last_p = None, None
        if isinstance(temperature, Sampled):
            tt, tv = [float(v) for v in temperature.time], [float(v) for v in temperature.value]
            self.T_of_t = lambda t: _interp_scalar(tt, tv, t)
            self._const = None
        else:
            T = math.nan if temperature is None else float(temperature)
            self.T_of_t = lambda t: T
            self._const = self.params(T) if (temperature is not None or model.thermal is None) else None

    # -- parameters at a temperature -----------------------------------------------------------
    def params(self, T) -> _Params:
        fr = self.model.friction
        th = self.model.thermal
        p = {n: getattr(fr, n) for n in _NAMES}
        laws = th.laws if isinstance(th, ModelI) else {}
        for name, law in laws.items():
            p[name] = law_value(law, T)
        if fr.fs is None and "fs" not in laws:
            p["fs"] = p["fc"]  # fs follows fc (its law too)
        if p["sigma2"] is None:
            p["sigma2"] = 0.0
        if p["delta"] is None:
            p["delta"] = 2.0
        lam, off = 1.0, 0.0
        if isinstance(th, ModelII):
            dF = law_value(th.dF, T)
            if th.form == "scale":
                lam = 1.0 + dF / float(fr.fc)
            else:
                off = dF
        return _Params(float(p["sigma0"]), float(p["sigma1"]), float(p["sigma2"]), float(p["fc"]), float(p["fs"]),
                       None if p["vs"] is None else float(p["vs"]), float(p["delta"]),
                       None if p["vd"] is None else float(p["vd"]), float(p["v_smooth"]), lam, off)

    def params_at_time(self, t) -> _Params:
        if self._const is not None:
            return self._const
        T = self.T_of_t(t)
        if T != self._last_T:
            self._last_T, self._last_p = T, self.params(T)
        return self._last_p

    # -- friction ------------------------------------------------------------------------------
    @staticmethod
    def lugre(p: _Params, v, z):
        """(F', z') with F' the thermally modified LuGre force."""
        if p.fs == p.fc:
            g = p.fc
        else:
            r = abs(v / p.vs)
            g = p.fc + (p.fs - p.fc) * (math.exp(-r ** p.delta) if r < 1e30 else 0.0)
        zd = v - p.sigma0 * abs(v) * z / g
        s1 = p.sigma1 * math.exp(-(v / p.vd) ** 2) if p.vd is not None else p.sigma1
        F = p.sigma0 * z + s1 * zd + p.sigma2 * v
        F = p.lam * F
        if p.dF_offset != 0.0:
            F += p.dF_offset * math.tanh(v / p.v_smooth)
        return F, zd

    def friction(self, t, y):
        return self.lugre(self.params_at_time(t), float(y[3]) - float(y[1]), float(y[4]))[0]

    def rhs(self, t, y):
        x_p, v_p, x_e, v_e, z = y.tolist() if isinstance(y, np.ndarray) else y
        p = self.params_at_time(t)
        F, zd = self.lugre(p, v_e - v_p, z)
        u = self.u(t)
        return [v_p, (-self.c * v_p - self.k * x_p + self.T_em * u + F) / self.m, v_e, -F / self.m_e, zd]

    def corners(self, t0, t1):
        c = waveform_corners(self.input, t0, t1)
        if isinstance(self.temperature, Sampled):
            tt = np.asarray(self.temperature.time, float)
            c = np.union1d(c, tt[(tt > t0) & (tt <= t1)])
        return c

    def scales(self):
        """Characteristic magnitudes (position, velocity, z): stroke T_em*|u|max/k, stroke*wn (at most
        1000 x the narrowest velocity band of the friction: v_smooth of the offset form, the Stribeck
        vs when fs != fc), fc/sigma0."""
        w = self.input
        if isinstance(w, Sampled):
            umax = float(np.max(np.abs(w.value)))
        elif isinstance(w, Zero):
            umax = 0.0
        else:
            umax = abs(w.offset) + abs(w.amplitude)
        X = abs(self.T_em) * umax / self.k or 1e-6
        V = X * math.sqrt(self.k / self.m)
        T0 = self.T_of_t(0.0)
        p = self.params(T0) if not math.isnan(T0) or self.model.thermal is None else None
        Z = p.fc / p.sigma0 if p is not None else 1e-3 * X
        if p is not None:  # resolve the narrowest velocity band of the friction law to 1e-3 of it
            bands = [V]
            if isinstance(self.model.thermal, ModelII) and self.model.thermal.form == "offset":
                bands.append(p.v_smooth)
            if p.fs != p.fc:
                bands.append(p.vs)
            V = min(V, 1e3 * min(bands))
        return X, V, Z


def friction_force(model, t, y, temperature=None, input=None):
    """F' at (t, y): the force resisting the end effector's sliding on the stage."""
    return ReferenceModel(model, temperature, input).friction(float(t), [float(v) for v in y])


def rhs(model, t, y, temperature=None, input=None):
    """dy/dt at (t, y), y = [x_p, v_p, x_e, v_e, z]."""
    return np.array(ReferenceModel(model, temperature, input).rhs(float(t), [float(v) for v in y]))


# ---------------------------------------------------------------------------------------------
# Simulation
# ---------------------------------------------------------------------------------------------


def default_atol(model, temperature=None, input=None, rtol=1e-10):
    """Per-state absolute tolerances: rtol times each state's characteristic magnitude (the
    stroke for positions, stroke x natural frequency for velocities, fc/sigma0 for z). For the
    Li (2009) presets at rtol = 1e-10: about 3e-16 m, 2e-12 m/s and 4e-17 m."""
    X, V, Z = ReferenceModel(model, temperature, input).scales()
    return np.array([rtol * X, rtol * V, rtol * X, rtol * V, rtol * Z])


@dataclass
class ReferenceResult:
    time: np.ndarray
    y: np.ndarray               # (N, 5): x_p, v_p, x_e, v_e, z
    friction_force: np.ndarray
    nfev: int
    segments: int

    @property
    def displacement(self):
        return self.y[:, 2]


def reference_simulate(model, t_eval, temperature=None, input=None, method="DOP853", rtol=1e-10, atol=None,
                       piecewise=True, first_step=None):
    """Integrates from rest with scipy.integrate.solve_ivp; returns a ReferenceResult on t_eval.

    piecewise=True restarts the integration at every corner of the input (and knot of a sampled
    temperature), so that no step crosses a kink; piecewise=False integrates across the whole
    interval in one call, as a SciPy user would. atol=None: ``default_atol(model, ..., rtol)``."""
    ref = ReferenceModel(model, temperature, input)
    t_eval = np.asarray(t_eval, float)
    t0, t1 = float(t_eval[0]), float(t_eval[-1])
    if atol is None:
        atol = default_atol(model, temperature, input, rtol)
    bounds = [t0, *ref.corners(t0, t1)] if piecewise else [t0]
    if bounds[-1] < t1:
        bounds.append(t1)
    bounds = np.array(bounds)
    # drop segments shorter than rounding noise (a corner equal to t1 up to an ulp)
    keep = np.concatenate([[True], np.diff(bounds) > 1e-12 * max(1.0, abs(t1))])
    bounds = bounds[keep]
    bounds[-1] = max(bounds[-1], t1)
    y = np.zeros(5)
    out = np.empty((t_eval.size, 5))
    out[t_eval <= t0] = y
    nfev = 0
    kw = {"first_step": first_step} if first_step else {}
    for a, b in zip(bounds[:-1], bounds[1:]):
        sel = np.nonzero((t_eval > a) & (t_eval <= b))[0]
        te = t_eval[sel]
        te_end = te if (te.size and te[-1] == b) else np.append(te, b)  # the state at b starts the next piece
        with np.errstate(over="ignore", invalid="ignore"):  # trial steps that overshoot are rejected
            sol = solve_ivp(ref.rhs, (a, b), y, method=method, rtol=rtol, atol=atol, t_eval=te_end, **kw)
        if sol.status != 0:
            raise RuntimeError(f"reference integration failed on [{a}, {b}]: {sol.message}")
        out[sel] = sol.y[:, :te.size].T
        y = sol.y[:, -1].copy()
        nfev += sol.nfev
    F = np.array([ref.friction(t, out[i]) for i, t in enumerate(t_eval)])
    return ReferenceResult(t_eval, out, F, nfev, len(bounds) - 1)
