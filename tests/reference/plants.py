"""The plants (docs/models.md#plants) with any friction model, as plain scalar Python right-hand
sides for solve_ivp.

    ReferenceSystem(model, temperature, input, gms_mode)   any plant, any friction model: rhs,
                                                           friction, GMS stick/slip events, scales
    ReferenceModel(model, temperature, input)              LuGre on the stick-slip actuator: a
                                                           ReferenceSystem with the (X, V, Z)
                                                           scales of the C core's default tolerances

States: stick-slip [x_p, v_p, x_e, v_e, *z], v_r = v_e - v_p (the end effector relative to the
stage); the stage feels +F, the end effector -F (docs/models.md#conventions). The friction comes
from friction.py only. GMS switches between sticking and slipping at events (gms_events,
gms_switch), with a scan of the dense output for crossings that come and go within one step.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from thermofriction.models import ModelII
from thermofriction.waveforms import Sampled, Sine, Zero

from .friction import FrictionParams, friction_params, on_side, stribeck_g, thermal_friction
from .waveforms import interp_scalar, scalar_waveform, scalar_waveform_slope, waveform_corners

_NSTATE = {"coulomb": 0, "stribeck": 0, "dahl": 1, "lugre": 1, "elastoplastic": 1}
_NMECH = {"stick-slip": 4, "mass": 2, "prescribed": 0}


class ReferenceSystem:
    """Any plant with any friction model and thermal extension, as plain scalar Python.

    States: stick-slip [x_p, v_p, x_e, v_e, *z] (v_r = v_e - v_p; the stage feels +F, the end
    effector -F); mass [x, v, *z] (v_r = v, m v' = f(t) + k_s (v_0 t - x) - F); prescribed [*z]
    (v_r = the input's slope). z: the friction model's states (GMS: the element forces F_i).
    ``modes`` holds GMS's element modes (0 stuck, +1/-1 slipping that way), all stuck from rest
    unless ``gms_mode`` says otherwise."""

    def __init__(self, model, temperature=None, input=None, gms_mode=None, load=None):
        self.model = model
        self.load = load  # a number, a Sampled load (interpolated, held beyond its ends), or None
        if isinstance(load, Sampled):
            lt, lv = [float(v) for v in load.time], [float(v) for v in load.value]
            self.L_of_t = lambda t: interp_scalar(lt, lv, t)
        else:
            self.L_of_t = lambda t: load
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
            self.T_of_t = lambda t: interp_scalar(tt, tv, t)
            self._const = None
        else:
            T = math.nan if temperature is None else float(temperature)
            self.T_of_t = lambda t: T
            self._const = None if isinstance(load, Sampled) else friction_params(model, T, load)
        if gms_mode is not None:
            self.modes = [int(np.sign(mv)) for mv in gms_mode]
        else:
            self.modes = [0] * (self.nz if self.kind == "gms" else 0)
        self._disarmed = set()  # GMS (element, direction) whose capacity was passed unloaded

    # -- parameters and inputs -----------------------------------------------------------------
    def params(self, T, t=0.0) -> FrictionParams:
        return friction_params(self.model, T, self.L_of_t(t))

    def params_at_time(self, t) -> FrictionParams:
        if self._const is not None:
            return self._const
        key = (self.T_of_t(t), self.L_of_t(t))
        if key != self._last_T:
            self._last_T, self._last_p = key, friction_params(self.model, *key)
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

    def position(self, t, y):
        """x_r, the driven body's position relative to its driving surface (the ripple's argument)."""
        if self.plant == "stick-slip":
            return y[2] - y[0]
        if self.plant == "mass":
            return y[0]
        return self.input_value(t)

    # -- friction and the right-hand side --------------------------------------------------------
    def friction_and_rates(self, t, y):
        p = self.params_at_time(t)
        return thermal_friction(self.kind, p, self.velocity(t, y), y[self.nm:], self.modes, self.position(t, y))

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
                        p = on_side(self.params_at_time(t), s)  # the capacity in direction s
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
        g = stribeck_g(on_side(p, v), v)
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
        for signal in (self.temperature, self.load):
            if isinstance(signal, Sampled):
                tt = np.asarray(signal.time, float)
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



def is_lugre_actuator(model):
    return model.plant.type == "stick-slip" and model.friction.model == "lugre"


class ReferenceModel(ReferenceSystem):
    """LuGre on the stick-slip actuator, y = [x_p, v_p, x_e, v_e, z]: a ReferenceSystem (the same
    rhs and friction) whose scales() are the three characteristic magnitudes (X, V, Z) the C
    core's default absolute tolerances are made of. The input is taken at t itself (no segment
    is begun: reference_simulate restarts at the corners instead)."""

    def __init__(self, model, temperature=None, input=None):
        if model.plant.type != "stick-slip":
            raise TypeError("reference: only the stick-slip plant")
        if model.friction.model != "lugre":
            raise TypeError("reference: only LuGre friction")
        super().__init__(model, temperature, input)

    def scales(self):
        """Characteristic magnitudes (position, velocity, z): stroke T_em*|u|max/k, stroke*wn (at most
        1000 x the narrowest velocity band of the friction: v_smooth of the offset form, the Stribeck
        vs when fs != fc), fc/sigma0."""
        umax = self._input_peak()
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
