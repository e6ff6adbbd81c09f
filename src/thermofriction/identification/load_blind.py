"""A load-blind model told it is load-blind (docs/force-data.md#loads): where the runs span loads and the model has
no law of load, the law is tried before anything is said -- an affine load term (``combine = "sum"``, k from 0)
added to each level parameter (fc, fs and their _neg sides; a number becomes a constant law), both models fitted
jointly on the fit runs (identification/load_fit.py), their residuals compared by an F-test whose degrees of freedom
are divided by the residuals' integrated autocorrelation time (correlated noise has fewer independent samples than
rows), and the gain measured on the held-out runs (on the fit runs where none is held out, and said so).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .._lazy import lazy
from ..errors import ThermofrictionError
from ..results import Finding
from ..models import Const, Model, ModelI
from ..models.load_laws import LoadLaw, LoadTerm, load_laws
from .load_fit import BLIND_ALPHA, LEVELS, LoadFit, fit_load_laws, held_out_rmse

stats = lazy("scipy.stats")


class LoadBlindWarning(UserWarning):
    """The runs span loads and the model, without a law of load, is load-blind (its errors follow the load)."""


@dataclass
class LoadBlindness:
    """What the load-blind check found.

    Parameters
    ----------
    loads : tuple of float
        The lowest and highest run load.
    blind, loaded : LoadFit
        The fits without and with the load terms.
    p_value : float
        The F-test's (correlation-corrected) probability of the improvement with no dependence on load.
    rmse_blind, rmse_loaded : float
        The RMS over the scored runs of each model's per-run RMSE [N or N m].
    scored_on : str
        "held-out runs" or "fit runs (none held out)".
    """

    loads: tuple
    blind: LoadFit
    loaded: LoadFit
    p_value: float
    rmse_blind: float
    rmse_loaded: float
    scored_on: str

    @property
    def gain(self) -> float:
        """rmse_blind / rmse_loaded."""
        return self.rmse_blind / self.rmse_loaded if self.rmse_loaded > 0 else float("inf")

    @property
    def load_blind(self) -> bool:
        """Whether the data show a dependence on the load the model lacks (significant and a gain above 1)."""
        return self.p_value < BLIND_ALPHA and self.gain > 1.0

    @property
    def p_text(self) -> str:
        return "p < 1e-16" if self.p_value < 1e-16 else f"p = {self.p_value:.2g}"

    def message(self) -> str:
        """The sentence the check says."""
        span = f"the runs span loads {self.loads[0]:.4g} to {self.loads[1]:.4g}"
        if not self.load_blind:
            return (f"{span}; the model has no law of load and needs none here: an affine load term on the level "
                    f"parameters, fitted, changed the RMSE on the {self.scored_on} from {self.rmse_blind:.4g} to "
                    f"{self.rmse_loaded:.4g} ({self.p_text})")
        return (f"the model is load-blind: {span} and its errors follow the load (F-test corrected for the noise's "
                f"correlation: {self.p_text}); an affine load term on {', '.join(self.terms)}, fitted, cut "
                f"the RMSE on the {self.scored_on} from {self.rmse_blind:.4g} to {self.rmse_loaded:.4g} "
                f"({self.gain:.3g}x): add a load law ([thermal] fc = {{ ..., load = {{ law = \"affine\", ... }} }})")

    @property
    def terms(self) -> list:
        return [n for n, law in self.loaded.model.laws.items() if isinstance(law, LoadLaw)]


def with_load_terms(model: Model) -> Model:
    """``model`` with an affine load term (k = 0, summed) on each level parameter it has; a number becomes a
    constant law.

    Parameters
    ----------
    model : Model
        A Model I (or temperature-independent) model without laws of load.

    Returns
    -------
    Model
    """
    laws, values = dict(model.laws), model.friction.values()
    for p in LEVELS:
        base = laws.get(p) or (Const(value=float(values[p])) if values.get(p) is not None else None)
        if base is not None:
            laws[p] = LoadLaw(base, LoadTerm("affine", k=0.0, combine="sum"))
    friction = dataclasses.replace(model.friction, **{p: None for p in laws if p not in model.laws})
    return dataclasses.replace(model, thermal=ModelI(laws), friction=friction)


def check_load_blind(model: Model, experiments, free=(), offset: str = "per-experiment") -> LoadBlindness | None:
    """Tries a law of load on a model without one where the runs span loads (module docstring); None where the
    check does not apply (a law of load already, fewer than two distinct loads).

    Parameters
    ----------
    model : Model
        A prescribed-motion model without laws of load (Model I or none), its values the start.
    experiments : Dataset or list of ForceExperiment
        The runs: those with role "fit" fitted, the others scored.
    free : sequence of str, default ()
        Friction parameters fitted with the laws (``fit_load_laws``).
    offset : str, default "per-experiment"
        The offset policy (``fit_load_laws``).

    Returns
    -------
    LoadBlindness or None

    Raises
    ------
    InputError
        As ``fit_load_laws``: a model or run the joint fit cannot take, named.
    ComputationError
        A fit that could not be computed.
    """
    exps = list(getattr(experiments, "experiments", experiments))
    loads = sorted({float(e.load) for e in exps if getattr(e, "load", None) is not None})
    if load_laws(model) or len(loads) < 2:
        return None
    fits = [e for e in exps if getattr(e, "role", "fit") == "fit"]
    held = [e for e in exps if getattr(e, "role", "fit") != "fit"]
    blind = fit_load_laws(model, fits, free, offset)
    loaded = fit_load_laws(with_load_terms(model), fits, free, offset)
    rss_b = sum(r ** 2 * len(e.time) for e, r in zip(fits, blind.rmse.values()))
    rss_l = sum(r ** 2 * len(e.time) for e, r in zip(fits, loaded.rmse.values()))
    q = len(loaded.names) - len(blind.names)
    rows = sum(len(e.time) for e in fits) - len(loaded.names)
    tau = max(loaded.correlation_time, 1.0)  # the noise's projections carry tau times a white noise's variance
    F = (rss_b - rss_l) / q / (tau * rss_l / rows)
    p = float(stats.f.sf(max(F, 0.0), q, max(rows / tau, 1.0)))
    scored = held or fits

    def rms(m):
        return float(np.sqrt(np.mean(np.square(list(held_out_rmse(m, scored).values())))))
    return LoadBlindness((loads[0], loads[-1]), blind, loaded, p, rms(blind.model), rms(loaded.model),
                         "held-out runs" if held else "fit runs (none held out)")


def load_findings(model: Model, experiments) -> list:
    """What validation says of the load: where force runs span loads and the model has no law of load, the
    load-blind check's sentence (a LoadBlindWarning where the model is load-blind, else a note of the same
    category saying it was tested), or why it could not be tested; nothing otherwise.

    Parameters
    ----------
    model : Model
        The model validated.
    experiments : list
        The runs validated.

    Returns
    -------
    list of Finding
    """
    exps = [e for e in experiments if getattr(e, "load", None) is not None]
    if load_laws(model) or len({float(e.load) for e in exps}) < 2 or not any(e.role == "fit" for e in exps):
        return []
    try:
        found = check_load_blind(model, experiments)
    except ThermofrictionError as e:
        return [Finding(LoadBlindWarning, f"the runs span loads but the model has no law of load, and adding one "
                                          f"could not be tried: {e}")]
    return [] if found is None else [Finding(LoadBlindWarning, found.message())]
