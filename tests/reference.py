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

Every other friction model and plant (SPEC 3.2, 3.3, 4) -- Coulomb, Stribeck, Dahl, LuGre,
elasto-plastic, GMS on the stick-slip actuator, the single mass and prescribed motion -- goes
through ReferenceSystem (below), to which friction_force / rhs / reference_simulate dispatch:

    friction_params(model, T), stribeck_g, elastoplastic_alpha, base_friction   the laws of SPEC 4
    waveform_slope(w, t)                                    right-hand slope (prescribed v_r)
    ReferenceSystem(model, temperature, input, gms_mode)    rhs / friction for any plant
    reference_simulate_system(model, t_eval, ...)           solve_ivp; GMS stick/slip switches as
                                                            terminal events, restarted in the new modes
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.interpolate import PchipInterpolator
from scipy.optimize import brentq

from thermofriction.models import PWL, Const, Exp, Linear, ModelI, ModelII, Poly, Table
from thermofriction.waveforms import Sampled, Sawtooth, Sine, Square, Step, Zero

__all__ = ["waveform_value", "waveform_corners", "law_value", "law_slope", "temperature_value",
           "ReferenceModel", "friction_force", "rhs", "reference_simulate", "default_atol", "ReferenceResult",
           "FrictionParams", "friction_params", "stribeck_g", "elastoplastic_alpha", "base_friction",
           "waveform_slope", "ReferenceSystem", "ReferenceSystemResult", "reference_simulate_system"]

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


def friction_force(model, t, y, temperature=None, input=None, gms_mode=None):
    """F' at (t, y): the force resisting the end effector's sliding on the stage (any plant and
    friction model: the driven body's sliding; GMS element modes from ``gms_mode``)."""
    if not _is_lugre_actuator(model):
        return ReferenceSystem(model, temperature, input, gms_mode).friction(float(t), [float(v) for v in y])
    return ReferenceModel(model, temperature, input).friction(float(t), [float(v) for v in y])


def rhs(model, t, y, temperature=None, input=None, gms_mode=None):
    """dy/dt at (t, y), y = [x_p, v_p, x_e, v_e, z] (other plants and friction models: the states
    of ReferenceSystem; GMS element modes from ``gms_mode``, default all stuck)."""
    if not _is_lugre_actuator(model):
        return np.array(ReferenceSystem(model, temperature, input, gms_mode).rhs(float(t), [float(v) for v in y]))
    return np.array(ReferenceModel(model, temperature, input).rhs(float(t), [float(v) for v in y]))


# ---------------------------------------------------------------------------------------------
# Simulation
# ---------------------------------------------------------------------------------------------


def default_atol(model, temperature=None, input=None, rtol=1e-10):
    """Per-state absolute tolerances: rtol times each state's characteristic magnitude (the
    stroke for positions, stroke x natural frequency for velocities, fc/sigma0 for z). For the
    Li (2009) presets at rtol = 1e-10: about 3e-16 m, 2e-12 m/s and 4e-17 m."""
    if not _is_lugre_actuator(model):
        return rtol * ReferenceSystem(model, temperature, input).scales()
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
    interval in one call, as a SciPy user would. atol=None: ``default_atol(model, ..., rtol)``.
    Other plants and friction models than LuGre on the actuator: ``reference_simulate_system``
    (always piecewise), which returns a ReferenceSystemResult."""
    if not _is_lugre_actuator(model):
        if not piecewise:
            raise ValueError("reference: only piecewise integration for this plant and friction model")
        return reference_simulate_system(model, t_eval, temperature, input, method, rtol, atol, first_step)
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


# =============================================================================================
# Every friction model on every plant (SPEC 3.1-3.3, 4, 5)
# =============================================================================================
#
# The functions above keep their LuGre-on-the-actuator implementation (ReferenceModel) for that
# case; every other combination goes to ReferenceSystem below: Coulomb and Stribeck static maps
# (sign smoothed by tanh(v / v_smooth)), Dahl, LuGre, elasto-plastic (Dupont et al. 2002) and
# generalized Maxwell-slip (Al-Bender et al. 2005), on the stick-slip actuator, the single mass
# (m x'' = f(t) + k_s (v_0 t - x) - F) and prescribed motion (x_r = the input in metres, v_r its
# slope; friction states only), with either thermal extension. GMS switches between sticking
# and slipping at events located by solve_ivp (terminal events, restarted in the new modes),
# with a scan of the dense output for crossings that come and go within one step.

#: friction parameters a model may carry (the C core's list, read here by name from the model)
_ALL_PARAMS = ("sigma0", "sigma1", "sigma2", "fc", "fs", "vs", "delta", "vd", "v_smooth", "z_ba", "C")
_NSTATE = {"coulomb": 0, "stribeck": 0, "dahl": 1, "lugre": 1, "elastoplastic": 1}
_NMECH = {"stick-slip": 4, "mass": 2, "prescribed": 0}


@dataclass(frozen=True)
class FrictionParams:
    """One friction model's parameters at one temperature (Model I laws applied), plus Model II's
    scale factor ``lam`` and offset force ``dF_offset``."""

    sigma0: float
    sigma1: float
    sigma2: float
    fc: float
    fs: float
    vs: float | None
    delta: float
    vd: float | None
    v_smooth: float
    z_ba: float
    C: float
    k: tuple
    w: tuple
    lam: float
    dF_offset: float


def friction_params(model, T) -> FrictionParams:
    """The friction parameters of ``model`` at temperature T [degC] (NaN without a thermal model),
    read from the friction object's attributes and the thermal model's laws."""
    fr, th = model.friction, model.thermal
    p = {n: getattr(fr, n, None) for n in _ALL_PARAMS}
    laws = th.laws if isinstance(th, ModelI) else {}
    for name, law in laws.items():
        p[name] = law_value(law, T)
    if p["fs"] is None:
        p["fs"] = p["fc"]  # no Stribeck effect; fs follows fc (and fc's law)
    defaults = {"sigma2": 0.0, "delta": 2.0, "sigma0": math.nan, "sigma1": 0.0, "z_ba": 0.0, "C": math.nan,
                "v_smooth": 1e-6}
    for name, value in defaults.items():
        if p[name] is None:
            p[name] = value
    lam, off = 1.0, 0.0
    if isinstance(th, ModelII):
        dF = law_value(th.dF, T)
        if th.form == "scale":
            lam = 1.0 + dF / float(fr.fc)  # F_ref: the base model's steady sliding level, fc
        else:
            off = dF
    f = {n: (None if p[n] is None else float(p[n])) for n in _ALL_PARAMS}
    k = tuple(float(x) for x in getattr(fr, "k", ()))
    w = tuple(float(x) for x in getattr(fr, "w", ()))
    return FrictionParams(**f, k=k, w=w, lam=lam, dF_offset=off)


def stribeck_g(p: FrictionParams, v):
    """g(v) = fc + (fs - fc) exp(-|v/vs|^delta) (fc when fs == fc)."""
    if p.fs == p.fc:
        return p.fc
    r = abs(v) / p.vs
    return p.fc + (p.fs - p.fc) * (math.exp(-(r ** p.delta)) if r < 1e30 else 0.0)


def elastoplastic_alpha(p: FrictionParams, z, v, g):
    """Dupont et al. (2002): 0 while z and v have opposite signs or |z| <= z_ba; 1 for |z| at or
    beyond the steady deflection z_ss = g(v)/sigma0; a half sine rising from 0 to 1 between."""
    if not (z * v > 0.0):
        return 0.0
    az, z_ss = abs(z), g / p.sigma0
    if az <= p.z_ba:
        return 0.0
    if az >= z_ss:
        return 1.0
    mid, half = 0.5 * (z_ss + p.z_ba), z_ss - p.z_ba
    return 0.5 + 0.5 * math.sin(math.pi * (az - mid) / half)


def base_friction(kind, p: FrictionParams, v, z, modes=()):
    """(F, [z_i']) of the friction model alone (no thermal extension) at sliding velocity v and
    internal states z. GMS ``modes``: 0 stuck, +1/-1 slipping in that direction."""
    if kind == "coulomb":
        return p.fc * math.tanh(v / p.v_smooth) + p.sigma2 * v, []
    if kind == "stribeck":
        return stribeck_g(p, v) * math.tanh(v / p.v_smooth) + p.sigma2 * v, []
    if kind == "dahl":
        return p.sigma0 * z[0], [v - p.sigma0 * abs(v) * z[0] / p.fc]
    if kind in ("lugre", "elastoplastic"):
        g = stribeck_g(p, v)
        alpha = 1.0 if kind == "lugre" else elastoplastic_alpha(p, z[0], v, g)
        zd = v - alpha * p.sigma0 * abs(v) * z[0] / g
        s1 = p.sigma1 * math.exp(-((v / p.vd) ** 2)) if p.vd is not None else p.sigma1
        return p.sigma0 * z[0] + s1 * zd + p.sigma2 * v, [zd]
    if kind == "gms":
        g = stribeck_g(p, v)
        F, rates = p.sigma2 * v, []
        for Fi, ki, wi, mi in zip(z, p.k, p.w, modes):
            F += Fi
            # stuck: a spring moving with the surface; slipping (direction mi = sgn v while it lasts):
            # relaxes towards its capacity mi w_i g(v) at rate C
            rates.append(ki * v if mi == 0 else p.C * (mi * wi - Fi / g))
        return F, rates
    raise TypeError(f"reference: unknown friction model {kind!r}")


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


class ReferenceSystem:
    """Any plant with any friction model and thermal extension, as plain scalar Python.

    States: stick-slip [x_p, v_p, x_e, v_e, *z] (v_r = v_e - v_p; the stage feels +F, the end
    effector -F); mass [x, v, *z] (v_r = v, m v' = f(t) + k_s (v_0 t - x) - F); prescribed [*z]
    (v_r = the input's slope). z: the friction model's states (GMS: the element forces F_i).
    ``modes`` holds GMS's element modes (0 stuck, +1/-1 slipping that way), all stuck from rest
    unless ``gms_mode`` says otherwise."""

    def __init__(self, model, temperature=None, input=None, gms_mode=None):
        self.model = model
        self.plant = model.plant.type
        self.kind = model.friction.model
        self.nz = len(model.friction.k) if self.kind == "gms" else _NSTATE[self.kind]
        self.nm = _NMECH[self.plant]
        self.n = self.nm + self.nz
        pl = model.plant
        if self.plant == "stick-slip":
            self.m, self.m_e = float(pl.mass), float(pl.end_effector_mass)
            self.c, self.k, self.T_em = (float(v) for v in pl.physical())
        elif self.plant == "mass":
            self.m, self.k_s, self.v_0 = float(pl.mass), float(pl.spring_stiffness), float(pl.pull_velocity)
        self.input = input if input is not None else (model.input if model.input is not None else Zero())
        self.u = scalar_waveform(self.input)
        self.du = scalar_waveform_slope(self.input)
        self._linear_pieces = not isinstance(self.input, Sine)  # slope constant between corners
        self._seg_last = math.inf   # inside a segment: its last time before the end corner
        self._seg_slope = None      # inside a segment: the input's slope on it (piecewise-linear inputs)
        self.temperature = temperature
        self._last_T, self._last_p = None, None
        if isinstance(temperature, Sampled):
            tt, tv = [float(v) for v in temperature.time], [float(v) for v in temperature.value]
            self.T_of_t = lambda t: _interp_scalar(tt, tv, t)
            self._const = None
        else:
            T = math.nan if temperature is None else float(temperature)
            self.T_of_t = lambda t: T
            self._const = friction_params(model, T)
        if gms_mode is not None:
            self.modes = [int(np.sign(mv)) for mv in gms_mode]
        else:
            self.modes = [0] * (self.nz if self.kind == "gms" else 0)
        self._disarmed = set()  # GMS (element, direction) whose capacity was passed unloaded

    # -- parameters and inputs -----------------------------------------------------------------
    def params(self, T) -> FrictionParams:
        return friction_params(self.model, T)

    def params_at_time(self, t) -> FrictionParams:
        if self._const is not None:
            return self._const
        T = self.T_of_t(t)
        if T != self._last_T:
            self._last_T, self._last_p = T, friction_params(self.model, T)
        return self._last_p

    def begin_segment(self, a, b):
        """Integrating over [a, b] (no corner inside): the input is taken from inside the segment
        (its left limit at b, its slope on the segment)."""
        self._seg_last = math.nextafter(b, -math.inf)
        self._seg_slope = self.du(0.5 * (a + b)) if self._linear_pieces else None

    def end_segment(self):
        self._seg_last, self._seg_slope = math.inf, None

    def input_value(self, t):
        return self.u(min(t, self._seg_last))

    def input_slope(self, t):
        return self._seg_slope if self._seg_slope is not None else self.du(t)

    def velocity(self, t, y):
        """v_r, the driven body's velocity relative to its driving surface."""
        if self.plant == "stick-slip":
            return y[3] - y[1]
        if self.plant == "mass":
            return y[1]
        return self.input_slope(t)

    # -- friction and the right-hand side --------------------------------------------------------
    def friction_and_rates(self, t, y):
        p = self.params_at_time(t)
        v = self.velocity(t, y)
        F, zd = base_friction(self.kind, p, v, y[self.nm:], self.modes)
        F = p.lam * F
        if p.dF_offset != 0.0:
            F += p.dF_offset * math.tanh(v / p.v_smooth)
        return F, zd

    def friction(self, t, y):
        y = [float(v) for v in y]
        return self.friction_and_rates(t, y)[0]

    def rhs(self, t, y):
        y = y.tolist() if isinstance(y, np.ndarray) else list(y)
        F, zd = self.friction_and_rates(t, y)
        if self.plant == "stick-slip":
            x_p, v_p, _, v_e = y[:4]
            u = self.input_value(t)
            return [v_p, (-self.c * v_p - self.k * x_p + self.T_em * u + F) / self.m, v_e, -F / self.m_e, *zd]
        if self.plant == "mass":
            x, v = y[:2]
            f = self.input_value(t) + self.k_s * (self.v_0 * t - x)
            return [v, (f - F) / self.m, *zd]
        return zd

    # -- GMS: sticking and slipping ---------------------------------------------------------------
    def gms_events(self):
        """Event functions (positive while the current modes hold; terminal, falling through
        zero) and, per function, what it means:
        ("capacity", i, s) -- stuck element i's force reaches its capacity s w_i g(v) in direction
        s = +1 or -1 (signed, so that an element that has just stuck at +capacity and is unloaded
        does not sit on a root); ("rearm", i, s) -- the force of a stuck element that went past
        that capacity without being loaded that way (g(v) fell under it) is back inside it;
        ("reversal", d, None) -- v reverses under the elements slipping in direction d."""
        if self.kind != "gms":
            return [], []
        funcs, what = [], []
        for i, mode in enumerate(self.modes):
            if mode == 0:
                for s in (1, -1):
                    kind = "rearm" if (i, s) in self._disarmed else "capacity"
                    sign = -1.0 if kind == "rearm" else 1.0

                    def cap(t, y, i=i, s=s, sign=sign):
                        p = self.params_at_time(t)
                        return sign * (p.w[i] * stribeck_g(p, self.velocity(t, y)) - s * y[self.nm + i])
                    funcs.append(cap)
                    what.append((kind, i, s))
        for d in sorted({mode for mode in self.modes if mode != 0}):
            funcs.append(lambda t, y, d=d: d * self.velocity(t, y))
            what.append(("reversal", d, None))
        for f in funcs:
            f.terminal, f.direction = True, -1.0
        return funcs, what

    def gms_switch(self, t, y, fired):
        """New modes after the events ``fired`` (items of gms_events' second list): an element
        whose force reaches its capacity while it is loaded further that way (s v > 0) breaks
        loose in that direction (otherwise it stays stuck, and that capacity is watched again
        once the force is back inside it); the slipping elements stick when v reverses."""
        v = self.velocity(t, y)
        for kind, i, s in fired:
            if kind == "capacity":
                if s * v > 0.0:
                    self.modes[i] = s
                    self._disarmed -= {(i, 1), (i, -1)}
                else:
                    self._disarmed.add((i, s))
            elif kind == "rearm":
                self._disarmed.discard((i, s))
            else:
                self.modes = [0 if m == i else m for m in self.modes]

    def gms_restart(self, t, y):
        """Modes at the start of a segment (after a corner, where v may jump): slipping elements
        whose direction v no longer follows stick; stuck ones at or beyond their capacity, loaded
        further, slip (not loaded further: they stay stuck, that capacity watched again once the
        force is back inside it)."""
        if self.kind != "gms":
            return
        p = self.params_at_time(t)
        v = self.velocity(t, y)
        g = stribeck_g(p, v)
        for i, mode in enumerate(self.modes):
            Fi = y[self.nm + i]
            if mode != 0 and mode * v <= 0.0:
                self.modes[i] = 0
            elif mode == 0 and abs(Fi) >= p.w[i] * g:
                s = 1 if Fi > 0 else -1
                if Fi * v > 0.0:
                    self.modes[i] = s
                    self._disarmed -= {(i, 1), (i, -1)}
                else:
                    self._disarmed.add((i, s))

    def gms_event_values(self, ts, Y, what):
        """The event functions of ``what`` (gms_events' second list) at many times ts, states Y
        (n x len(ts)), vectorised: rows in the order of ``what``."""
        ts = np.asarray(ts, float)
        if self.plant == "stick-slip":
            V = Y[3] - Y[1]
        elif self.plant == "mass":
            V = Y[1]
        else:
            V = np.array([self.input_slope(t) for t in ts])
        if self._const is not None:
            p = self._const
            if p.fs == p.fc:
                G = np.full_like(V, p.fc)
            else:
                r = np.abs(V) / p.vs
                with np.errstate(over="ignore"):
                    G = p.fc + (p.fs - p.fc) * np.exp(-(r ** p.delta))
            W = np.array(p.w)[:, None] * G
        else:
            W = np.array([[pi.w[i] * stribeck_g(pi, v) for i in range(self.nz)]
                          for pi, v in ((self.params_at_time(t), v) for t, v in zip(ts, V))]).T
        rows = []
        for kind, i, s in what:
            if kind == "reversal":
                rows.append(i * V)
            else:
                rows.append((1.0 if kind == "capacity" else -1.0) * (W[i] - s * Y[self.nm + i]))
        return np.array(rows)

    def gms_missed_crossing(self, sol, t0, t_stop, what, include_end, points=32):
        """An event function crossing zero (falling) and back within one step escapes solve_ivp,
        which compares signs at step ends only (an element grazing its capacity near a
        reversal). Scans the dense output on ``points`` points per step over [t0, t_stop) (or
        [t0, t_stop] with include_end) and returns (time, index into what) of the earliest such
        crossing, located by brentq on the dense output, or None."""
        if not what:
            return None
        steps = np.asarray(sol.t, float)
        steps = steps[(steps >= t0) & (steps <= t_stop)]
        if steps.size < 2:
            return None
        frac = np.arange(points) / points
        grid = (steps[:-1, None] + (steps[1:] - steps[:-1])[:, None] * frac[None, :]).ravel()
        grid = grid[grid < t_stop]
        if include_end:
            grid = np.append(grid, t_stop)
        E = self.gms_event_values(grid, sol.sol(grid), what)
        down = (E[:, :-1] > 0.0) & (E[:, 1:] <= 0.0)
        if not down.any():
            return None
        j = int(np.min(np.nonzero(down.any(axis=0))[0]))
        best = None
        for k in np.nonzero(down[:, j])[0]:
            f = lambda t, k=k: float(self.gms_event_values([t], sol.sol(t)[:, None], [what[k]])[0, 0])
            tk = brentq(f, grid[j], grid[j + 1], xtol=1e-15, rtol=4 * np.finfo(float).eps)
            if best is None or tk < best[0]:
                best = (tk, int(k))
        return best

    # -- tolerances -----------------------------------------------------------------------------
    def corners(self, t0, t1):
        c = waveform_corners(self.input, t0, t1)
        if isinstance(self.temperature, Sampled):
            tt = np.asarray(self.temperature.time, float)
            c = np.union1d(c, tt[(tt > t0) & (tt <= t1)])
        return c

    def _input_peak(self):
        w = self.input
        if isinstance(w, Sampled):
            return float(np.max(np.abs(w.value)))
        if isinstance(w, Zero):
            return 0.0
        return abs(w.offset) + abs(w.amplitude)

    def scales(self):
        """Each state's characteristic magnitude: positions and velocities of the motion
        (velocities at most 1000 x the friction's narrowest velocity band), the presliding
        deflection fc/sigma0 for z, w_i fc for a GMS element's force."""
        p = self.params(self.T_of_t(0.0))
        per = getattr(self.input, "period", None) or 1.0
        upk = self._input_peak()
        presliding = p.fc / p.sigma0 if self.kind in ("dahl", "lugre", "elastoplastic") else None
        if self.plant == "stick-slip":
            X = abs(self.T_em) * upk / self.k or 1e-6
            V = X * math.sqrt(self.k / self.m)
        elif self.plant == "mass":
            V = self.v_0 if self.v_0 > 0 else max(upk, p.fc) / self.m * per
            X = V * per if presliding is None else min(V * per, presliding)
        else:
            X = upk or 1e-6
            V = X / per
        bands = [V]
        if self.kind in ("coulomb", "stribeck") or p.dF_offset != 0.0:
            bands.append(p.v_smooth)
        if p.fs != p.fc:
            bands.append(p.vs)
        V = min(V, 1e3 * min(bands))
        if self.plant == "stick-slip":
            s = [X, V, X, V]
        elif self.plant == "mass":
            s = [X, V]
        else:
            s = []
        if self.kind == "gms":
            s += [p.fc * max(wi, 1e-3) for wi in p.w]
        elif self.nz:
            s += [presliding]
        return np.array(s, float)


def _is_lugre_actuator(model):
    return model.plant.type == "stick-slip" and model.friction.model == "lugre"


@dataclass
class ReferenceSystemResult:
    time: np.ndarray
    y: np.ndarray                   # (N, n): the plant's states, then the friction states
    friction_force: np.ndarray
    displacement: np.ndarray        # the driven body: end effector, mass, or the prescribed motion
    velocity: np.ndarray
    stage_displacement: np.ndarray | None
    nfev: int
    segments: int
    events: int                     # GMS stick/slip switches located as events (not those at corners)


def reference_simulate_system(model, t_eval, temperature=None, input=None, method="DOP853", rtol=1e-10,
                              atol=None, first_step=None, max_step=math.inf):
    """Integrates any plant with any friction model from rest (solve_ivp, restarted at every corner
    of the input and knot of a sampled temperature; GMS also at every stick/slip switch, located
    by solve_ivp's terminal events, and at crossings that come and go within one step, found by
    scanning the dense output). atol=None: rtol times ReferenceSystem.scales(). max_step bounds
    the steps: an adaptive step can jump a short window where the solution moves after being
    exactly still (a slipping GMS element's force, constant while |v| >> vs, rises as v crosses
    the Stribeck band before a reversal) without its error estimate noticing."""
    sys_ = ReferenceSystem(model, temperature, input)
    t_eval = np.asarray(t_eval, float)
    t0, t1 = float(t_eval[0]), float(t_eval[-1])
    n = sys_.n
    out = np.zeros((t_eval.size, n))
    nfev = events = 0
    bounds = np.array([t0, *sys_.corners(t0, t1)])
    if bounds[-1] < t1:
        bounds = np.append(bounds, t1)
    keep = np.concatenate([[True], np.diff(bounds) > 1e-12 * max(1.0, abs(t1))])
    bounds = bounds[keep]
    bounds[-1] = max(bounds[-1], t1)
    if n:
        if atol is None:
            atol = rtol * sys_.scales()
        y = np.zeros(n)
        kw = {"first_step": first_step} if first_step else {}
        kw["max_step"] = max_step
        for a, b in zip(bounds[:-1], bounds[1:]):
            sys_.begin_segment(a, b)
            sys_.gms_restart(a, y)
            t, stalls = a, 0
            while True:
                funcs, what = sys_.gms_events()
                with np.errstate(over="ignore", invalid="ignore"):
                    sol = solve_ivp(sys_.rhs, (t, b), y, method=method, rtol=rtol, atol=atol,
                                    events=funcs or None, dense_output=True, **kw)
                if sol.status < 0:
                    raise RuntimeError(f"reference integration failed on [{t}, {b}]: {sol.message}")
                nfev += sol.nfev
                t_end = float(sol.t[-1])
                sel = np.nonzero((t_eval > t) & (t_eval <= t_end))[0]
                fired = [what[j] for j, te in enumerate(sol.t_events) if te.size] if sol.status == 1 else []
                missed = sys_.gms_missed_crossing(sol, t, t_end, what, include_end=sol.status != 1)
                if missed is not None:  # a crossing solve_ivp stepped over, before anything it found
                    t_end, fired = missed[0], [what[missed[1]]]
                    sel = np.nonzero((t_eval > t) & (t_eval <= t_end))[0]
                    y = sol.sol(t_end)
                else:
                    y = sol.y[:, -1].copy()
                if sel.size:
                    out[sel] = sol.sol(t_eval[sel]).T
                if not fired:
                    break
                before = list(sys_.modes)
                sys_.gms_switch(t_end, y, fired)
                events += sys_.modes != before
                stalls = stalls + 1 if t_end <= t else 0
                if stalls > 10:
                    raise RuntimeError(f"reference: GMS events do not advance at t = {t}")
                t = t_end
                if t >= b:
                    break
            sys_.end_segment()
    F = np.array([sys_.friction(t, out[i]) for i, t in enumerate(t_eval)])
    if sys_.plant == "stick-slip":
        x, v, xs = out[:, 2], out[:, 3], out[:, 0]
    elif sys_.plant == "mass":
        x, v, xs = out[:, 0], out[:, 1], None
    else:
        x, v, xs = waveform_value(sys_.input, t_eval), waveform_slope(sys_.input, t_eval), None
    return ReferenceSystemResult(t_eval, out, F, np.asarray(x, float), np.asarray(v, float), xs, nfev,
                                 len(bounds) - 1, events)


# ---------------------------------------------------------------------------------------------
# Self-heating (SPEC 5.3)
# ---------------------------------------------------------------------------------------------

class ReferenceHeatedSystem(ReferenceSystem):
    """ReferenceSystem with the lumped thermal model: states [plant, z, T, W] with
    C_th T' = eta |F v_r| - (T - T_amb) / R_th + P_ext(t) and W' = |F v_r|; the friction
    parameters are evaluated at the state T. Not for GMS (no mode switching here)."""

    def __init__(self, model, ambient, input=None):
        super().__init__(model, ambient, input)
        h = model.heat
        self.C_th, self.R_th, self.eta = float(h.heat_capacity), float(h.thermal_resistance), float(h.heat_fraction)
        self.T_amb = float(ambient)
        self.T_0 = float(h.initial_temperature) if h.initial_temperature is not None else self.T_amb
        self.P_ext = scalar_waveform(h.external_heat) if h.external_heat is not None else (lambda t: 0.0)
        self.heater = h.external_heat
        self._T = self.T_0
        self.params_at_time = lambda t: friction_params(self.model, self._T)
        self.n += 2

    def corners(self, t0, t1):
        c = waveform_corners(self.input, t0, t1)
        if self.heater is not None:
            c = np.union1d(c, waveform_corners(self.heater, t0, t1))
        return c

    def rhs(self, t, y):
        y = y.tolist() if isinstance(y, np.ndarray) else list(y)
        self._T = y[-2]
        d = super().rhs(t, y[:-2])
        P = abs(self.friction_and_rates(t, y[:-2])[0] * self.velocity(t, y))
        dT = (self.eta * P - (self._T - self.T_amb) / self.R_th + self.P_ext(t)) / self.C_th
        return [*d, dT, P]


def reference_simulate_heated(model, t_eval, ambient, input=None, rtol=1e-10, atol=None):
    """Integrates ReferenceHeatedSystem from rest at T_0 (solve_ivp LSODA, restarted at every corner
    of the input and the heater). Returns (time, states (N, n)): the last two columns T and W."""
    sys_ = ReferenceHeatedSystem(model, ambient, input)
    t_eval = np.asarray(t_eval, float)
    t0, t1 = float(t_eval[0]), float(t_eval[-1])
    bounds = np.union1d([t0, t1], sys_.corners(t0, t1))
    y = np.zeros(sys_.n)
    y[-2] = sys_.T_0
    out = np.zeros((t_eval.size, sys_.n))
    out[0] = y
    if atol is None:
        atol = rtol * np.concatenate([super(ReferenceHeatedSystem, sys_).scales(), [1.0, 1e-6]])
    for a, b in zip(bounds[:-1], bounds[1:]):
        if b - a <= 1e-12 * max(1.0, abs(t1)):
            continue
        sys_.begin_segment(a, b)
        sol = solve_ivp(sys_.rhs, (a, b), y, method="LSODA", rtol=rtol, atol=atol, dense_output=True)
        if sol.status < 0:
            raise RuntimeError(f"reference integration failed on [{a}, {b}]: {sol.message}")
        sel = np.nonzero((t_eval > a) & (t_eval <= b))[0]
        if sel.size:
            out[sel] = sol.sol(t_eval[sel]).T
        y = sol.y[:, -1].copy()
        sys_.end_segment()
    return t_eval, out


# ---------------------------------------------------------------------------------------------
# Closed loop (control.h)
# ---------------------------------------------------------------------------------------------

def reference_closed_loop(stage, ref, T, pid, gain=100.0, substeps=10):
    """The closed loop of control.h written again as plain scalar Python (LuGre stage, Model I
    parameters at the stage temperature T, PID with a filtered derivative, the Canudas de Wit
    observer told T, semi-implicit Euler plant substeps, the exponential bristle step). Returns
    the position at each period start."""
    p = friction_params(stage, T)
    s0, s1, s2, fc, fs, vs = p.sigma0, p.sigma1, p.sigma2, p.fc, p.fs, p.vs
    m, dt = stage.plant.mass, ref.time[1] - ref.time[0]
    h = dt / substeps

    def step(z, v, dt_, extra=0.0):
        g = fc + (fs - fc) * math.exp(-(v / vs) ** 2)
        b = s0 * abs(v) / g
        rate = v - b * z + extra
        z += rate * (dt_ if abs(b * dt_) < 1e-12 else -math.expm1(-b * dt_) / b)
        zdot = v - s0 * abs(v) * z / g + extra
        return z, s0 * z + s1 * zdot + s2 * v

    x, v, z, zh, integ, dfilt, e_prev = ref.position[0], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    kp, ki, kd, tau = pid.kp, pid.ki, pid.kd, pid.tau_d
    a = -math.expm1(-dt / tau)
    xs = np.empty(ref.time.size)
    for i in range(ref.time.size):
        e = ref.position[i] - x
        if i == 0:
            e_prev = e
        dfilt += a * ((e - e_prev) / dt - dfilt)
        integ += e * dt
        e_prev = e
        zh, Fh = step(zh, v, dt, -gain * -e)
        u = kp * e + ki * integ + kd * dfilt + Fh
        xs[i] = x
        for _ in range(substeps):
            z, F = step(z, v, h)
            v += (u - F) / m * h
            x += v * h
    return xs
