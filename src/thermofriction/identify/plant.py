"""The plant from a stage response: xi, wn and K of x'' + 2 xi wn x' + wn^2 x = K wn^2 u(t), the way
the paper obtained them (Eqs. 3-4), from any recorded input (a step, a sawtooth...)."""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
from scipy import linalg, optimize, signal, stats

from ..errors import InputError
from .parameters import Parameters


def step_response(time, xi, wn, K, amplitude, t_step=0.0):
    """Exact response of the second-order stage to a step of ``amplitude`` volts at ``t_step``."""
    tau = np.clip(np.asarray(time, float) - t_step, 0.0, None)
    if xi < 1:
        wd = wn * math.sqrt(1 - xi ** 2)
        g = 1 - np.exp(-xi * wn * tau) * (np.cos(wd * tau) + xi / math.sqrt(1 - xi ** 2) * np.sin(wd * tau))
    elif xi == 1:
        g = 1 - np.exp(-wn * tau) * (1 + wn * tau)
    else:
        s = math.sqrt(xi ** 2 - 1)
        p1, p2 = -wn * (xi - s), -wn * (xi + s)
        g = 1 + (p2 * np.exp(p1 * tau) - p1 * np.exp(p2 * tau)) / (p1 - p2)
    return K * amplitude * g


def unit_gain_response(time, voltage, xi, wn):
    """Response with K = 1 to the recorded voltage, exact for piecewise-linear input: the
    first-order-hold discretisation of the state-space model on each sampling interval."""
    t = np.asarray(time, float)
    u = np.asarray(voltage, float)
    A = np.array([[0.0, 1.0], [-wn * wn, -2 * xi * wn]])
    B = np.array([0.0, wn * wn])
    dt = np.diff(t)
    if np.ptp(dt) > 1e-9 * dt.mean():
        raise InputError("the plant fit needs uniformly sampled data")
    h = float(dt.mean())
    # augmented exponential gives Phi, Gamma0 (zero-order part) and Gamma1 (ramp part) at once
    M = np.zeros((4, 4))
    M[:2, :2] = A * h
    M[:2, 2] = B * h
    M[2, 3] = 1.0
    E = linalg.expm(M)
    Phi, G0, G1 = E[:2, :2], E[:2, 2], E[:2, 3]
    # x[k+1] = Phi x[k] + G0 u[k] + G1 (u[k+1] - u[k]). With w[k] = x[k] - G1 u[k] this is the
    # ordinary discrete system w[k+1] = Phi w[k] + Bt u[k], y[k] = C w[k] + C G1 u[k]: one lfilter
    # call, plus the free response of w[0] = -G1 u[0] (the stage starts at rest).
    Bt = Phi @ G1 + G0 - G1
    C = np.array([1.0, 0.0])
    num, den = signal.ss2tf(Phi, Bt[:, None], C[None, :], np.array([[C @ G1]]))
    y = signal.lfilter(num[0], den, u)
    w0 = -G1 * u[0]
    if np.any(w0):
        ev, V = np.linalg.eig(Phi)
        coef = np.linalg.solve(V, w0)
        k = np.arange(len(t))
        y = y + np.real((C @ V) @ (coef[:, None] * ev[:, None] ** k[None, :]))
    return y


@dataclasses.dataclass
class PlantFit:
    damping_ratio: float
    natural_frequency: float
    gain: float
    parameters: Parameters
    rmse: float
    n_points: int
    wall_time: float

    def plant(self, mass, end_effector_mass):
        from ..models import StickSlipPlant
        return StickSlipPlant(mass=mass, end_effector_mass=end_effector_mass, damping_ratio=self.damping_ratio,
                              natural_frequency=self.natural_frequency, gain=self.gain)

    def to_dict(self):
        return {"parameters": self.parameters.to_dict(), "rmse": self.rmse, "n_points": self.n_points,
                "wall_time": self.wall_time}

    def report(self):
        lines = ["[[Plant fit]]", f"    rmse = {self.rmse * 1e9:.4g} nm, {self.n_points} points"]
        for p in self.parameters.values():
            lines.append(f"    {p.name:18s} {p.value:12.6g} +/- {p.stderr:.3g}  95 % [{p.ci95[0]:.6g}, {p.ci95[1]:.6g}] {p.unit}")
        return "\n".join(lines)


def fit_plant(time_s, voltage, stage_displacement, initial=None) -> PlantFit:
    """Fits xi, wn [rad/s], K [m/V] to a measured stage displacement. K and the sensor's offset
    enter linearly and are solved for exactly at every (xi, wn); those two are found by a grid
    over frequency and damping, then least squares in log space. Intervals come from the full
    Jacobian at the optimum."""
    t0 = time.perf_counter()
    t = np.asarray(time_s, float)
    u = np.asarray(voltage, float)
    y = np.asarray(stage_displacement, float)
    if not (t.shape == u.shape == y.shape) or t.size < 20:
        raise InputError("the plant fit needs time, voltage and stage displacement of equal length (>= 20 samples)")
    if np.ptp(u) == 0:
        raise InputError("the recorded voltage is constant: a plant fit needs an input that moves the stage")

    def linear_part(xi, wn):
        g = unit_gain_response(t, u, xi, wn)
        A = np.column_stack([g, np.ones_like(g)])
        coef, *_ = np.linalg.lstsq(A, y, rcond=None)
        return coef, A @ coef - y

    def residual(phi):
        return linear_part(math.exp(phi[0]), math.exp(phi[1]))[1]

    if initial is None:
        nyq = math.pi / float(np.mean(np.diff(t)))
        best = None
        for wn in np.geomspace(2 * math.pi * 5, 0.5 * nyq, 40):
            for xi in (0.02, 0.05, 0.1, 0.2, 0.35, 0.5, 0.7, 1.0, 1.5):
                r = linear_part(xi, wn)[1]
                c = float(r @ r)
                if best is None or c < best[0]:
                    best = (c, xi, wn)
        initial = best[1:]
    res = optimize.least_squares(residual, np.log(initial[:2]), method="lm", xtol=1e-14, ftol=1e-14, gtol=1e-14)
    xi, wn = (math.exp(v) for v in res.x)
    (K, offset), r = linear_part(xi, wn)
    # full Jacobian in (xi, wn, K, offset) by central differences of the exact response
    def model(theta):
        return theta[2] * unit_gain_response(t, u, theta[0], theta[1]) + theta[3]
    theta = np.array([xi, wn, K, offset])
    J = np.empty((t.size, 4))
    for k in range(4):
        h = 1e-6 * max(abs(theta[k]), 1e-12)
        tp, tm = theta.copy(), theta.copy()
        tp[k] += h
        tm[k] -= h
        J[:, k] = (model(tp) - model(tm)) / (2 * h)
    dof = max(t.size - 4, 1)
    s2 = float(r @ r) / dof
    col = np.linalg.norm(J, axis=0)  # scale columns first: volts and rad/s differ by 10 decades
    col[col == 0] = 1.0
    Js = J / col
    cov = s2 * np.linalg.pinv(Js.T @ Js) / np.outer(col, col)
    se = np.sqrt(np.clip(np.diag(cov), 0, None))
    tq = stats.t.ppf(0.975, dof)
    params = Parameters()
    for name, unit, v, e in (("damping_ratio", "", xi, se[0]), ("natural_frequency", "rad/s", wn, se[1]),
                             ("gain", "m/V", K, se[2])):
        p = params.add(name, v, unit=unit)
        p.stderr, p.ci95 = float(e), (v - tq * e, v + tq * e)
    return PlantFit(xi, wn, K, params, math.sqrt(float(r @ r) / t.size), int(t.size), time.perf_counter() - t0)


__all__ = ["fit_plant", "step_response", "unit_gain_response", "PlantFit"]
