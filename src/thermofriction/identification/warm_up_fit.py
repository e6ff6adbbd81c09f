"""The warm-up fit's least squares (docs/self-heating.md#warm-up-without-a-contact-temperature): the parameters
(the friction's law coefficients and constants, the heat path per unit of eta, the proxy's lag, the initial
temperatures), the residuals of every record each by its own noise (the forces of soak and warm-up runs, each
run's sensor offset profiled out, and the proxy's temperature), the optimum, and its covariance.

The friction's forces at the temperature grid depend on the friction's values only: they are cached on them, so
that the Jacobian's columns of the heat path (forward differences, like every column here) cost only the heat
balance's integration."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import _bridge
from .._lazy import lazy
from ..errors import ComputationError, ThermofrictionError
from ..fitting.identifiability import scaled_svd
from ..fitting.optimiser import UNDETERMINED
from ..fitting.parameters import get_value, with_values
from ..fitting.uncertainty import inflation_of
from .warm_up_path import HeatPath, forces_at, track

optimize = lazy("scipy.optimize")

#: the heat path's parameters, with their units (per unit of eta: C/eta and eta R)
HEAT_UNITS = {"C_th": "J/K", "R_th": "K/W", "C_2": "J/K", "R_2": "K/W", "tau_p": "s"}
#: the residual a failed evaluation gives every sample (in noise units): far above any fit
FAILED = 1e3
#: the forward differences' relative step
STEP = 1e-6


@dataclasses.dataclass
class SoakRun:
    """A run at a known, constant contact temperature: its label, samples, measured force, driving waveform and
    temperature [C]."""

    label: str
    time: np.ndarray
    force: np.ndarray
    waveform: object
    temperature: float


@dataclasses.dataclass
class Layout:
    """The fitted parameters: names, which are fitted in log space (positive ones), and which are the friction's
    (the rest are the heat path's, the proxy's lag and the initial temperatures ``T_0`` or ``T_0[label]``)."""

    names: list
    log: list
    friction: list

    def to_phi(self, theta):
        return np.array([math.log(v) if lg else v for v, lg in zip(theta, self.log)])

    def to_theta(self, phi):
        return np.array([math.exp(min(p, 700.0)) if lg else p for p, lg in zip(phi, self.log)])


class WarmProblem:
    """The residuals of a warm-up fit as a function of its parameters.

    Parameters
    ----------
    init : Model
        The initial model (Model I, prescribed motion): what is not fitted is held at its values.
    layout : Layout
        The fitted parameters.
    warm : list of WarmRecord
        The warm-up records, in the order they are integrated (a record follows the one it continues).
    soak : list of SoakRun
        The runs at known temperatures.
    nodes : int
        1 or 2 heat-path nodes.
    proxy_node : int
        The node the proxy follows (0 the contact, 1 the housing).
    grid, basis : numpy.ndarray
        The temperature grid and its spline basis (warm_up_path.spline_basis).
    sigma : dict
        The noise of each block of residuals (the record's label, or ``label + " proxy"``).
    held : dict
        Values held in the model (a law's slope holding an undetermined scale).
    """

    def __init__(self, init, layout, warm, soak, nodes, proxy_node, grid, basis, sigma, held=None):
        self.init, self.layout, self.warm, self.soak = init, layout, warm, soak
        self.nodes, self.proxy_node, self.grid, self.basis = nodes, proxy_node, grid, basis
        self.sigma = dict(sigma)
        self.held = dict(held or {})
        self._cache = (None, None)
        self.nfev = 0

    def model_of(self, theta):
        values = {n: v for n, v in zip(self.layout.names, theta) if n in self.layout.friction}
        return with_values(self.init, {**self.held, **values})

    def path_of(self, theta) -> HeatPath:
        v = dict(zip(self.layout.names, theta))
        return HeatPath(v["C_th"], v["R_th"], v.get("C_2"), v.get("R_2"), v.get("tau_p"), self.proxy_node)

    def forces(self, theta):
        """(the warm records' forces at the grid, the soak runs' forces), cached on the friction's values."""
        key = tuple(float(v) for n, v in zip(self.layout.names, theta) if n in self.layout.friction)
        if self._cache[0] != key:
            model = self.model_of(theta)
            warm = {r.label: forces_at(model, r.waveform, r.time, self.grid) for r in self.warm}
            soak = {s.label: forces_at(model, s.waveform, s.time, [s.temperature])[0] for s in self.soak}
            self._cache = (key, (warm, soak))
        return self._cache[1]

    def start_state(self, rec, theta, ends):
        """Where ``rec`` starts: the state the record it continues ended in, else every node at its T_0."""
        if rec.continues is not None:
            return ends[rec.continues]
        v = dict(zip(self.layout.names, theta))
        T0 = v.get(f"T_0[{rec.label}]", v.get("T_0"))
        path = self.path_of(theta)
        return np.full(path.states, T0)

    def run(self, theta, forces=None):
        """({label: Track}, {label: soak force}) at ``theta`` (``forces``: the grid's and the soak runs' forces
        given, else computed)."""
        warm_f, soak_f = self.forces(theta) if forces is None else forces
        path = self.path_of(theta)
        tracks, ends = {}, {}
        for rec in self.warm:
            tr = track(path, rec, warm_f[rec.label], self.grid, self.basis, self.start_state(rec, theta, ends))
            tracks[rec.label], ends[rec.label] = tr, tr.end
        return tracks, soak_f

    def blocks(self, theta, forces=None) -> list:
        """[(block name, raw residuals, measured)] : each run's force error with its own offset removed, and the
        proxy's temperature error."""
        tracks, soak_f = self.run(theta, forces)
        out = []
        for s in self.soak:
            e = soak_f[s.label] - s.force
            out.append((s.label, e - e.mean(), s.force))
        for rec in self.warm:
            e = tracks[rec.label].force - rec.force
            out.append((rec.label, e - e.mean(), rec.force))
            if rec.proxy is not None and self.path_of(theta).tau_p is not None:
                out.append((rec.label + " proxy", tracks[rec.label].proxy - rec.proxy, rec.proxy))
        return out

    def residuals(self, phi):
        """The residuals in noise units at the transformed parameters ``phi``."""
        self.nfev += 1
        return self.whitened(self.layout.to_theta(phi))

    def whitened(self, theta, forces=None):
        """The residuals in noise units at ``theta`` (FAILED everywhere where the model cannot be evaluated)."""
        try:
            with np.errstate(all="ignore"):  # (a trial step far off overflows: its residuals are refused below)
                r = np.concatenate([e / self.sigma[name] for name, e, _ in self.blocks(theta, forces)])
        except (ThermofrictionError, ValueError, np.linalg.LinAlgError, OverflowError):
            return np.full(self.size, FAILED)
        return r if np.all(np.isfinite(r)) else np.full(self.size, FAILED)

    def _force_derivatives(self, theta):
        """d(forces)/d(each fitted friction name): the grid's (label -> names x nodes x samples) and the soak
        runs' (label -> names x samples), by the core's exact stepping's closed-form sensitivities to the values at
        each temperature and the chain rule through the laws there."""
        model = self.model_of(theta)
        names = self.layout.friction
        values = sorted({n.split(".")[0] for n in names})

        def at(waveform, time, T):
            spec = _bridge.model_spec(model, float(T), waveform)
            return (_bridge.prescribed_force(spec, time, values)[1] @ law_chain(model, names, values, T)).T
        warm = {r.label: np.stack([at(r.waveform, r.time, T) for T in self.grid], axis=1) for r in self.warm}
        soak = {s.label: at(s.waveform, s.time, s.temperature) for s in self.soak}
        return warm, soak

    def jacobian(self, phi):
        """The residuals' Jacobian in the transformed parameters: forward differences of the heat balance, with
        the forces moved along their exact derivatives for the friction's names (no stepping per column)."""
        theta = self.layout.to_theta(phi)
        r0 = self.whitened(theta)
        warm_f, soak_f = self.forces(theta)
        dwarm, dsoak = self._force_derivatives(theta) if self.layout.friction else ({}, {})
        J = np.empty((r0.size, theta.size))
        for j, name in enumerate(self.layout.names):
            h = STEP * (abs(theta[j]) if self.layout.log[j] or theta[j] != 0 else 1.0)
            if name in self.layout.friction:
                k = self.layout.friction.index(name)
                moved = ({lab: f + h * dwarm[lab][k] for lab, f in warm_f.items()},
                         {lab: f + h * dsoak[lab][k] for lab, f in soak_f.items()})
                r = self.whitened(theta, moved)
            else:
                t = theta.copy()
                t[j] += h
                r = self.whitened(t, (warm_f, soak_f))
            J[:, j] = (r - r0) / h * (theta[j] if self.layout.log[j] else 1.0)
        return J

    @property
    def size(self) -> int:
        n = sum(s.time.size for s in self.soak) + sum(r.time.size for r in self.warm)
        return n + sum(r.time.size for r in self.warm if r.proxy is not None and "tau_p" in self.layout.names)


def solve(problem: WarmProblem, theta0, max_nfev=200):
    """scipy's trust-region least squares from ``theta0``; returns (theta, result)."""
    phi0 = problem.layout.to_phi(theta0)
    if failed(problem.residuals(phi0)):
        raise ComputationError("the warm-up fit cannot evaluate its model at its start (a law turns invalid at the "
                               "temperatures the start reaches): give starting values closer to the data (--init)")
    res = optimize.least_squares(problem.residuals, phi0, jac=problem.jacobian, method="trf", x_scale="jac",
                                 max_nfev=max_nfev)
    if failed(res.fun):
        raise ComputationError("the warm-up fit failed: the model cannot be evaluated near its start (give "
                               "starting values closer to the data: --init with laws and a [heat] section)")
    return problem.layout.to_theta(res.x), res


def failed(r) -> bool:
    """Whether residuals are those of a failed evaluation."""
    return not np.all(np.isfinite(r)) or float(r @ r) >= 0.5 * FAILED ** 2 * r.size


def covariance(problem: WarmProblem, theta, res):
    """(covariance of theta, residual variance times its inflation, the SVD (S, Vt, col, bad), statistics): from
    the Jacobian at the optimum (least_squares' own, in the transformed parameters, brought back), the residuals'
    scatter and their autocorrelation (fitting.uncertainty: inflation_of); a direction the data do not determine
    gives an infinite variance (fitting.identifiability: scaled_svd)."""
    J = res.jac * np.array([1.0 / t if lg else 1.0 for t, lg in zip(theta, problem.layout.log)])
    r = res.fun
    sizes = [e.size for _, e, _ in problem.blocks(theta)]
    n, p = J.shape
    dof = max(n - p - len(sizes), 1)
    s2 = float(r @ r) / dof
    inflation, rho = inflation_of(r, sizes)
    S, Vt, col, bad, cov1 = scaled_svd(J, UNDETERMINED)
    stats = {"dof": dof, "residual_std": math.sqrt(s2), "autocorrelation": rho, "variance_inflation": inflation,
             "effective_samples": n / inflation, "residuals": "in noise units (each block by its own noise)"}
    return cov1 * s2 * inflation, s2 * inflation, (S, Vt, col, bad), stats


def gradient(f, theta, layout: Layout) -> np.ndarray:
    """The forward-difference gradient of the vector function ``f`` in ``theta`` (columns per parameter)."""
    f0 = np.asarray(f(theta), float)
    G = np.empty((f0.size, len(theta)))
    for k in range(len(theta)):
        h = STEP * max(abs(theta[k]), 1e-3 if not layout.log[k] else abs(theta[k]))
        t = np.array(theta, float)
        t[k] += h
        G[:, k] = (np.asarray(f(t), float) - f0) / h
    return G


def delta_band(G, cov, z=1.959963984540054) -> np.ndarray:
    """z times the standard deviation of G theta under ``cov`` (inf where it involves an undetermined
    direction)."""
    finite = np.isfinite(np.diag(cov))
    c = np.where(np.isfinite(cov), cov, 0.0)
    var = np.einsum("ij,jk,ik->i", G, c, G)
    loose = np.any(np.abs(G[:, ~finite]) > 0, axis=1) if (~finite).any() else np.zeros(G.shape[0], bool)
    return np.where(loose, math.inf, z * np.sqrt(np.maximum(var, 0.0)))


def law_chain(model, names, values, T) -> np.ndarray:
    """d(the friction's ``values`` at T)/d(the fitted ``names``): 1 for a value fitted as itself, a law's
    derivative in a coefficient by central differences (exact for the laws linear in their coefficients)."""
    M = np.zeros((len(values), len(names)))
    for j, name in enumerate(names):
        base, _, coef = name.partition(".")
        if not coef:
            M[values.index(base), j] = 1.0
            continue
        law = model.laws[base]
        c = np.array(law.coefficients(), float)
        k = law.coefficient_names().index(coef)
        h = 1e-4 * (abs(c[k]) if c[k] != 0 else max(float(np.max(np.abs(c))), 1e-300))
        up, down = c.copy(), c.copy()
        up[k] += h
        down[k] -= h
        M[values.index(base), j] = (float(law.with_coefficients(up)(T)) - float(law.with_coefficients(down)(T))) / (2 * h)
    return M


def law_slope_name(model) -> str | None:
    """The coefficient that holds a Model I law's temperature scale: the first linear law's slope ``a`` or
    exponential law's rate ``b`` (None where no law is of either kind)."""
    for name, law in model.laws.items():
        if law.kind in ("linear", "exp"):
            return f"{name}.{'a' if law.kind == 'linear' else 'b'}"
    return None


def held_values(model, name) -> dict:
    """{name: its value in ``model``}: a value the fit holds."""
    return {name: get_value(model, name)}


__all__ = ["SoakRun", "Layout", "WarmProblem", "solve", "covariance", "gradient", "delta_band", "law_slope_name",
           "held_values", "failed", "HEAT_UNITS"]
