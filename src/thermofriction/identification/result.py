"""What a fit returns: the fitted model, parameters with errors and intervals, the fit's quality and
statistics, and the results JSON (docs/formats.md#results-json); its text report and notebook table are written
by identification/fit_text.py."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._io import dump_json, jsonable
from ..figures.fit_plots import fit_figure
from ..figures.load_plots import fit_laws_figure
from ..measurements import amount
from ..models import Model
from ..results import Result, Summary
from ..fitting.parameters import Parameters
from .fit_text import fit_blocks, fit_html_blocks, verdict


@dataclasses.dataclass
class FitResult(Result):
    """What ``identify`` returns: the fitted model, its parameters with errors and intervals, the fit's quality,
    a readable ``report()``, the results JSON (``to_json``, docs/formats.md#results-json) and an HTML table for
    notebooks.

    Parameters
    ----------
    method : str
        The identification method ("plant", "base", "model-i", "model-ii", "heat", "warm-up").
    model : Model
        The fitted model.
    parameters : Parameters
        The fitted and held parameters, each with its value, unit, standard error and 95 % interval.
    correlation : numpy.ndarray
        The correlation matrix of the fitted parameters (in ``parameters.varying``'s order).
    cost : float
        The sum of squared residuals [unit^2].
    rmse : float
        The residuals' root mean square [unit].
    n_points : int
        The number of residuals (samples fitted).
    nfev, njev : int
        Every evaluation of the residuals the fit made (its starts' screening, per-temperature, reference and joint
        fits, profiles, refits, the held values' tests and the ripple advice), and how many of them computed the
        Jacobian too.
    starts : int
        The multi-start's starting points.
    wall_time : float
        The fit's duration [s].
    success : bool
        Whether the solver converged.
    message : str
        The solver's message.
    experiments : list, default []
        Per experiment: its file, temperature, role and RMSE.
    warnings : list of str, default []
        What the reader should know (a parameter at a bound, a held value the data contradict, ...).
    statistics : dict, default {}
        The residuals' statistics (degrees of freedom, autocorrelation, ...).
    details : dict, default {}
        What the procedure chose and why (law kinds and their AICc, the per-temperature fits, ...).
    alternatives : dict, default {}
        Other results of the same call (Model II ``procedure="both"``: the paper's, under "paper").
    fit_quality : dict, optional
        The residuals against the noise estimated from the data (measurements/quality.py), the held values'
        tests and the verdict; None where not measured.
    measurement : str, default "displacement"
        The measured quantity ("displacement", "force", "command").
    unit : str, default "m"
        The SI unit of the residuals and the RMSE.
    removed : str, default "each experiment's constant offset"
        What the RMSE has had removed (the measurement's ``removed``).
    sensor_offset : dict, default {}
        Force data: the sensor's offset (value, stderr, ci95, unit, fitted); empty where there is none.
    identifiability : list, default []
        The groups of parameters the data determine only together (identification/identifiability.py).
    """

    method: str
    model: Model
    parameters: Parameters
    correlation: np.ndarray
    cost: float                 # sum of squared residuals [unit^2]
    rmse: float                 # [unit]
    n_points: int
    nfev: int
    njev: int
    starts: int
    wall_time: float            # [s]
    success: bool
    message: str
    experiments: list = dataclasses.field(default_factory=list)
    warnings: list = dataclasses.field(default_factory=list)
    statistics: dict = dataclasses.field(default_factory=dict)
    details: dict = dataclasses.field(default_factory=dict)
    alternatives: dict = dataclasses.field(default_factory=dict)
    #: residuals against the noise estimated from the data (measurements/quality.py); None where not measured
    fit_quality: dict | None = None
    #: the measured quantity (thermofriction.measurements) and the SI unit of the residuals and the RMSE
    measurement: str = "displacement"
    unit: str = "m"
    #: what the RMSE has had removed (measurements: ``removed``)
    removed: str = "each experiment's constant offset"
    #: force data: the sensor's offset (value, stderr, ci95, unit, fitted); empty where there is none
    sensor_offset: dict = dataclasses.field(default_factory=dict)
    #: the groups of parameters the data determine only together (identification/identifiability.py)
    identifiability: list = dataclasses.field(default_factory=list)

    @property
    def adequate(self) -> bool | None:
        """Whether the residuals are at the measurement noise (None where not measured, or where the noise cannot
        be estimated from the data: fit_quality["why"])."""
        return None if self.fit_quality is None or self.fit_quality["adequate"] is None else \
            bool(self.fit_quality["adequate"])

    @property
    def aicc(self) -> float:
        """Akaike's criterion, corrected for small samples, of the trajectory fit."""
        n, k = self.n_points, len(self.parameters.varying)
        if n - k - 1 <= 0 or self.cost <= 0:
            return math.nan
        return n * math.log(self.cost / n) + 2 * k + 2 * k * (k + 1) / (n - k - 1)

    def law_interval(self, name: str, temperatures, level: float = 0.95):
        """The fitted law of ``name`` (a Model I parameter, or ``"dF"``) at ``temperatures`` with its
        ``level`` interval, by the delta method on the covariance of every fitted coefficient and
        breakpoint of that law (for an exponential law in the log of its value, where the law is linear in its
        coefficients). Returns (value, lower, upper) arrays."""
        from scipy import stats

        from ..fitting.parameters import with_values
        T = np.atleast_1d(np.asarray(temperatures, float))
        law_of = (lambda m: m.thermal.dF) if name == "dF" else (lambda m: m.laws[name])
        value = np.asarray(law_of(self.model)(T), float)
        names = [p.name for p in self.parameters.varying]
        own = [i for i, n in enumerate(names) if n.startswith(name + ".")]
        considered = self.details.get("considered") or {}
        if not own and name in considered.get("parameters", ()):  # held for lack of information: its stated range
            return value, value / considered["prior_factor"], value * considered["prior_factor"]
        if not own:
            return value, value.copy(), value.copy()
        theta = np.array([self.parameters[names[i]].value for i in own])
        se = np.array([self.parameters[names[i]].stderr for i in own], float)
        if not np.all(np.isfinite(se)):
            return value, np.full_like(value, -math.inf), np.full_like(value, math.inf)
        cov = np.nan_to_num(self.correlation[np.ix_(own, own)] * np.outer(se, se))
        z = stats.norm.ppf(0.5 + level / 2)
        law = law_of(self.model)
        if law.kind == "exp" and len(own) == 2 and law.a > 0:
            # log(a exp(bT)) = log a + bT is linear in the coefficients: the delta method is exact there, with the
            # gradient (1/a, T) exact too, and the interval stays positive. In the law's own scale a poorly
            # determined law run towards zero took its interval with it (1e-9 wide around 1e-13 against a
            # truth of 14); and a finite difference in b, 1 % off, lost the cancellation between a and b's
            # correlated errors that sets the interval where the data determine the law
            grad = np.vstack([np.full_like(T, 1.0 / law.a) if names[i].endswith(".a") else T for i in own])
            sd_log = np.sqrt(np.maximum(np.einsum("it,ij,jt->t", grad, cov, grad), 0.0))
            with np.errstate(over="ignore"):
                spread = np.exp(z * sd_log)
            return value, value / spread, value * spread
        grad = np.empty((len(own), len(T)))
        for j in range(len(own)):
            h = 1e-6 * max(abs(theta[j]), se[j], 1e-12)
            up = with_values(self.model, {names[own[j]]: theta[j] + h})
            grad[j] = (np.asarray(law_of(up)(T), float) - value) / h
        sd = np.sqrt(np.maximum(np.einsum("it,ij,jt->t", grad, cov, grad), 0.0))
        return value, value - z * sd, value + z * sd

    def recovery(self, truth: Model, temperatures, level: float = 0.95) -> list:
        """For data made from a known ``truth`` (a study, the demo): each temperature-dependent
        parameter of the truth against the fit, with the fit's ``level`` interval, and whether it
        covers the truth. Model I laws compare directly; Model II's dF relative to the fit's
        reference temperature (its definition: dF = 0 there). Empty where the fit and the truth are
        not the same kind of model."""
        from ..models import ModelI, ModelII
        rows = []
        T = np.atleast_1d(np.asarray(temperatures, float))
        if isinstance(truth.thermal, ModelI) and isinstance(self.model.thermal, ModelI):
            pairs = [(name, truth.laws[name](T)) for name in truth.laws if name in self.model.laws]
        elif isinstance(truth.thermal, ModelII) and isinstance(self.model.thermal, ModelII):
            law = self.model.thermal.dF
            ref = float(law.T[int(np.argmin(np.abs(law.values)))]) if law.kind == "pwl" else float(T.min())
            pairs = [("dF", truth.thermal.dF(T) - truth.thermal.dF(ref))]
        else:
            return rows
        for name, true in pairs:
            value, lo, hi = self.law_interval(name, T, level)
            for k, t in enumerate(T):
                rows.append({"parameter": name, "temperature": float(t), "truth": float(true[k]),
                             "value": float(value[k]), "lower": float(lo[k]), "upper": float(hi[k]),
                             "covered": bool(lo[k] <= true[k] <= hi[k])})
        return rows

    def to_dict(self) -> dict:
        names = [p.name for p in self.parameters.varying]
        d = {
            "method": self.method,
            "success": self.success,
            "message": self.message,
            "parameters": self.parameters.to_dict(),
            "correlation": {"names": names, "matrix": self.correlation},
            "cost": self.cost,
            "rmse_offset_removed": self.rmse,
            "offset_removed": self.removed,
            "measurement": self.measurement,
            "unit": self.unit,
            "fit_quality": self.fit_quality,
            "aicc": self.aicc,
            "n_points": self.n_points,
            "iterations": self.nfev,
            "jacobian_evaluations": self.njev,
            "starts": self.starts,
            "wall_time": self.wall_time,
            "experiments": self.experiments,
            "warnings": self.warnings,
            "identifiability": self.identifiability,
            "statistics": self.statistics,
            "details": self.details,
            "model": self.model.to_dict(),
        }
        if self.sensor_offset:
            d["sensor_offset"] = self.sensor_offset
            d["rmse"] = self.rmse  # the name force results gave this metric before (docs/formats.md)
        if self.model.provenance:
            d["provenance"] = self.model.provenance
        if self.alternatives:
            d["alternatives"] = {k: v.to_dict() for k, v in self.alternatives.items()}
        return jsonable(d)

    def with_command(self, command: str) -> "FitResult":
        """This result with the command line that made it in the fitted models' provenance."""
        def add(fit):
            if not fit.model.provenance:
                return fit
            model = dataclasses.replace(fit.model, provenance={**fit.model.provenance, "command": command})
            return dataclasses.replace(fit, model=model, alternatives={k: add(v) for k, v in fit.alternatives.items()})
        return add(self)

    def to_json(self, path=None) -> str:
        """The results as JSON (docs/formats.md#results-json), written atomically to ``path`` when given."""
        return dump_json(self.to_dict(), path)

    title = "fit"

    def summary(self) -> Summary:
        q = self.fit_quality or {}
        return Summary([("method", self.method), ("converged", str(self.success)),
                        ("rmse", amount(self.rmse, self.unit) if self.n_points else "-"),
                        ("adequate", "-" if not q else verdict(q)), ("evaluations", str(self.nfev))])

    def _frame(self) -> dict:
        """One row per parameter: value, standard error, 95 % interval, unit, fitted or held."""
        ps = list(self.parameters.values())
        return {"name": [p.name for p in ps], "value": [p.value for p in ps],
                "stderr": [p.stderr for p in ps], "ci95_low": [None if p.ci95 is None else p.ci95[0] for p in ps],
                "ci95_high": [None if p.ci95 is None else p.ci95[1] for p in ps], "unit": [p.unit for p in ps],
                "vary": [p.vary for p in ps]}

    def to_mat(self, path):
        """The same results as a MATLAB file (docs/formats.md#results-in-matlab-files)."""
        from ..data.matlab_results import save_results_mat
        save_results_mat(self.to_dict(), path)

    def _blocks(self) -> list:
        """The report like lmfit's fit report (identification/fit_text.py writes it)."""
        return fit_blocks(self)

    def plot(self, data=None, paper=False):
        """A matplotlib figure of the fit: with ``data`` (the dataset, or a ValidationResult of
        this model on it) measured against predicted displacement and the residuals' RMS; for Model
        I and II the laws with the per-temperature estimates and their 95 % intervals (``paper``:
        the paper's Eqs. (9)-(11) and (13) beside them). A fit of laws of temperature and load: the laws over
        the load at each fit temperature with their 95 % bands and the per-condition estimates."""
        if self.details.get("load"):  # laws of temperature and load: over the load (figures/load_plots.py)
            return fit_laws_figure(self)
        validation = data
        if data is not None and not hasattr(data, "predictions"):
            from ..validation import validate
            validation = validate(self.model, data)
        return fit_figure(self, validation, paper=paper)

    def _html_blocks(self) -> list:
        """The notebook's table: the headline, the parameters, the warnings (identification/fit_text.py)."""
        return fit_html_blocks(self)
