"""Validation (docs/formats.md#validation-metrics): how well a model predicts measured displacements, per experiment."""

from __future__ import annotations

import dataclasses
import html
import math
import warnings

import numpy as np

from ._io import dump_json, jsonable
from .errors import InputError, TemperatureRangeWarning, ThermofrictionError
from . import _args
from .data.experiments import Dataset
from .drive import drive
from .identify.quality import fit_quality
from .models import Model, require_actuator
from .simulate import StepSizeController, simulate


class MetricWarning(UserWarning):
    """A validation metric is undefined for this experiment (NaN), e.g. a percentage of a measured
    displacement that does not move."""


def _zero(measured, predicted):
    """The measurement's zero (a sensor's zero is arbitrary): the offset that makes the first 1 % of
    the run agree with the prediction on average -- exact for a perfect model, robust to noise,
    and blind to the rest of the run, so it cannot hide errors that build up."""
    k = max(len(measured) // 100, 1)
    return float(np.mean(measured[:k] - predicted[:k]))


def step_sizes(time, x, period):
    """Displacement over each whole period, read off by linear interpolation at k * period."""
    if period is None:
        return np.empty(0)
    k0 = math.ceil(time[0] / period - 1e-9)
    k1 = math.floor(time[-1] / period + 1e-9)
    if k1 - k0 < 1:
        return np.empty(0)
    return np.diff(np.interp(np.arange(k0, k1 + 1) * period, time, x))


@dataclasses.dataclass
class Prediction:
    """One experiment: the measurement, the model's prediction and its metrics (docs/formats.md#validation-metrics)."""

    file: str
    temperature: float
    role: str
    time: np.ndarray
    measured: np.ndarray
    predicted: np.ndarray
    max_error_pct: float
    rmse: float                 # the mean offset removed: the same definition as identification's
    nrmse: float
    final_error_pct: float
    step_error_pct: float
    step_error: float
    measured_steps: np.ndarray
    predicted_steps: np.ndarray
    fit_quality: dict | None = None

    def metrics(self) -> dict:
        return {"file": self.file, "temperature": self.temperature, "role": self.role,
                "max_error_pct": self.max_error_pct, "rmse_offset_removed": self.rmse, "nrmse": self.nrmse,
                "final_error_pct": self.final_error_pct, "step_error_pct": self.step_error_pct,
                "step_error": self.step_error, "fit_quality": self.fit_quality}


@dataclasses.dataclass
class Failure:
    """An experiment the model could not be run on, and why."""

    file: str
    temperature: float
    role: str
    reason: str

    def metrics(self) -> dict:
        return {"file": self.file, "temperature": self.temperature, "role": self.role, "failed": self.reason}


def predict(model: Model, exp, rtol=1e-8) -> Prediction:
    """Simulates one experiment (at rtol 1e-8: predictions should carry no solver error worth
    mentioning next to a measurement's) and computes its metrics."""
    d = drive(exp, model, start="model")  # a self-heating model from its own T_0, else the record's start
    waveform = d.waveform
    res = simulate(d.model(model), t_eval=exp.time, temperature=d.temperature, input=waveform,
                   controller=StepSizeController(rtol=rtol))
    pred = res.displacement - res.displacement[0]
    meas = np.asarray(exp.displacement, float)
    meas = meas - _zero(meas, pred)
    err = pred - meas
    span = float(np.max(meas) - np.min(meas))
    # RMSE as identification measures it: about the mean offset (the sensor's zero is arbitrary)
    quality = fit_quality(err - err.mean(), meas)
    rmse = quality["rmse"]
    net = float(meas[-1] - meas[0])
    ms = step_sizes(exp.time, meas, waveform.period)
    ps = step_sizes(exp.time, pred, waveform.period)
    step_err = float(np.mean(np.abs(ps - ms))) if ms.size else math.nan
    mean_step = abs(float(np.mean(ms))) if ms.size else math.nan

    # a percentage of nothing is not a number: a measurement that does not move (a constant
    # displacement, a sensor that was off) has no span; dividing by a stand-in such as 1e-300
    # gave 1e297 % with no word of why
    def pct(value, scale, what):
        if scale > 0:
            return 100 * value / scale
        warnings.warn(f"{exp.file}: the measured {what} is zero: percentage errors relative to it are "
                      f"undefined (NaN)", MetricWarning, stacklevel=3)
        return math.nan

    max_pct = pct(float(np.max(np.abs(err))), span, "displacement's span (it is constant)")
    return Prediction(exp.file, float(exp.temperature), getattr(exp, "role", "fit"), np.asarray(exp.time), meas, pred,
                      max_pct, rmse, rmse / span if span > 0 else math.nan,
                      pct(float(err[-1]), abs(net), "net displacement (it ends where it starts)") if span > 0 else math.nan,
                      pct(step_err, mean_step, "mean step per cycle") if ms.size and span > 0 else math.nan, step_err, ms, ps, quality)


@dataclasses.dataclass
class ValidationResult:
    model: Model
    predictions: list
    warnings: list
    #: experiments the model could not be run on (Failure: file, reason); the others are still computed
    failures: list = dataclasses.field(default_factory=list)

    @property
    def experiments(self):
        return [p.metrics() for p in self.predictions]

    @property
    def complete(self) -> bool:
        """Every experiment was predicted."""
        return not self.failures

    def summary(self) -> dict:
        out = {}
        for role in ("fit", "validate"):
            ps = [p for p in self.predictions if p.role == role]
            if ps:
                # an undefined (NaN) percentage, warned about, does not hide the others
                pcts = [p.max_error_pct for p in ps if not math.isnan(p.max_error_pct)]
                out[role] = {"max_error_pct": max(pcts) if pcts else math.nan,
                             "mean_max_error_pct": float(np.mean(pcts)) if pcts else math.nan,
                             "rmse_offset_removed": float(np.sqrt(np.mean([p.rmse ** 2 for p in ps]))),
                             "n": len(ps)}
        return out

    def to_dict(self) -> dict:
        return jsonable({"model": self.model.name, "experiments": self.experiments, "summary": self.summary(),
                         "failed": [f.metrics() for f in self.failures], "warnings": self.warnings})

    def to_json(self, path=None) -> str:
        """The metrics (docs/formats.md#validation-metrics) as JSON, written atomically to ``path`` when given."""
        return dump_json(self.to_dict(), path)

    def to_mat(self, path):
        """The same metrics as a MATLAB file (docs/formats.md#results-in-matlab-files)."""
        from .data.matlab import save_results_mat
        save_results_mat(jsonable(self.to_dict()), path)

    _COLUMNS = (("file", "file", "{}"), ("T [C]", "temperature", "{:.4g}"), ("role", "role", "{}"),
                ("max error [%]", "max_error_pct", "{:.3g}"), ("RMSE [nm]", "rmse_offset_removed", "{:.4g}"),
                ("NRMSE", "nrmse", "{:.3g}"), ("final error [%]", "final_error_pct", "{:+.3g}"),
                ("step error [%]", "step_error_pct", "{:.3g}"))

    def rows(self):
        for m in self.experiments:
            yield [fmt.format(m[key] * 1e9 if key == "rmse_offset_removed" else m[key]) for _, key, fmt in self._COLUMNS]

    def table(self) -> str:
        head = [c[0] for c in self._COLUMNS]
        rows = list(self.rows())
        w = [max(len(r[i]) for r in rows + [head]) for i in range(len(head))]
        lines = ["  ".join(h.ljust(w[i]) for i, h in enumerate(head))]
        lines += ["  ".join(c.ljust(w[i]) for i, c in enumerate(r)) for r in rows]
        return "\n".join(lines)

    def print_table(self, title=None):
        """A rich table on the terminal."""
        from rich.console import Console
        from rich.markup import escape
        from rich.measure import Measurement
        from rich.table import Table
        # (escaped: rich would take "[nm]" in a header, or brackets in a file name, for markup)
        t = Table(title=escape(title or f"Validation of {self.model.name or 'the model'}"),
                  caption="RMSE: each experiment's constant offset removed; NRMSE = RMSE / measured span; "
                          "definitions: docs/formats.md#validation-metrics")
        for name, _, _ in self._COLUMNS:
            t.add_column(escape(name), justify="left" if name in ("file", "role") else "right", no_wrap=True)
        for r in self.rows():
            t.add_row(*map(escape, r))
        console = Console()
        # never cut a file name to fit 80 columns (a pipe, a CI log): the table as wide as it needs
        width = Measurement.get(console, console.options.update_width(10_000), t).maximum
        if width > console.width:
            console = Console(width=width)
        console.print(t)

    def plot(self, metric="max_error_pct", ax=None, label=None):
        """A matplotlib figure of ``metric`` (max_error_pct, final_error_pct, step_error_pct, nrmse,
        rmse) against temperature: fit temperatures filled, held-out ones open on pale red bands,
        and for the max error the 7-8 % of Li et al. (2009). Draws into ``ax`` when given."""
        from .report.plots import error_figure
        return error_figure([(label or self.model.name or "model", self)], metric, ax=ax)

    def _repr_html_(self):
        head = "".join(f"<th>{html.escape(c[0])}</th>" for c in self._COLUMNS)
        body = "".join("<tr>" + "".join(f"<td>{html.escape(c)}</td>" for c in r) + "</tr>" for r in self.rows())
        summary = "; ".join(f"{role}: max error {s['max_error_pct']:.3g} %, RMSE {s['rmse_offset_removed'] * 1e9:.4g} nm "
                            f"({s['n']} run{'s' if s['n'] != 1 else ''})" for role, s in self.summary().items())
        notes = "".join(f"<li>{html.escape(w)}</li>" for w in self.warnings)
        notes += "".join(f"<li>{html.escape(f.file)}: not predicted: {html.escape(f.reason)}</li>" for f in self.failures)
        return (f"<div><b>Validation of {html.escape(self.model.name or 'the model')}</b> — {html.escape(summary)}"
                f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"
                f"<small>RMSE: each experiment's constant offset removed; NRMSE = RMSE / measured span; max error: "
                f"100 max|error| / measured span; final error: of the net displacement; step error: mean per input "
                f"period (docs/formats.md#validation-metrics)</small>"
                + (f"<ul>{notes}</ul>" if notes else "") + "</div>")


def validate(model: Model, data, experiments=None) -> ValidationResult:
    """Predicts every experiment of ``data`` (or the given ones) with ``model`` and measures the
    errors (docs/formats.md#validation-metrics). Temperatures outside a law's calibrated range are reported as warnings."""
    _args.model(model, Model)
    _args.dataset(data, Dataset, experiments=True)
    _args.dataset(experiments, Dataset, "experiments", experiments=True, none=True)
    exps = list(experiments if experiments is not None else getattr(data, "experiments", data))
    if not exps:
        raise InputError("the dataset has no experiments")
    from .data.force import is_force_data
    if is_force_data(exps):  # measured force under measured motion: validate_force.py
        from .validate_force import validate_force
        return validate_force(model, exps)
    require_actuator(model, "validate")
    caught, preds, failures = [], [], []
    for exp in exps:
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always", TemperatureRangeWarning)
            warnings.simplefilter("always", MetricWarning)
            try:
                preds.append(predict(model, exp))
            except ThermofrictionError as e:  # one experiment the model cannot run: say why, go on
                failures.append(Failure(exp.file, float(exp.temperature), getattr(exp, "role", "fit"), str(e)))
        caught += [f"{exp.file}: {x.message}" for x in w if issubclass(x.category, TemperatureRangeWarning)]
        caught += [str(x.message) for x in w if issubclass(x.category, MetricWarning)]
    return ValidationResult(model, preds, caught, failures)


__all__ = ["MetricWarning", "validate", "ValidationResult", "Prediction", "Failure", "predict", "step_sizes"]
