"""What every measured quantity provides (docs/architecture.md#measurements).

A measurement is what an experiment recorded and how a model is held against it: the quantity and its unit,
how a run of the model becomes a trace and its residuals (and their Jacobian), which offset of the record is
removed, the parameters fitted by default, what to advise when a fit misses, and how a prediction is measured
when validating. ``identify``, ``validate`` and ``report`` ask the dataset's measurement once
(:func:`thermofriction.measurements.measurement_of`) and then only ask it."""

from __future__ import annotations

import math

import numpy as np

from ..fitting.problem import Trace


class MetricWarning(UserWarning):
    """A validation metric is undefined for this experiment (NaN), e.g. a percentage of a measured
    displacement that does not move."""


class Measurement:
    """The interface; :mod:`.displacement` and :mod:`.force` implement it.

    Attributes: ``name`` (the registry's key and the results' ``measurement``), ``quantity`` (in words),
    ``plants`` (the plant types whose models it is fitted with), ``fit_parameters`` (the default fitted
    parameters per friction model), ``offset`` (the offset policy, OFFSETS: ``"per-experiment"``, each
    run's own, a nuisance parameter estimated on every run; ``"shared"``, one fitted offset for all runs;
    ``"none"``, none fitted: the model's own is used)."""

    name = ""
    quantity = ""
    plants: tuple = ()
    fit_parameters: dict = {}
    offset = "per-experiment"
    methods: tuple = ()

    # -- identification --------------------------------------------------------------------------
    def make_trace(self, exp, model) -> Trace:
        """One experiment ready to fit."""
        raise NotImplementedError

    def residuals(self, problem, model, theta, jac):
        """(r, J) over all of ``problem``'s traces, offsets removed as :attr:`offset` says; (None, None)
        where a run failed."""
        raise NotImplementedError

    def per_trace(self, problem, model, theta):
        r, _ = self.residuals(problem, model, theta, False)
        if r is None:
            return [None] * len(problem.traces)
        edges = np.cumsum([0] + [tr.n_residuals for tr in problem.traces])
        return [r[a:b] for a, b in zip(edges[:-1], edges[1:])]

    def initial_model(self, init, method, data, experiments, **options):
        """The model a fit of ``experiments`` starts from: ``init`` (a Model, a preset's name, a model file, or
        None) made ready for this measurement and ``method``, with values read off the data where it gives none.
        ``options``: identify's ``friction``, ``free``, ``procedure`` and ``parameters`` (the fitted names)."""
        raise NotImplementedError

    def complete(self, res, experiments, init):
        """The result of a fit of ``experiments`` from ``init`` completed at its optimum: what this measurement
        estimates besides the fitted parameters (an offset, an inertia, a delay); by default the result as it is."""
        return res

    def offsets_in(self, traces) -> int:
        """Offsets fitted besides the parameters (the degrees of freedom they take)."""
        return {"per-experiment": len(traces), "shared": int(bool(traces)), "none": 0}[self.offset]

    def unit(self, experiments) -> str:
        raise NotImplementedError

    def checks(self, model, traces) -> list:
        """What to check when a fit is not adequate and no refit can try it (a unit, the sampling), only where it
        applies to these data; what can be tried (a held value freed) is tried after the fit (held.py, advice.py)."""
        return []

    # -- validation ------------------------------------------------------------------------------
    def predict(self, model, exp):
        """One experiment predicted by ``model``, with its metrics (a Prediction)."""
        raise NotImplementedError

    def spans(self, model, exp, rtol=1e-6):
        """(measured, predicted) of one experiment for the unit check (unit_scale.py), which uses only their
        spans: by default the prediction's."""
        p = self.predict(model, exp, rtol)
        return p.measured, p.predicted

    #: the validation table's columns: (header, metric key, format); headers may hold ``{unit}``
    columns: tuple = ()
    #: what the table's RMSE has had removed, for its footer and the JSON
    removed = ""

    #: what a validation's RMSE has had removed
    validation_removed = ""
    #: columns shown in another unit than the metric's SI one (metric key -> factor)
    column_scale: dict = {}
    #: the validation table's caption (terminal) and footer (HTML)
    caption = ""
    footer = ""

    def check_model(self, model, experiments):
        """Refuses a model that cannot predict these experiments at all (InputError)."""

    def validation_extras(self, model) -> dict:
        """What a validation's JSON adds for this measurement."""
        return {}

    def summary(self, predictions) -> dict:
        raise NotImplementedError

    @staticmethod
    def by_role(predictions):
        """(role, its predictions) for "fit" and "validate", where there are any: what summaries are taken over."""
        for role in ("fit", "validate"):
            ps = [p for p in predictions if p.role == role]
            if ps:
                yield role, ps


#: Relative step of the forward differences (a measurement without closed-form sensitivities, force data's
#: integrated runs), and the tolerance of the runs they difference: the solver's
#: error over the step (1e-9 / 1e-5) and the truncation error (~1e-5) make the Jacobian good to ~1e-4, ample
#: for Gauss-Newton steps and for the intervals (1e-10 costs half as much again for nothing visible).
FD_STEP = 1e-5
FD_RTOL = 1e-9

#: the offset policies, by the names the API, the command line (--offset) and the JSON use
OFFSETS = ("shared", "per-experiment", "none")


def reverses(trace) -> bool:
    """Whether the motion that drives ``trace`` (a prescribed position) changes direction."""
    s = np.sign(np.diff(np.asarray(getattr(trace.waveform, "value", ()), float)))
    s = s[s != 0]
    return bool(s.size > 1 and np.any(s[1:] != s[:-1]))


def thermal_check(model, traces) -> list:
    """A model without a thermal extension on runs that span temperatures: said, with what would compare (not
    tried: a Model I or II fit costs as much as this one)."""
    temps = [t.nominal_temperature for t in traces if math.isfinite(t.nominal_temperature)]
    if getattr(model, "thermal", None) is not None or not temps or max(temps) - min(temps) < 0.5:
        return []
    return [f"the experiments span {min(temps):.4g} to {max(temps):.4g} C and the model has no thermal extension "
            f"(not tried here: --method model-i or model-ii compares)"]


def amount(value: float, unit: str) -> str:
    """A residual or an RMSE in its unit: metres shown in nm, N and N m as they are.

    Parameters
    ----------
    value : float
        The value, in ``unit``.
    unit : str
        Its SI unit ("m", "N", "N m").

    Returns
    -------
    str
        E.g. ``"12.5 nm"``, ``"0.031 N"``.

    Raises
    ------
    TypeError
        A value that is not a number (nothing is checked).
    """
    return f"{value * 1e9:.4g} nm" if unit == "m" else f"{value:.4g} {unit}"


def center(r, S=None):
    """Residuals (and their Jacobian's columns) about their mean: an offset fitted by linear least squares,
    profiled out.

    Parameters
    ----------
    r : numpy.ndarray
        The residuals, in the data's unit.
    S : numpy.ndarray, optional
        Their Jacobian (residuals x parameters).

    Returns
    -------
    tuple
        (r, S) about their means (S None where not given).

    Raises
    ------
    None
        Nothing is checked.
    """
    r = r - r.mean()
    if S is not None:
        S = S - S.mean(axis=0)
    return r, S


def center_each(r, S, sizes):
    """Each run's residuals (and Jacobian rows) about their own mean: one offset per run, profiled out."""
    r = r.copy()
    S = None if S is None else S.copy()
    start = 0
    for n in sizes:
        r[start:start + n], seg = center(r[start:start + n], None if S is None else S[start:start + n])
        if S is not None:
            S[start:start + n] = seg
        start += n
    return r, S


__all__ = ["FD_STEP", "FD_RTOL", "center_each", "Measurement", "MetricWarning", "Trace", "OFFSETS", "amount", "center", "reverses", "thermal_check"]
