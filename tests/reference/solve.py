"""Simulation: the right-hand sides integrated from rest with scipy.integrate.solve_ivp, restarted
at every corner of the input (and knot of a sampled temperature) so that no step crosses a kink.

    friction_force(model, t, y, ...), rhs(model, t, y, ...)   one evaluation, any model
    default_atol(model, ...)                                  the C core's default tolerances
    reference_simulate(model, t_eval, ...)                    LuGre on the actuator (ReferenceModel),
                                                              piecewise or in one call; others go to
    reference_simulate_system(model, t_eval, ...)             any plant and friction model; GMS
                                                              stick/slip switches as terminal events
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from .plants import ReferenceModel, ReferenceSystem, is_lugre_actuator
from .waveforms import waveform_slope, waveform_value


def friction_force(model, t, y, temperature=None, input=None, gms_mode=None):
    """F' at (t, y): the force resisting the end effector's sliding on the stage (any plant and
    friction model: the driven body's sliding; GMS element modes from ``gms_mode``)."""
    return ReferenceSystem(model, temperature, input, gms_mode).friction(float(t), [float(v) for v in y])


def rhs(model, t, y, temperature=None, input=None, gms_mode=None):
    """dy/dt at (t, y), y = [x_p, v_p, x_e, v_e, z] (other plants and friction models: the states
    of ReferenceSystem; GMS element modes from ``gms_mode``, default all stuck)."""
    return np.array(ReferenceSystem(model, temperature, input, gms_mode).rhs(float(t), [float(v) for v in y]))


def default_atol(model, temperature=None, input=None, rtol=1e-10):
    """Per-state absolute tolerances: rtol times each state's characteristic magnitude (the
    stroke for positions, stroke x natural frequency for velocities, fc/sigma0 for z). For the
    Li (2009) presets at rtol = 1e-10: about 3e-16 m, 2e-12 m/s and 4e-17 m."""
    if not is_lugre_actuator(model):
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
    if not is_lugre_actuator(model):
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
                              atol=None, first_step=None, max_step=math.inf, load=None):
    """Integrates any plant with any friction model from rest (solve_ivp, restarted at every corner
    of the input and knot of a sampled temperature; GMS also at every stick/slip switch, located
    by solve_ivp's terminal events, and at crossings that come and go within one step, found by
    scanning the dense output). atol=None: rtol times ReferenceSystem.scales(). max_step bounds
    the steps: an adaptive step can jump a short window where the solution moves after being
    exactly still (a slipping GMS element's force, constant while |v| >> vs, rises as v crosses
    the Stribeck band before a reversal) without its error estimate noticing."""
    sys_ = ReferenceSystem(model, temperature, input, load=load)
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
