"""The online contact-temperature estimator of the real-time C API (estimator.h), over recorded samples.

    est = tf.control.TemperatureEstimator(C_th=2.0, R_th=20.0, C_2=30.0, R_2=60.0, r_F=0.016)
    out = est.run(model, velocity, dt=1e-3, ambient=30.0, measured_force=F, start=35.0)
    out.temperature, out.variance, out.friction

An extended Kalman filter on the lumped heat path of the contact (one node, or a contact and a housing node),
driven by the friction model's own power and corrected by a measured friction force and, optionally, a lagging
proxy temperature (docs/control.md#temperature-estimator). ``run`` moves whole arrays through one call of the
binding: the same C steps a controller or the FMU takes, bit for bit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import _args, _bridge
from ._bridge import model_spec
from .errors import InputError, SolverError
from .figures.estimation_plots import estimate_figure
from .models import Model
from .models.load_laws import load_laws
from .results import Result, Summary

#: Which node the proxy temperature lags (estimator.h: tf_proxy_kind).
PROXY_KINDS = tuple(sorted(_bridge.PROXY_CODES, key=_bridge.PROXY_CODES.get))


@dataclass(frozen=True)
class TemperatureEstimator:
    """The estimator's heat path and noises (estimator.h: tf_temperature_config), SI units, temperatures in C.

    Parameters
    ----------
    C_th : float
        The contact node's heat capacity [J/K], > 0.
    R_th : float
        The thermal resistance from the contact to the next node (the housing, or ambient) [K/W], > 0.
    r_F : float
        The friction measurement's noise variance [N^2], > 0 (with correlated noise of correlation time tau
        sampled at dt, about its variance times 2 tau / dt).
    eta : float, default 1.0
        The fraction of the friction power that heats the contact, 0 to 1.
    C_2 : float, default 0.0
        The housing node's heat capacity [J/K]; 0: one node, R_th straight to ambient.
    R_2 : float, default 0.0
        The housing's resistance to ambient [K/W], > 0 with a housing node.
    proxy : str, default "none"
        The node a proxy sensor lags: "none", "contact" or "housing".
    tau_p : float, default 0.0
        The proxy's lag [s], > 0 with a proxy.
    r_p : float, default 0.01
        The proxy's noise variance [K^2], > 0 with a proxy.
    q_contact, q_housing, q_proxy : float, default 1e-3, 1e-4, 0.0
        The process noise of each state [K^2/s], >= 0: what the heat path leaves out (its parameters' errors,
        unmodelled heat).
    v_min : float, default 0.0
        No friction update where |v| < v_min [m/s] (sticking and reversals, where the measured force is not the
        temperature-dependent sliding friction).

    Raises
    ------
    InputError
        A value of the wrong type or out of its domain, named.
    """

    C_th: float
    R_th: float
    r_F: float
    eta: float = 1.0
    C_2: float = 0.0
    R_2: float = 0.0
    proxy: str = "none"
    tau_p: float = 0.0
    r_p: float = 0.01
    q_contact: float = 1e-3
    q_housing: float = 1e-4
    q_proxy: float = 0.0
    v_min: float = 0.0

    def __post_init__(self):
        w = "TemperatureEstimator"
        for name in ("C_th", "R_th", "r_F"):
            _args.number(getattr(self, name), f"{w}: {name}", positive=True)
        for name in ("eta", "C_2", "R_2", "tau_p", "r_p", "q_contact", "q_housing", "q_proxy", "v_min"):
            _args.number(getattr(self, name), f"{w}: {name}", minimum=0.0)
        if self.eta > 1.0:
            raise InputError(f"{w}: eta must be 0 to 1, got {self.eta!r}")
        if self.proxy not in PROXY_KINDS:
            raise InputError(f"{w}: proxy must be one of {', '.join(PROXY_KINDS)}, got {self.proxy!r}")
        if self.C_2 > 0 and not self.R_2 > 0:
            raise InputError(f"{w}: R_2 must be > 0 with a housing node (C_2 > 0), got {self.R_2!r}")
        if self.proxy == "housing" and not self.C_2 > 0:
            raise InputError(f"{w}: proxy 'housing' needs a housing node (C_2 > 0)")
        if self.proxy != "none":
            for name in ("tau_p", "r_p"):
                _args.number(getattr(self, name), f"{w}: {name} (with a proxy)", positive=True)

    @classmethod
    def from_fit(cls, result, *, r_F: float | None = None, r_p: float | None = None, v_min: float = 0.0,
                 q_contact: float = 1e-3, q_housing: float = 1e-4, q_proxy: float = 0.0) -> TemperatureEstimator:
        """The estimator of a warm-up fit's heat path (``identify(..., method="warm-up")``,
        docs/self-heating.md#warm-up-without-a-contact-temperature): its nodes, ``C_th``, ``R_th`` (``C_2``,
        ``R_2``), the proxy's node and lag, per unit of eta (eta 1, as the fit holds it), and its noises; run it with
        the fit's model (``result.model``).

        Parameters
        ----------
        result : FitResult
            A warm-up fit whose temperature scale is determined (soak runs or a proxy).
        r_F : float, optional
            The force's noise variance [N^2]; default the fit's: its force residuals' RMS squared times their
            autocorrelation's variance inflation (``statistics["variance_inflation"]``).
        r_p : float, optional
            The proxy's noise variance [K^2]; default the fit's largest proxy residual RMS squared (with a proxy).
        v_min : float, default 0.0
            No friction update where |v| < v_min [m/s or rad/s].
        q_contact, q_housing, q_proxy : float, default 1e-3, 1e-4, 0.0
            The process noise of each state [K^2/s].

        Returns
        -------
        TemperatureEstimator
            The heat path and noises of the fit.

        Raises
        ------
        InputError
            ``result`` is not a warm-up fit, or its temperature scale is undetermined (no heat path as numbers).
        """
        w = "TemperatureEstimator.from_fit"
        heat = (getattr(result, "details", None) or {}).get("heat_path")
        if getattr(result, "method", None) != "warm-up" or not isinstance(heat, dict):
            raise InputError(f"{w}: result must be a warm-up fit (method 'warm-up'), got "
                             f"{getattr(result, 'method', type(result).__name__)!r}")
        if heat["scale"] == "undetermined":
            raise InputError(f"{w}: the fit's temperature scale is undetermined (no soak runs at two temperatures or "
                             f"more, no proxy): its heat path's resistances and capacities are not numbers")
        p = result.parameters
        two = heat["nodes"] == 2
        proxy = heat.get("proxy")
        if r_F is None:
            r_F = result.rmse ** 2 * float(result.statistics.get("variance_inflation", 1.0))
        if r_p is None and proxy:
            r_p = max([row.get("proxy_rmse", 0.0) for row in result.experiments] + [1e-6]) ** 2
        return cls(C_th=float(p["C_th"].value), R_th=float(p["R_th"].value), r_F=float(r_F), eta=1.0,
                   C_2=float(p["C_2"].value) if two else 0.0, R_2=float(p["R_2"].value) if two else 0.0,
                   proxy=proxy["node"] if proxy else "none", tau_p=float(proxy["tau_p"]) if proxy else 0.0,
                   r_p=float(r_p) if proxy else 0.01, q_contact=q_contact, q_housing=q_housing, q_proxy=q_proxy,
                   v_min=v_min)

    def config(self) -> tuple:
        """The binding's tuple of tf_temperature_config (its fields in order)."""
        return (self.C_th, self.R_th, self.eta, self.C_2, self.R_2, _bridge.PROXY_CODES[self.proxy], self.tau_p,
                self.q_contact, self.q_housing, self.q_proxy, self.r_F, self.r_p, self.v_min)

    def run(self, model: Model, velocity, *, dt: float, ambient, start: float, start_variance: float = 25.0,
            measured_force=None, proxy_temperature=None, load=None) -> TemperatureEstimate:
        """The estimator over n samples: sample i holds ``velocity[i]`` over [i dt, (i+1) dt); its measurements
        are taken at the end, where the estimate applies. ``model``'s friction starts at rest.

        Parameters
        ----------
        model : Model
            The friction model (with its thermal extension: without one the force carries no temperature and
            only the heat path and the proxy inform the estimate).
        velocity : array_like
            The sliding velocity [m/s], one per sample.
        dt : float
            The sample period [s], > 0.
        ambient : float or array_like
            The ambient temperature [C], one value or one per sample.
        start : float
            The temperature every node starts at [C].
        start_variance : float, default 25.0
            Its variance [K^2], > 0.
        measured_force : array_like, optional
            The measured friction force [N], one per sample, NaN where none; None: no friction measurement.
        proxy_temperature : array_like, optional
            The proxy temperature [C], one per sample, NaN where none; only with a ``proxy``.
        load : float or array_like, optional
            The load [N or N m] (a normal force, or a joint's load torque), one value or one per sample (held over
            it, as the velocity), read by the model's laws of the load: required by a model with one, ignored by a
            model without (docs/models.md#laws-of-temperature-and-load).

        Returns
        -------
        TemperatureEstimate
            The contact temperature estimate, its variance and the friction estimate per sample.

        Raises
        ------
        InputError
            An argument of the wrong type or value, named; no ``load`` for a model with a law of the load; the
            model invalid at the estimate and the load (the step named).
        SolverError
            A step whose estimate or force overflows.
        """
        w = "TemperatureEstimator.run"
        model = _args.instance(model, Model, f"{w}: model", "a thermofriction Model")
        v = _series(w, "velocity", velocity, None)
        n = v.size
        L = _load(w, model, load, n)
        dt = _args.number(dt, f"{w}: dt", "s", positive=True)
        T_amb = np.full(n, _args.number(ambient, f"{w}: ambient", "C")) if np.ndim(ambient) == 0 else \
            _series(w, "ambient", ambient, n)
        T0 = _args.number(start, f"{w}: start", "C")
        var0 = _args.number(start_variance, f"{w}: start_variance", "K^2", positive=True)
        F_m = np.full(n, math.nan) if measured_force is None else \
            _series(w, "measured_force", measured_force, n, nan=True)
        if proxy_temperature is not None and self.proxy == "none":
            raise InputError(f"{w}: proxy_temperature given, but the estimator has no proxy (proxy='none')")
        T_p = None if proxy_temperature is None else _series(w, "proxy_temperature", proxy_temperature, n, nan=True)
        outs = [np.empty(n) for _ in range(3)]
        try:
            seconds = _bridge.temperature_estimate(model_spec(model, T0), self.config(), T0, var0, v, F_m, T_p, T_amb,
                                                   dt, *outs, load=L)
        except FloatingPointError as e:
            raise SolverError(f"{w}: {e}") from None
        except ValueError as e:
            raise InputError(f"{w}: {e}") from None
        return TemperatureEstimate(dt * np.arange(1, n + 1), outs[0], outs[1], outs[2],
                                   {"seconds": seconds, "ns_per_step": 1e9 * seconds / max(n, 1)})


def _load(where: str, model: Model, load, n: int) -> np.ndarray | None:
    """The load per sample for a model with a law of the load (required, finite), or None (the core's NaN: a model
    without one ignores it, so its results do not depend on ``load``)."""
    laws = load_laws(model)
    if not laws:
        return None
    if load is None:
        raise InputError(f"{where}: the model has a law of the load ({', '.join(laws)}): give load= (a number or "
                         f"one per sample [N or N m])")
    if np.ndim(load) == 0:
        return np.full(n, _args.number(load, f"{where}: load", "N or N m"))
    return _series(where, "load", load, n)


def _series(where: str, name: str, values, n, *, nan: bool = False) -> np.ndarray:
    """A 1-D float64 array (n values when n is given), every value finite (NaN allowed with ``nan``)."""
    try:
        a = np.ascontiguousarray(values, float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{where}: {name} must be an array of numbers") from None
    if a.ndim != 1 or (n is not None and a.size != n) or a.size == 0:
        raise InputError(f"{where}: {name} must be one-dimensional with "
                         + (f"{n} values" if n else "one value or more")
                         + f", got shape {a.shape}")
    bad = np.flatnonzero(np.isinf(a) if nan else ~np.isfinite(a))
    if bad.size:
        raise InputError(f"{where}: {name}[{bad[0]}] is {float(a[bad[0]])!r}: every value must be finite"
                         + (" (NaN: not measured)" if nan else ""))
    return a


@dataclass(eq=False)
class TemperatureEstimate(Result):
    """An estimator run, per sample (plain arrays, SI, temperatures in C).

    Parameters
    ----------
    time : numpy.ndarray
        The end of each sample [s], where its estimate applies.
    temperature : numpy.ndarray
        The contact temperature estimate [C].
    variance : numpy.ndarray
        Its variance [K^2].
    friction : numpy.ndarray
        The friction estimate [N] (the model at the corrected estimate: what a compensation uses).
    stats : dict, default {}
        The run's costs: ``seconds`` in C, ``ns_per_step``.
    """

    time: np.ndarray
    temperature: np.ndarray
    variance: np.ndarray
    friction: np.ndarray
    stats: dict = field(default_factory=dict)

    title = "temperature estimate"

    @property
    def sigma(self) -> np.ndarray:
        return np.sqrt(self.variance)

    def summary(self) -> Summary:
        return Summary([("duration", f"{self.time[-1]:.6g} s"), ("samples", f"{len(self.time)}"),
                        ("final estimate", f"{self.temperature[-1]:.4g} C +- {2 * self.sigma[-1]:.2g} K (2 sigma)"),
                        ("cost", f"{self.stats.get('ns_per_step', math.nan):.3g} ns per step")])

    def _frame(self) -> dict:
        return {"time": self.time, "temperature": self.temperature, "variance": self.variance,
                "friction": self.friction}

    def to_dict(self) -> dict:
        return {"summary": dict(self.summary()), "stats": self.stats, "samples": self._frame()}

    def plot(self):
        """A matplotlib figure: the estimate with its 2-sigma band, and the friction estimate, against time."""
        return estimate_figure(self)


__all__ = ["PROXY_KINDS", "TemperatureEstimator", "TemperatureEstimate"]
