"""Self-heating (docs/models.md#self-heating): the lumped thermal model on top of ReferenceSystem,
the friction parameters taken at the state temperature."""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from .friction import friction_params
from .plants import ReferenceSystem
from .waveforms import scalar_waveform, waveform_corners


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
