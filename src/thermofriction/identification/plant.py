"""The plant from a stage response: xi, wn and K of

    x'' + 2 xi wn x' + wn^2 x = K wn^2 u(t)

the way the paper obtained them (Eqs. 3-4), from any recorded input (a step, a sawtooth...).

The response is computed exactly for the sampled input (no ODE solver): the state-space model is
discretised with the matrix exponential, with a first-order hold (``hold="foh"``, exact for an
input that is linear between samples: ramps, sawtooths, steps with a slew) or a zero-order hold
(``hold="zoh"``, exact for an input that is constant between samples: ideal steps at a sample
instant). The stage starts at rest at zero, as in ``tf.simulate``.

The gain K and the sensor's zero offset enter linearly: they are solved for exactly at every
(xi, wn) (variable projection), and xi, wn are found by a coarse grid then Levenberg-Marquardt in
log space. Standard errors and 95 % intervals come from the full Jacobian in (xi, wn, K, offset)
at the optimum, cov = s^2 (J^T J)^-1, with s^2 inflated by (1 + rho) / (1 - rho) for residuals
with lag-1 autocorrelation rho > 0 (as in the friction fits); a direction the data cannot
determine gets an infinite interval and a warning.
"""

from __future__ import annotations

import dataclasses
import math
import time as _time

import numpy as np

from .._lazy import lazy
from ..errors import InputError
from ..results import Result, Summary, fields, heading, lines, table
from ..fitting.parameters import Parameters

from .plant_response import is_uniform, step_response, unit_gain_response

optimize, stats = lazy("scipy.optimize"), lazy("scipy.stats")

NAMES = ("damping_ratio", "natural_frequency", "gain")
UNITS = {"damping_ratio": "", "natural_frequency": "rad/s", "gain": "m/V"}


@dataclasses.dataclass
class PlantFit(Result):
    """The fitted plant: values, standard errors and 95 % intervals (in ``parameters``, and as
    ``stderr`` / ``ci95`` dicts), the correlation matrix of (xi, wn, K), and the fit statistics.

    Parameters
    ----------
    damping_ratio : float
        xi [-].
    natural_frequency : float
        wn [rad/s].
    gain : float
        K [m/V].
    parameters : Parameters
        xi, wn and K with their standard errors and 95 % intervals.
    rmse : float
        The residuals' root mean square [m].
    n_points : int
        The samples fitted.
    wall_time : float
        The fit's duration [s].
    offset : float, default 0.0
        The sensor's zero [m], profiled out.
    covariance, correlation : numpy.ndarray, optional
        Of (xi, wn, K).
    cost : float, default nan
        The sum of squared residuals [m^2].
    nfev : int, default 0
        The residuals' evaluations.
    success : bool, default True
        Whether the solver converged.
    message : str, default ""
        The solver's message.
    hold : {"foh", "zoh"}, default "foh"
        How the input was taken between samples.
    warnings : list of str, default []
        What the reader should know (strongly correlated residuals, ...).
    statistics : dict, default {}
        The residuals' statistics (degrees of freedom, autocorrelation, variance inflation).
    """

    damping_ratio: float
    natural_frequency: float              # [rad/s]
    gain: float                           # [m/V]
    parameters: Parameters
    rmse: float                           # [m]
    n_points: int
    wall_time: float                      # [s]
    offset: float = 0.0                   # [m] the sensor's zero, profiled out
    covariance: np.ndarray | None = None  # of (xi, wn, K)
    correlation: np.ndarray | None = None
    cost: float = math.nan                # sum of squared residuals [m^2]
    nfev: int = 0
    success: bool = True
    message: str = ""
    hold: str = "foh"
    warnings: list = dataclasses.field(default_factory=list)
    statistics: dict = dataclasses.field(default_factory=dict)

    @property
    def stderr(self) -> dict:
        return {k: self.parameters[k].stderr for k in NAMES}

    @property
    def ci95(self) -> dict:
        return {k: tuple(self.parameters[k].ci95) for k in NAMES}

    def modal_parameters(self):
        """(xi, wn, K), as ``StickSlipPlant.modal_parameters()``."""
        return self.damping_ratio, self.natural_frequency, self.gain

    def plant(self, mass, end_effector_mass):
        """A ``StickSlipPlant`` with the fitted xi, wn, K and the given masses (a stage response
        cannot tell the masses)."""
        from ..models import StickSlipPlant
        return StickSlipPlant(mass=mass, end_effector_mass=end_effector_mass, damping_ratio=self.damping_ratio,
                              natural_frequency=self.natural_frequency, gain=self.gain)

    def to_dict(self) -> dict:
        """JSON-ready (docs/formats.md#results-json): each parameter as {"value", "stderr", "ci95": [lo, hi], ...}."""
        from .._io import jsonable
        corr = None if self.correlation is None else self.correlation
        return jsonable({"parameters": self.parameters.to_dict(),
                         "correlation": {"names": list(NAMES), "matrix": corr},
                         "offset": self.offset, "rmse": self.rmse, "cost": self.cost, "n_points": self.n_points,
                         "iterations": self.nfev, "success": self.success, "message": self.message,
                         "hold": self.hold, "wall_time": self.wall_time, "warnings": self.warnings,
                         "statistics": self.statistics})

    title = "Plant fit"

    def summary(self) -> Summary:
        return Summary([("converged", str(self.success)), ("damping ratio", f"{self.damping_ratio:.6g}"),
                        ("natural frequency", f"{self.natural_frequency:.6g} rad/s"), ("gain", f"{self.gain:.6g} m/V"),
                        ("rmse", f"{self.rmse * 1e9:.4g} nm"), ("evaluations", str(self.nfev))])

    def _frame(self) -> dict:
        """One row per parameter: value, standard error, 95 % interval, unit."""
        ps = list(self.parameters.values())
        return {"name": [p.name for p in ps], "value": [p.value for p in ps], "stderr": [p.stderr for p in ps],
                "ci95_low": [None if p.ci95 is None else p.ci95[0] for p in ps],
                "ci95_high": [None if p.ci95 is None else p.ci95[1] for p in ps], "unit": [p.unit for p in ps]}

    def _blocks(self) -> list:
        """The report like lmfit's fit report: the fit, the parameters, the correlations above 0.1."""
        head = ("name", "value", "stderr", "rel", "95 % interval", "unit")
        rows = []
        for p in self.parameters.values():
            if p.stderr is None:
                rows.append((p.name, f"{p.value:.7g}", "", "", "", p.unit))
                continue
            rel = f"{100 * p.stderr / abs(p.value):.2g} %" if p.value and math.isfinite(p.stderr) else ""
            rows.append((p.name, f"{p.value:.7g}", f"{p.stderr:.4g}", rel,
                         f"[{p.ci95[0]:.6g}, {p.ci95[1]:.6g}]", p.unit))
        blocks = [heading(self.title), lines([f"{'converged' if self.success else 'NOT CONVERGED'}: {self.message}"]),
                  fields([("data points", str(self.n_points)), ("rmse", f"{self.rmse * 1e9:.4g} nm"),
                          ("sensor offset", f"{self.offset * 1e9:.4g} nm (profiled)"), ("input hold", self.hold),
                          ("evaluations", str(self.nfev)), ("wall time", f"{self.wall_time:.3g} s")], 16),
                  heading("Parameters"), table(head, rows, strip=True)]
        if self.correlation is not None:
            pairs = [(NAMES[i], NAMES[j], self.correlation[i, j]) for i in range(3) for j in range(i + 1, 3)
                     if np.isfinite(self.correlation[i, j]) and abs(self.correlation[i, j]) > 0.1]
            if pairs:
                blocks += [heading("Correlations", "(|C| > 0.1)"),
                           lines(f"C({a}, {b}) = {c:+.3f}" for a, b, c in sorted(pairs, key=lambda x: -abs(x[2])))]
        if self.warnings:
            blocks += [heading("Warnings"), lines(self.warnings)]
        return blocks

    def plot(self, duration=None):
        """A matplotlib figure of the fitted stage's response to a unit step of its input (K x wn^2 / (s^2 + 2 xi
        wn s + wn^2)), over ``duration`` [s] (default ten of its time constants 1/(xi wn))."""
        from matplotlib.figure import Figure  # no pyplot: the caller's backend (a notebook's) is left alone
        xi, wn, K = self.modal_parameters()
        t = np.linspace(0.0, duration or 10.0 / max(xi * wn, 1e-12), 500)
        fig = Figure(figsize=(6, 3.5), layout="constrained")  # (the axis labels inside the figure)
        ax = fig.subplots()
        ax.plot(t, step_response(t, xi, wn, K, 1.0) * 1e6)
        ax.set(xlabel="time [s]", ylabel="displacement [um per V]",
               title=f"fitted stage: xi {xi:.3g}, wn {wn:.4g} rad/s, K {K * 1e6:.4g} um/V")
        return fig


def _initial(initial):
    """(xi, wn) from an initial guess: a sequence (xi, wn[, K]) or a dict with those names."""
    if isinstance(initial, dict):
        try:
            xi, wn = initial["damping_ratio"], initial["natural_frequency"]
        except KeyError:
            raise InputError("initial must give 'damping_ratio' and 'natural_frequency'") from None
    else:
        try:
            xi, wn = (float(v) for v in list(initial)[:2])
        except (TypeError, ValueError):
            raise InputError(f"initial must be (xi, wn[, K]), got {initial!r}") from None
    if not (xi > 0 and wn > 0 and math.isfinite(xi) and math.isfinite(wn)):
        raise InputError(f"initial xi and wn must be positive, got {xi!r}, {wn!r}")
    return float(xi), float(wn)


def _checked_record(time, voltage, stage_displacement, hold):
    """The record as float arrays, refused with the reason where a plant fit cannot use it."""
    t = np.asarray(time, float).ravel()
    u = np.asarray(voltage, float).ravel()
    y = np.asarray(stage_displacement, float).ravel()
    if hold not in ("foh", "zoh"):
        raise InputError(f"hold must be 'foh' or 'zoh', got {hold!r}")
    if not (t.shape == u.shape == y.shape) or t.size < 20:
        raise InputError("the plant fit needs time, voltage and stage displacement of equal length (>= 20 samples)")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(u)) and np.all(np.isfinite(y))):
        raise InputError("the plant fit needs finite time, voltage and stage displacement")
    if np.any(np.diff(t) <= 0):
        raise InputError("the plant fit needs strictly increasing time")
    if np.ptp(u) == 0:
        raise InputError("the recorded voltage is constant: a plant fit needs an input that moves the stage")
    if np.ptp(y) == 0:
        raise InputError("the recorded stage displacement is constant: nothing to fit")
    return t, u, y


class _LinearPart:
    """The response's linear part: for given xi, wn, the gain K and the offset by linear least squares on
    [g 1] (solved centred: well conditioned, exact, and fast for 10^6 points), g the unit-gain response."""

    def __init__(self, t, u, y, hold):
        self.t, self.u, self.y, self.hold = t, u, y, hold
        self.ym = float(y.mean())
        self.yc = y - self.ym
        self.evals = 0

    def __call__(self, xi, wn):
        """(K and offset, g, residuals)"""
        self.evals += 1
        g = unit_gain_response(self.t, self.u, xi, wn, self.hold)
        gm = float(g.mean())
        gc = g - gm
        gg = float(gc @ gc)
        k = float(gc @ self.yc) / gg if gg > 0 else 0.0
        coef = np.array([k, self.ym - k * gm])
        return coef, g, k * g + coef[1] - self.y

    def cost(self, xi, wn):
        r = self(xi, wn)[2]
        return float(r @ r)


def _start(linear_part, t, initial, nyq):
    """(xi, wn) to start from: ``initial``, or the best of a coarse grid over wn (from about one period per
    record to the Nyquist frequency) and xi (0.01 to 3)."""
    if initial is not None:
        return _initial(initial)
    duration = float(t[-1] - t[0])
    lo = max(2 * math.pi / duration, 1e-6 * nyq)
    xis = (0.01, 0.03, 0.07, 0.15, 0.25, 0.4, 0.6, 0.85, 1.2, 2.0, 3.0)
    wns = np.geomspace(lo, 0.9 * nyq, max(24, int(12 * math.log10(0.9 * nyq / lo)) + 1))
    costs = np.array([[linear_part.cost(xi, wn) for xi in xis] for wn in wns])
    i, j = np.unravel_index(int(np.argmin(costs)), costs.shape)
    return xis[j], float(wns[i])


def _plant_covariance(t, u, hold, xi, wn, K, g, r):
    """The covariance of (xi, wn, K, offset) from the full Jacobian: central differences for xi and wn (the
    response is smooth and cheap), exact columns for the linear K and offset. As in the friction fits,
    coloured residuals (model error, quantisation) carry less information than white ones: s^2 is inflated by
    (1 + rho) / (1 - rho), rho their lag-1 autocorrelation. Returns (cov, corr, undetermined, statistics)."""
    J = np.empty((t.size, 4))
    d = 1e-6 * xi
    J[:, 0] = K * (unit_gain_response(t, u, xi + d, wn, hold) - unit_gain_response(t, u, xi - d, wn, hold)) / (2 * d)
    d = 1e-6 * wn
    J[:, 1] = K * (unit_gain_response(t, u, xi, wn + d, hold) - unit_gain_response(t, u, xi, wn - d, hold)) / (2 * d)
    J[:, 2] = g
    J[:, 3] = 1.0
    n, p = t.size, 4
    dof = max(n - p, 1)
    sse = float(r @ r)
    rho = min(max(float(r[1:] @ r[:-1]) / sse, 0.0), 0.99) if sse > 0 else 0.0
    inflation = (1 + rho) / (1 - rho)
    s2 = sse / dof * inflation
    col = np.linalg.norm(J, axis=0)  # scale the columns first: rad/s and m/V differ by 10 decades
    col[col == 0] = 1.0
    _, sv, Vt = np.linalg.svd(J / col, full_matrices=False)
    keep = sv > 1e-10 * sv[0]
    cov_s = (Vt[keep].T / sv[keep] ** 2) @ Vt[keep]
    cov = s2 * cov_s / np.outer(col, col)
    null = np.abs(Vt[~keep]).max(axis=0) > 1e-6 if np.any(~keep) else np.zeros(p, bool)
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.sqrt(np.outer(np.diag(cov), np.diag(cov)))
    corr[null, :] = np.nan
    corr[:, null] = np.nan
    return cov, corr, null, {"dof": dof, "residual_std": math.sqrt(sse / dof), "autocorrelation": rho,
                             "variance_inflation": inflation}


def fit_plant(time, voltage, stage_displacement, *, initial=None, hold="foh") -> PlantFit:
    """Fits xi, wn [rad/s] and K [m/V] to a measured stage displacement [m] under a measured
    voltage [V] (any input that moves the stage: a step, a sawtooth...).

    Parameters
    ----------
    time : array_like
        The sample times [s], strictly increasing.
    voltage : array_like
        The drive's voltage [V], one per sample.
    stage_displacement : array_like
        The stage's displacement [m], one per sample; at least 20 samples in all.
    initial : tuple or dict, optional
        (xi, wn[, K]) or a dict of them; default: the best of a coarse grid over wn (from about one period
        per record to the Nyquist frequency) and xi (0.01 to 3); K is always solved for exactly.
    hold : {"foh", "zoh"}, default "foh"
        How the input behaves between samples: linear or constant.

    Returns
    -------
    PlantFit

    Raises
    ------
    InputError
        Records of unequal length or shorter than 20 samples, non-finite values, time not increasing, a
        constant voltage, an unknown ``hold``.
    """
    t0 = _time.perf_counter()
    t, u, y = _checked_record(time, voltage, stage_displacement, hold)
    warns = []
    if not is_uniform(t):
        warns.append("sampling is not uniform: the response was simulated on a uniform grid and interpolated")
    linear_part = _LinearPart(t, u, y, hold)
    nyq = math.pi / float(np.median(np.diff(t)))
    guess = _start(linear_part, t, initial, nyq)
    scale = max(float(np.sqrt(np.mean(y * y))), 1e-300)  # residuals in units of the signal: a tame problem
    res = optimize.least_squares(lambda p: linear_part(math.exp(p[0]), math.exp(p[1]))[2] / scale, np.log(guess),
                                 method="lm", xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=1000)
    xi, wn = (math.exp(v) for v in res.x)
    (K, offset), g, r = linear_part(xi, wn)
    cov, corr, null, statistics = _plant_covariance(t, u, hold, xi, wn, K, g, r)
    se = np.sqrt(np.where(null, np.inf, np.clip(np.diag(cov), 0.0, None)))
    tq = float(stats.t.ppf(0.975, statistics["dof"]))
    params = Parameters()
    for k, (name, v) in enumerate(zip(NAMES, (xi, wn, K))):
        par = params.add(name, v, unit=UNITS[name])
        par.stderr = float(se[k])
        par.ci95 = (v - tq * se[k], v + tq * se[k])
        if null[k]:
            warns.append(f"{name} is not determined by this record: its interval is infinite")
    if wn > 0.5 * nyq:
        warns.append(f"natural_frequency {wn:.4g} rad/s is above half the Nyquist frequency ({nyq:.4g} rad/s): "
                     f"sample faster")
    if 2 * math.pi / wn > 0.5 * (t[-1] - t[0]):
        warns.append("the record is shorter than two natural periods: record longer")
    if statistics["autocorrelation"] > 0.5:
        warns.append(f"the residuals are strongly correlated (lag-1 autocorrelation {statistics['autocorrelation']:.2f}): "
                     f"the model does not explain the record fully; intervals widened by "
                     f"{math.sqrt(statistics['variance_inflation']):.2g}x")
    success = bool(res.status > 0)
    if not success:
        warns.append(f"the optimiser stopped early: {res.message}")
    sse = float(r @ r)
    return PlantFit(xi, wn, float(K), params, math.sqrt(sse / t.size), int(t.size), _time.perf_counter() - t0,
                    offset=float(offset), covariance=cov[:3, :3], correlation=corr[:3, :3], cost=sse,
                    nfev=linear_part.evals, success=success, message=str(res.message), hold=hold, warnings=warns,
                    statistics=statistics)


__all__ = ["fit_plant", "step_response", "unit_gain_response", "PlantFit"]
