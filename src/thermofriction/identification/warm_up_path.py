"""The warm-up fit's simulation (docs/self-heating.md#warm-up-without-a-contact-temperature): a friction force
record under a duty cycle with the contact's temperature moving along a lumped heat path driven by the friction
power, and a proxy sensor lagging one of its nodes.

Two time scales: the friction's fast states settle in milliseconds, the temperature moves in seconds to minutes.
So the force along a record is computed at a few fixed temperatures (``grid``) by the core's exact stepping of the
prescribed motion (``_bridge.prescribed_force``) and interpolated across temperature at the contact's T(t) (a
natural cubic spline in T, linear in the grid's forces: :func:`spline_basis`); the heat balance is integrated on a
coarse grid of bins (:func:`integrate`), exactly for its linear part over a bin (a matrix exponential) with the
bin's mean friction power interpolated across temperature the same way, evaluated at the bin's mid temperature by
one predictor-corrector pass. The heat path, per unit of eta (the fraction of the friction power that heats the
contact, which force data cannot tell from the heat capacities and resistances: ``C/eta`` and ``eta R`` are what
they determine):

    C_th T_c' = P - (T_c - T_h) / R_th             (T_h = T_amb with one node)
    C_2  T_h' = (T_c - T_h) / R_th - (T_h - T_amb) / R_2
    tau_p T_p' = T_node - T_p                       (the proxy, following the contact or the housing node)
"""

from __future__ import annotations

import bisect
import dataclasses
import math
import operator

import numpy as np

from .. import _bridge
from .._lazy import lazy
from ..drive import drive
from ..errors import InputError

interpolate = lazy("scipy.interpolate")

#: the bins of the heat balance: at most this fraction of the fastest time constant, and at most this many seconds
BIN_FRACTION = 0.05
MAX_BIN = 1.0
#: the temperature grid's nodes (the force is computed at each)
GRID_NODES = 7
#: the most bins of the heat balance per record before the heat path is known (each at most MAX_BIN wide)
MAX_BINS = 1500


def first_bin_width(duration: float) -> float:
    """The bins' width [s] for a record of ``duration`` [s] before the heat path is known: at most MAX_BIN,
    and at most MAX_BINS bins over the record.

    Parameters
    ----------
    duration : float
        The record's (or the longest record's) duration [s].

    Returns
    -------
    float
    """
    return min(MAX_BIN, duration / MAX_BINS)


@dataclasses.dataclass(frozen=True)
class HeatPath:
    """A lumped heat path per unit of eta: the contact node (``C_th`` [J/K], ``R_th`` [K/W] to the housing node or,
    with one node, to ambient), the housing node (``C_2``, ``R_2`` to ambient; None with one node), and a proxy
    sensor lagging node ``proxy_node`` (0 the contact, 1 the housing) by ``tau_p`` [s] (None without one)."""

    C_th: float
    R_th: float
    C_2: float | None = None
    R_2: float | None = None
    tau_p: float | None = None
    proxy_node: int = 0

    @property
    def nodes(self) -> int:
        return 1 if self.C_2 is None else 2

    @property
    def states(self) -> int:
        return self.nodes + (self.tau_p is not None)

    def system(self):
        """(A, B): the balance ``x' = A x + B [P, T_amb]`` over the states (contact, housing, proxy)."""
        n = self.states
        A, B = np.zeros((n, n)), np.zeros((n, 2))
        A[0, 0] = -1.0 / (self.R_th * self.C_th)
        B[0, 0] = 1.0 / self.C_th
        if self.nodes == 2:
            A[0, 1] = 1.0 / (self.R_th * self.C_th)
            A[1, 0] = 1.0 / (self.R_th * self.C_2)
            A[1, 1] = -1.0 / (self.R_th * self.C_2) - 1.0 / (self.R_2 * self.C_2)
            B[1, 1] = 1.0 / (self.R_2 * self.C_2)
        else:
            B[0, 1] = 1.0 / (self.R_th * self.C_th)
        if self.tau_p is not None:
            A[-1, self.proxy_node] = 1.0 / self.tau_p
            A[-1, -1] = -1.0 / self.tau_p
        return A, B

    def time_constants(self) -> list:
        """The heat path's time constants [s] (of its nodes: the proxy's lag apart), fastest first."""
        A, _ = self.system()
        k = self.nodes
        return sorted(float(-1.0 / ev) for ev in np.linalg.eigvals(A[:k, :k]).real)

    def steady_rise(self, power: float) -> float:
        """The contact's steady rise over ambient [K] at a constant friction power [W]."""
        return power * (self.R_th + (self.R_2 or 0.0))


@dataclasses.dataclass
class WarmRecord:
    """One warm-up record as the fit uses it: the experiment's label, samples, measured force, the waveform that
    drives the model (its measured motion), the speed at the samples, the bins of the heat balance (sample index
    where each bin starts, and the bins' edges in time), the ambient temperature per bin, the proxy record, and the
    label of the record it continues (None: it starts soaked at its own initial temperature)."""

    label: str
    time: np.ndarray
    force: np.ndarray
    waveform: object
    speed: np.ndarray
    starts: np.ndarray
    edges: np.ndarray
    ambient: np.ndarray
    proxy: np.ndarray | None
    continues: str | None


def warm_record(exp, model, bin_width: float) -> WarmRecord:
    """A :class:`WarmRecord` of the warm-up experiment ``exp`` driven as ``model`` is (its measured motion), with
    bins of about ``bin_width`` [s]."""
    t = np.asarray(exp.time, float)
    m = max(1, int(math.ceil((t[-1] - t[0]) / bin_width)))
    edges = np.linspace(t[0], t[-1], m + 1)
    starts = np.searchsorted(t, edges[:-1], side="left")
    starts = np.unique(np.clip(starts, 0, t.size - 1))
    edges = np.append(t[starts], t[-1])
    ambient = np.add.reduceat(np.asarray(exp.ambient_temperature, float), starts) / np.diff(np.append(starts, t.size))
    d = drive(exp, model, start="record")
    proxy = None if exp.proxy_temperature is None else np.asarray(exp.proxy_temperature, float)
    return WarmRecord(exp.label, t, np.asarray(exp.force, float), d.waveform, np.abs(exp.drive_velocity), starts,
                      edges, ambient, proxy, exp.continues)


def bin_width_for(path: HeatPath, duration: float) -> float:
    """The bins' width [s]: BIN_FRACTION of the fastest time constant (the proxy's lag included), at most MAX_BIN,
    and at least a thousandth of the record."""
    fastest = min(path.time_constants() + ([path.tau_p] if path.tau_p else []))
    return max(min(BIN_FRACTION * fastest, MAX_BIN), duration / 4000.0)


def forces_at(model, waveform, time, temperatures) -> np.ndarray:
    """The friction force along a measured motion at each of ``temperatures`` (rows), by the core's exact stepping
    (prescribed.h). Raises InputError where the friction model is one the core does not step exactly."""
    out = np.empty((len(temperatures), len(time)))
    for k, T in enumerate(temperatures):
        spec = _bridge.model_spec(model, float(T), waveform)
        if not _bridge.prescribed_applies(spec):
            raise InputError(f"the warm-up fit steps the friction exactly under the measured motion, which the "
                             f"{model.friction.model} friction model does not allow here")
        out[k] = _bridge.prescribed_force(spec, time)[0]
    return out


def spline_basis(grid) -> np.ndarray:
    """The natural cubic spline through ``grid`` as a linear map of the values at its nodes: coefficients of shape
    (4, nodes - 1, nodes), so that on interval i the spline of values y is sum_k c[k, i] @ y (T - grid[i])^(3-k)."""
    grid = np.asarray(grid, float)
    return interpolate.CubicSpline(grid, np.eye(grid.size), bc_type="natural").c


def weights_at(basis, grid, T) -> np.ndarray:
    """The spline's weights of the grid's values at temperatures ``T`` (samples x nodes)."""
    i = np.clip(np.searchsorted(grid, T, side="right") - 1, 0, len(grid) - 2)
    d = (np.asarray(T, float) - np.asarray(grid)[i])[:, None]
    with np.errstate(over="ignore", invalid="ignore"):  # (a trial step far off: its residuals are refused)
        return ((basis[0][i] * d + basis[1][i]) * d + basis[2][i]) * d + basis[3][i]


def _expm(M) -> np.ndarray:
    """exp(M) of a small matrix by scaling and squaring a Taylor series (18 terms at a norm of at most 1/2:
    to rounding); scipy's expm costs milliseconds per call on these 3-by-3 to 5-by-5 matrices."""
    norm = float(np.max(np.sum(np.abs(M), axis=1)))
    k = max(0, int(math.ceil(math.log2(norm / 0.5)))) if norm > 0.5 else 0
    A = M / 2.0 ** k
    X = term = np.eye(M.shape[0])
    for j in range(1, 19):
        term = term @ A / j
        X = X + term
    for _ in range(k):
        X = X @ X
    return X


def _steps(path: HeatPath, widths):
    """{width: (E, G)} for each distinct bin width: x+ = E x + G [P, T_amb] over a bin with P and T_amb held."""
    A, B = path.system()
    n = A.shape[0]
    out = {}
    for h in np.unique(widths):
        M = np.zeros((n + 2, n + 2))
        M[:n, :n], M[:n, n:] = A, B
        X = _expm(M * h)
        out[float(h)] = (X[:n, :n].tolist(), X[:n, n:].tolist())
    return out


def integrate(path: HeatPath, rec: WarmRecord, power, grid, basis, x0) -> np.ndarray:
    """The states at the bins' edges (edges x states) from ``x0``, with ``power`` (bins x grid nodes) the bins'
    mean friction power at each grid temperature, interpolated at the contact's temperature in each bin's middle
    (extrapolated from the bin before: second order, one pass; the power depends weakly on the temperature)."""
    coef = np.einsum("kij,bj->bik", basis, power).tolist()  # per bin and interval: the cubic's coefficients
    g = [float(v) for v in grid]
    widths = np.round(np.diff(rec.edges), 12)
    steps = _steps(path, widths)
    uniform = len(steps) == 1
    E, G = next(iter(steps.values()))
    n = path.states
    rows = range(n)
    x = [float(v) for v in x0]
    out = [x]
    last = len(g) - 2
    ambient = rec.ambient.tolist()
    before = x[0]
    for b in range(len(coef)):
        if not uniform:
            E, G = steps[float(widths[b])]
        T = 1.5 * x[0] - 0.5 * before
        i = min(max(bisect.bisect_right(g, T) - 1, 0), last)
        c, d = coef[b][i], T - g[i]
        P = ((c[0] * d + c[1]) * d + c[2]) * d + c[3]
        P = P if P > 0.0 else 0.0
        Ta = ambient[b]
        before = x[0]
        x = [sum(map(operator.mul, E[r], x)) + G[r][0] * P + G[r][1] * Ta for r in rows]
        out.append(x)
    return np.array(out)


def bin_power(rec: WarmRecord, forces) -> np.ndarray:
    """The bins' mean friction power |F v| at each grid temperature (bins x nodes) from the forces (nodes x
    samples)."""
    p = np.abs(forces) * rec.speed
    counts = np.diff(np.append(rec.starts, rec.time.size))
    return (np.add.reduceat(p, rec.starts, axis=1) / counts).T


@dataclasses.dataclass
class Track:
    """One record simulated: the force at its samples, the contact's temperature there and the proxy's (None
    without one), the states at the bins' edges, and the state it ends in."""

    force: np.ndarray
    contact: np.ndarray
    proxy: np.ndarray | None
    states: np.ndarray

    @property
    def end(self) -> np.ndarray:
        return self.states[-1]


def track(path: HeatPath, rec: WarmRecord, forces, grid, basis, x0) -> Track:
    """The record simulated from the state ``x0`` with ``forces`` at the grid's temperatures (nodes x samples)."""
    states = integrate(path, rec, bin_power(rec, forces), grid, basis, x0)
    at = np.column_stack([np.interp(rec.time, rec.edges, states[:, k]) for k in range(states.shape[1])])
    W = weights_at(basis, grid, at[:, 0])
    force = np.einsum("ij,ji->i", W, forces)
    proxy = at[:, -1] if path.tau_p is not None else None
    return Track(force, at[:, 0], proxy, states)


def grid_for(low: float, high: float, nodes: int = GRID_NODES) -> np.ndarray:
    """The grid's temperatures: ``nodes`` from ``low`` to ``high`` [C], Chebyshev-spaced (denser at the ends,
    where a spline's error is largest)."""
    k = np.arange(nodes)
    return 0.5 * (low + high) - 0.5 * (high - low) * np.cos(np.pi * k / (nodes - 1))


def interpolation_error(model, rec: WarmRecord, grid, basis, forces) -> float:
    """The largest error [N or N m] of the interpolated force against the force computed directly, at the
    temperatures midway between the grid's nodes."""
    mids = 0.5 * (np.asarray(grid)[1:] + np.asarray(grid)[:-1])
    direct = forces_at(model, rec.waveform, rec.time, mids)
    W = weights_at(basis, grid, mids)
    return float(np.max(np.abs(W @ forces - direct)))


__all__ = ["HeatPath", "WarmRecord", "Track", "warm_record", "bin_width_for", "first_bin_width", "forces_at",
           "spline_basis",
           "weights_at", "integrate", "bin_power", "track", "grid_for", "interpolation_error", "GRID_NODES"]
