"""The closed loop of control.h, written again as plain scalar Python: a test oracle and the
baseline of benchmarks/bench_control.py. Its LuGre step is the controller's discretisation (the
exponential bristle update, the observer's correction inside z'), not the continuous equations
of friction.py; only the parameters come from there."""

from __future__ import annotations

import math

import numpy as np

from .friction import friction_params


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
