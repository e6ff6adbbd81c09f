"""The closed loop of control.h, written again as plain scalar Python: a test oracle and the
baseline of benchmarks/bench_control.py. Its LuGre step is the controller's discretisation (the
exponential bristle update, the observer's correction inside z'), not the continuous equations
of friction.py; only the parameters come from there."""

from __future__ import annotations

import math

import numpy as np

from .friction import friction_params


def reference_closed_loop(stage, ref, T, pid, gain=100.0, substeps=10, T_comp=None, friction=False,
                          inertia_feedforward=False, L=None, L_comp=None):
    """The closed loop of control.h written again as plain scalar Python (LuGre stage, Model I
    parameters at the stage temperature T, PID with a filtered derivative, the Canudas de Wit
    observer told T_comp, semi-implicit Euler plant substeps, the exponential bristle step; with
    inertia_feedforward, the control adds m times the reference velocity's change over the period). T and
    T_comp: one value, or one per control period (a warm-up; what a sensor or an estimator told the
    observer); T_comp None: T. L and L_comp, the same for the load a law of the load reads (None: none; L_comp
    None: L). Returns the position at each period start."""
    n = ref.time.size
    T_plant = np.broadcast_to(np.asarray(T, float), (n,))
    T_told = T_plant if T_comp is None else np.broadcast_to(np.asarray(T_comp, float), (n,))
    L_plant = np.broadcast_to(np.asarray(math.nan if L is None else L, float), (n,))
    L_told = L_plant if L_comp is None else np.broadcast_to(np.asarray(L_comp, float), (n,))
    cache = {}

    def params(Ti, Li):
        if (Ti, Li) not in cache:
            p = friction_params(stage, Ti, None if math.isnan(Li) else Li)
            cache[Ti, Li] = (p.sigma0, p.sigma1, p.sigma2, p.fc, p.fs, p.vs)
        return cache[Ti, Li]

    m, dt = stage.plant.mass, ref.time[1] - ref.time[0]
    h = dt / substeps

    def step(z, v, dt_, Ti, Li, extra=0.0):
        s0, s1, s2, fc, fs, vs = params(Ti, Li)
        g = fc + (fs - fc) * math.exp(-(v / vs) ** 2)
        b = s0 * abs(v) / g
        rate = v - b * z + extra
        z += rate * (dt_ if abs(b * dt_) < 1e-12 else -math.expm1(-b * dt_) / b)
        zdot = v - s0 * abs(v) * z / g + extra
        return z, s0 * z + s1 * zdot + s2 * v

    x, v, z, zh, integ, dfilt, e_prev = ref.position[0], 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    kp, ki, kd, tau = pid.kp, pid.ki, pid.kd, pid.tau_d
    a = -math.expm1(-dt / tau)
    xs, Fs = np.empty(n), np.empty(n)
    for i in range(n):
        e = ref.position[i] - x
        if i == 0:
            e_prev = e
        dfilt += a * ((e - e_prev) / dt - dfilt)
        integ += e * dt
        e_prev = e
        zh, Fh = step(zh, v, dt, float(T_told[i]), float(L_told[i]), -gain * -e)
        u = kp * e + ki * integ + kd * dfilt + Fh
        if inertia_feedforward and i + 1 < n:
            u += m * (ref.velocity[i + 1] - ref.velocity[i]) / dt
        xs[i] = x
        F_sum = 0.0
        for _ in range(substeps):
            z, F = step(z, v, h, float(T_plant[i]), float(L_plant[i]))
            v += (u - F) / m * h
            x += v * h
            F_sum += F
        Fs[i] = F_sum / substeps
    return (xs, Fs) if friction else xs


def disturbance_observer(x, u, noise, mass, dt, tau=0.0):
    """The friction the loop's disturbance observer measures (control.h), from the positions at the period
    starts x, the controls u and the encoder's noise, low-passed with time constant tau (0: none; the filter
    starts at the first measurement): (velocity, force) per period, the force NaN in the first two periods.
    Written again from the documented formula."""
    xe = x + (0.0 if noise is None else noise)
    v, F = np.zeros(x.size), np.full(x.size, np.nan)
    v[1] = (xe[1] - xe[0]) / dt
    v[2:] = (xe[2:] - xe[:-2]) / (2.0 * dt)
    F[2:] = 0.5 * (u[1:-1] + u[:-2]) - mass * (xe[2:] - 2.0 * xe[1:-1] + xe[:-2]) / (dt * dt)
    if tau > 0.0:
        a = -math.expm1(-dt / tau)
        for i in range(3, x.size):
            F[i] = F[i - 1] + a * (F[i] - F[i - 1])
    return v, F
