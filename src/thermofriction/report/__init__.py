"""The HTML report: one self-contained file (figures inlined as SVG, no scripts) comparing models
on a dataset — the paper's Figs. 3-7, 9-10 and Eq. (13), residuals, error and comparison tables,
and a footer that lets anyone reproduce it."""

from __future__ import annotations

import dataclasses
import html
import math
import re
import sys

import numpy as np

from .._io import atomic_write
from ..errors import InputError
from .. import _args
from ..data.experiments import Dataset
from ..models import PARAMETER_UNITS, Model, ModelI, ModelII
from ..validate import ValidationResult, validate
from .figures import (definitions, fig_displacement, fig_errors, fig_model_i, fig_model_ii, fig_residuals,
                      fig_steps)
from .page import Figures, _fmt, _table, page_html
from .plots import _float
from .studies import control_report, heating_report

@dataclasses.dataclass
class Entry:
    """One model in the report, with its identification results when known (FitResult.to_dict())."""

    label: str
    model: Model
    fit: dict | None = None
    validation: ValidationResult | None = None


def entry_label(model: Model, fit: dict | None = None) -> str:
    if fit and fit.get("method"):
        m = fit["method"]
        return {"model-i": "Model I", "base": "no thermal model"}.get(m, m.replace("model-ii", "Model II"))
    if isinstance(model.thermal, ModelI):
        return "Model I"
    if isinstance(model.thermal, ModelII):
        return "Model II"
    return "no thermal model"



def akaike(entries):
    """AICc difference to the best and Akaike weight of each entry's fit, or None: only between fits
    of the same data (the same experiments and points), where AICc is comparable; the weights sum to
    one over such a group."""
    groups = {}
    for i, e in enumerate(entries):
        f = e.fit or {}
        a = f.get("aicc")
        if a is None or not math.isfinite(float(a)):
            continue
        key = (f.get("n_points"), tuple(sorted(str(x.get("file")) for x in f.get("experiments") or [])))
        groups.setdefault(key, []).append((i, float(a)))
    out = [None] * len(entries)
    for members in groups.values():
        best = min(a for _, a in members)
        w = {i: math.exp(-0.5 * (a - best)) for i, a in members}
        total = sum(w.values())
        for i, a in members:
            out[i] = (a - best, w[i] / total)
    return out, len(groups)


def _aicc_cells(a):
    """(ΔAICc, Akaike weight) as text: a difference with its sign and thousands, a weight too small to
    print as "< 0.001" rather than a misleading 0.000."""
    if not a:
        return "—", "—"
    d, w = a
    return (f"{d:+,.1f}" if d else "0 (best)"), ("< 0.001" if w < 1e-3 else f"{w:.3f}")


COMPARISON_COLUMNS = ["model", "friction", "max error, held out [%]", "mean max error, held out [%]",
                      "RMSE, held out [nm]", "max error, fit [%]", "ΔAICc", "Akaike weight", "identification time"]
EXPERIMENT_COLUMNS = ["model", "file", "T [°C]", "role", "max error [%]", "RMSE [nm]", "NRMSE", "final error [%]",
                      "step error [%]"]


def comparison_rows(entries):
    rows = []
    aic, _ = akaike(entries)
    for e, a in zip(entries, aic):
        s = e.validation.summary()
        v = s.get("validate", s.get("fit", {}))
        f = e.fit or {}
        rows.append([e.label, e.model.friction.model, _fmt(v.get("max_error_pct")), _fmt(v.get("mean_max_error_pct")),
                     _fmt(v.get("rmse_offset_removed", math.nan) * 1e9, "{:.4g}"), _fmt(s.get("fit", {}).get("max_error_pct")),
                     *_aicc_cells(a), _fmt(f.get("wall_time"), "{:.2f} s")])
    return rows


def _unit(u: str) -> str:
    """Temperatures in °C in units shown to a reader: "1/C" -> "1/°C", "N/C^2" -> "N/°C^2"."""
    return re.sub(r"/C(?![A-Za-z_])", "/°C", u or "")


def _covariance(fit: dict, names):
    """The covariance of fitted parameters ``names`` from a fit's standard errors and correlation
    (zero for a parameter held fixed); None when they are not known."""
    params = fit.get("parameters") or {}
    corr = fit.get("correlation") or {}
    idx = {n: i for i, n in enumerate(corr.get("names") or [])}
    matrix = np.asarray(corr.get("matrix") if corr.get("matrix") is not None else np.zeros((0, 0)), dtype=object)
    se = []
    for n in names:
        p = params.get(n)
        if p is None:
            return None
        x = _float(p.get("stderr"))  # None, "inf" (JSON), a number
        se.append(x if n in idx else 0.0)
    if not all(math.isfinite(x) for x in se):
        return None
    C = np.zeros((len(names), len(names)))
    for i, a in enumerate(names):
        for j, b in enumerate(names):
            if i == j:
                C[i, j] = se[i] ** 2
            elif a in idx and b in idx:
                r = float(matrix[idx[a]][idx[b]]) if matrix.size else math.nan
                C[i, j] = (r if math.isfinite(r) else 0.0) * se[i] * se[j]
    return C


def law_at(law, T, fit, name):
    """(value, standard error) of a parameter's law at T; the error by the delta method from the
    fit's covariance of the law's coefficients (None when unknown)."""
    value = float(law(T))
    names = [f"{name}.{c}" for c in law.coefficient_names()]
    C = _covariance(fit or {}, names) if names else None
    if C is None:
        return value, None
    c = np.array(law.coefficients(), float)
    grad = np.zeros(len(c))
    for i in range(len(c)):  # central differences: any law kind, evaluated by the core
        h = 1e-6 * max(abs(c[i]), 1e-12)
        up, dn = c.copy(), c.copy()
        up[i] += h
        dn[i] -= h
        grad[i] = (float(law.with_coefficients(up)(T)) - float(law.with_coefficients(dn)(T))) / (2 * h)
    return value, float(math.sqrt(max(grad @ C @ grad, 0.0)))


def reference_temperature(law, fallback):
    rng = getattr(law, "range", None)
    return float(round(0.5 * (rng[0] + rng[1]))) if rng else float(round(fallback))


def _equation(name, law, Tr, unit):
    T = f"{Tr:g} °C"
    if law.kind == "exp":
        return f"{name}(T) = {name}({T}) · exp(b · (T − {T})), b = {law.b:.4g} 1/°C"
    if law.kind == "linear":
        return f"{name}(T) = {name}({T}) + a · (T − {T}), a = {law.a:.4g} {_unit(unit + '/C')}"
    if law.kind == "const":
        return f"{name}(T) = {name} (no temperature dependence)"
    if law.kind == "poly":
        return f"{name}(T) = Σ c_i T^i (degree {len(law.c) - 1})"
    return f"{name}(T): {'linear' if law.kind == 'pwl' else 'monotone cubic'} between {len(law.T)} points"


def law_rows(entry, fallback_T):
    """Model I: each law's equation, its value at a reference temperature in the calibrated range
    (not the extrapolation to 0 °C that an exponential law's coefficient a is), its change per °C,
    its values at the range's ends, and whether it stays inside the per-temperature intervals."""
    from .plots import law_outside_intervals, per_temperature_estimates
    rows, outside = [], law_outside_intervals(entry.fit or {}, entry.model)
    for name, law in entry.model.laws.items():
        unit = PARAMETER_UNITS.get(name, "")
        Tr = reference_temperature(law, fallback_T)
        value, se = law_at(law, Tr, entry.fit, name)
        per_deg = 100 * float(law.slope(Tr)) / value if value else math.nan
        rng = getattr(law, "range", None)
        ends = (f"{_fmt(law(rng[0]), '{:.4g}')} at {rng[0]:g} °C, {_fmt(law(rng[1]), '{:.4g}')} at {rng[1]:g} °C"
                if rng else "—")
        T = per_temperature_estimates(entry.fit or {}, name)[0]
        inside = ("—" if not T.size else f"yes, all {T.size}" if name not in outside else
                  f"no: outside at {', '.join(f'{t:g}' for t in outside[name])} °C")
        rows.append([name, _equation(name, law, Tr, unit), f"{Tr:g}", _fmt(value, "{:.5g}"), _fmt(se, "{:.3g}"), unit,
                     _fmt(per_deg, "{:+.3g} %/°C"), ends, inside])
    return rows, outside


def breakpoint_rows(entry):
    """Model II: dF's breakpoints, each with its temperature, value, standard error and the friction
    factor there."""
    dF = entry.model.thermal.dF
    params = (entry.fit or {}).get("parameters") or {}
    varying = set(((entry.fit or {}).get("correlation") or {}).get("names") or [])
    rows = []
    if dF.kind not in ("pwl", "table"):
        return rows
    for i, (T, v) in enumerate(zip(dF.T, dF.values)):
        pname = f"dF.values[{i}]"
        p = params.get(pname) or {}
        fixed = bool(params) and pname not in varying
        lam = entry.model.thermal_factor(float(T)) if entry.model.thermal.form == "scale" else math.nan
        rows.append([f"{T:.2f}", _fmt(v, "{:.5g}"), "fixed" if fixed else _fmt(p.get("stderr"), "{:.3g}"),
                     _fmt(lam, "{:.4f}"), "reference temperature (dF = 0 by definition)" if fixed and v == 0 else ""])
    return rows


def _parameter_table(entry, keep):
    rows = []
    for name, p in ((entry.fit or {}).get("parameters") or {}).items():
        if not keep(name):
            continue
        ci = p.get("ci95") or ["", ""]
        rows.append([name, _fmt(p.get("value"), "{:.6g}"), _fmt(p.get("stderr"), "{:.3g}"),
                     f"[{_fmt(ci[0], '{:.5g}')}, {_fmt(ci[1], '{:.5g}')}]", _unit(p.get("unit", ""))])
    return rows


def parameter_section(entries, fit_T) -> str:
    """Per model: its fitted parameters; Model I's laws with their equations and values at a
    reference temperature; Model II's breakpoints; the raw coefficients as in the model file."""
    out = []
    for e in entries:
        parts = []
        plain = _parameter_table(e, lambda n: "." not in n and not n.startswith("dF"))
        if plain:
            parts.append(_table(["parameter", "value", "std. error", "95 % interval", "unit"], plain, text=(4,)))
        if e.model.laws:
            rows, outside = law_rows(e, fit_T)
            parts.append("<p class='note'>Temperature laws (Model I). Each is given at a reference temperature "
                         "in the middle of the range it was calibrated on; the standard error there follows from "
                         "the coefficients' covariance. An exponential law's coefficient <code>a</code> in the "
                         "model file is its value extrapolated to 0 °C, far outside the data.</p>" + _table(
                ["parameter", "law", "T_ref [°C]", "value at T_ref", "std. error", "unit", "change per °C",
                 "at the range's ends", "inside the per-temperature 95 % intervals"], rows, text=(5,), wrap=(1, 7, 8)))
            if outside:
                parts.append("<p class='note'>" + "; ".join(
                    f"The refined law of <b>{html.escape(n)}</b> lies outside the per-temperature 95 % interval at "
                    f"{', '.join(f'{t:g}' for t in T)} °C" for n, T in outside.items()) +
                    ". The refined law is fitted to all trajectories at once, while each per-temperature "
                    "estimate comes from one temperature's data and trades this parameter against the others "
                    "(their correlation): a law that misses intervals is the best compromise over all "
                    "temperatures, or a sign that its shape does not follow the data there. The held-out errors "
                    "say which.</p>")
        if isinstance(e.model.thermal, ModelII):
            rows = breakpoint_rows(e)
            if rows:
                parts.append("<p class='note'>Thermal-induced friction dF(T) (Model II), linear between its "
                             "breakpoints; the friction force is scaled by λ = 1 + dF/fc"
                             f" (fc = {_fmt(e.model.friction.values().get('fc'), '{:.4g}')} N).</p>" +
                             _table(["breakpoint T [°C]", "dF [N]", "std. error [N]", "λ", "note"], rows, wrap=(4,)))
        coef = _parameter_table(e, lambda n: "." in n or n.startswith("dF"))
        if coef:
            parts.append("<details><summary>the fitted coefficients as stored in the model file</summary>" +
                         _table(["coefficient", "value", "std. error", "95 % interval", "unit"], coef, text=(4,)) +
                         "</details>")
        if parts:
            out.append(f"<h3>{html.escape(e.label)}</h3>" + "".join(parts))
    return ("<section><h2>Identified parameters</h2>" + "".join(out) + "</section>") if out else ""


def render(entries, data, *, figures_dir=None, command=None, title=None, truth=None, bands=None) -> str:
    exps = list(getattr(data, "experiments", data))
    if not any(getattr(e, "role", "fit") == "validate" for e in exps):
        raise InputError("the dataset has no experiment with role 'validate': a report compares predictions at "
                         "temperatures the models were not identified on")
    for e in entries:
        if e.validation is None:
            e.validation = validate(e.model, data)
    figs = Figures(figures_dir)
    parts = []
    best = min(entries, key=lambda e: e.validation.summary().get("validate", {}).get("max_error_pct", math.inf))
    bs = best.validation.summary()["validate"]
    cards = [("best on held-out temperatures", best.label,
              f"max error {bs['max_error_pct']:.2g} % (the paper: 7–8 %)"),
             ("experiments", f"{len(exps)}", f"{sum(getattr(e, 'role', 'fit') == 'validate' for e in exps)} held out"),
             ("temperatures", f"{min(e.temperature for e in exps):.1f}–{max(e.temperature for e in exps):.1f} °C",
              "")]
    for e in entries:
        if e.fit and e.fit.get("wall_time") is not None:
            cards.append((f"identification, {e.label}", f"{float(e.fit['wall_time']):.2f} s",
                          "the paper: ~2 h per temperature" if e.label == "Model I" else ""))
    card_html = "".join(f'<div class="card"><div class="k">{html.escape(k)}</div><div class="v">{html.escape(v)}'
                        f'</div><div class="s">{html.escape(s)}</div></div>' for k, v, s in cards)
    parts.append(f'<div class="cards">{card_html}</div>')
    # never silently: a fit that misses the data, or did not converge, first, and in every report
    fit_warnings = {e.label: list((e.fit or {}).get("warnings", [])) for e in entries}
    warns = []
    for e in entries:
        if ((e.fit or {}).get("fit_quality") or {}).get("adequate") is False:
            first = [w for w in fit_warnings[e.label] if w.startswith("the fit is not adequate")]
            warns += [f"{e.label}: {w}" for w in first]
            fit_warnings[e.label] = [w for w in fit_warnings[e.label] if w not in first]
    warns += [f"{e.label}: the fit did not converge: {(e.fit or {}).get('message', '')}" for e in entries
              if (e.fit or {}).get("success") is False]
    warns += [f"{e.label}: {f.file} could not be predicted: {f.reason}" for e in entries for f in e.validation.failures]
    warns += [f"{e.label}: {w}" for e in entries for w in e.validation.warnings + fit_warnings[e.label]]
    if warns:
        parts.append("<section><h2>Warnings</h2>" + "".join(f'<div class="warn">{html.escape(w)}</div>'
                                                           for w in dict.fromkeys(warns)) + "</section>")
    groups = akaike(entries)[1]
    parts.append("<section><h2>Model comparison</h2>" +
                 _table(COMPARISON_COLUMNS, comparison_rows(entries), text=(1,)) +
                 definitions(*COMPARISON_COLUMNS[2:8]) +
                 ("" if groups <= 1 else "<p class='note'>Fits of different data are compared within their own "
                  "group.</p>") +
                 "<p class='note'>AICc weighs how well each model fits the data it was identified on against its "
                 "number of parameters; the held-out errors compare the models on temperatures none was fitted "
                 "to.</p>" +
                 f'<div class="pair">{fig_errors(figs, entries)}{fig_steps(figs, entries)}</div></section>')
    parts.append("<section><h2>Displacement</h2>" + fig_displacement(figs, entries) + "</section>")
    parts.append("<section><h2>Residuals</h2>" + fig_residuals(figs, entries) + "</section>")
    held = sorted({p.temperature for e in entries for p in e.validation.predictions if p.role == "validate"})
    mi = [e for e in entries if isinstance(e.model.thermal, ModelI)]
    mii = [e for e in entries if isinstance(e.model.thermal, ModelII)]
    thermal = "".join(fig_model_i(figs, e, held) for e in mi) + "".join(fig_model_ii(figs, e, held) for e in mii)
    if thermal:
        parts.append("<section><h2>Thermal models</h2>" + thermal + "</section>")
    err_rows = []
    for e in entries:
        for m in e.validation.experiments:
            err_rows.append([e.label, m["file"], _fmt(m["temperature"], "{:.4g}"),
                             "held out" if m["role"] == "validate" else m["role"],
                             _fmt(m["max_error_pct"]), _fmt(m["rmse_offset_removed"] * 1e9, "{:.4g}"), _fmt(m["nrmse"]),
                             _fmt(m["final_error_pct"], "{:+.3g}"), _fmt(m["step_error_pct"])])
    parts.append("<section><h2>Errors per experiment</h2>" + _table(
        EXPERIMENT_COLUMNS, err_rows, row_class=lambda r: "held" if r[3] == "held out" else "", text=(1, 3)) +
                 "<p class='note'>e = x_sim − x_meas at each sample: the predicted minus the measured end-effector "
                 "displacement, both starting from zero (the measurement's arbitrary zero matched on the first 1 % "
                 "of the run). Held-out rows are shaded.</p>" + definitions(*EXPERIMENT_COLUMNS[4:]) + "</section>")
    if bands is not None:
        parts.append("<section><h2>Prediction bands</h2>" + figs.render(
            bands.plot(), "prediction-bands",
            f"The fitted model's prediction with its {100 * bands.level:g} % band from the parameters' uncertainty "
            f"(Monte Carlo: {bands.draws} parameter sets drawn from the fit's covariance, "
            f"{bands.draws - len(bands.failures)} of them simulated), shown as the difference from the fitted "
            f"model: per temperature over time (left) and the mean step per cycle against temperature (right).")
            + "</section>")
    if truth:
        parts.append(truth_section(truth))
    fit_T = float(np.mean([e.temperature for e in exps if getattr(e, "role", "fit") != "validate"] or
                          [e.temperature for e in exps]))
    parts.append(parameter_section(entries, fit_T))
    return page_html(title or f"thermofriction report — {getattr(data, 'name', None) or 'dataset'}",
                     f"{', '.join(e.label for e in entries)} on {len(exps)} experiments", parts, command=command,
                     data=data)


def truth_section(truth: dict) -> str:
    """Data made from a known model (the demo, a study): whether each fit's 95 % intervals cover it, or
    why a fit cannot be compared with it. ``truth``: label -> FitResult.recovery summary."""
    parts = []
    for label, rec in truth.items():
        parts.append(f"<p><b>{html.escape(label)}</b>: {html.escape(rec['summary'])}.</p>")
        rows = rec.get("rows", [])
        if rows:
            summary = []
            for name in dict.fromkeys(r["parameter"] for r in rows):
                mine = [r for r in rows if r["parameter"] == name]
                scale = max(abs(r["truth"]) for r in mine) or 1.0
                summary.append([name, f"{sum(r['covered'] for r in mine)} of {len(mine)}",
                                _fmt(100 * max(abs(r["value"] - r["truth"]) for r in mine) / scale, "{:.2g}"),
                                _fmt(100 * max((r["upper"] - r["lower"]) / 2 for r in mine) / scale, "{:.2g}")])
            parts.append(_table(["parameter", "covered", "largest error [% of the truth's largest value]",
                                 "largest interval half-width [%]"], summary, text=(0,)))
            detail = [[r["parameter"], _fmt(r["temperature"], "{:.4g}"), _fmt(r["truth"], "{:.5g}"),
                       _fmt(r["value"], "{:.5g}"), f"[{r['lower']:.5g}, {r['upper']:.5g}]",
                       "yes" if r["covered"] else "NO"] for r in rows]
            parts.append("<details><summary>every (parameter, temperature) point</summary>" +
                         _table(["parameter", "temperature [°C]", "truth", "fitted", "95 % interval", "covered"],
                                detail, text=(0, 5)) + "</details>")
    return ("<section><h2>Against the truth</h2><p class='note'>These data were made by simulation from a known "
            "model: each fitted law at the fit temperatures, with its 95 % interval (delta method over the fitted "
            "coefficients and breakpoints), against the truth. About 1 point in 20 outside its interval is what a "
            "95 % interval means.</p>" + "".join(parts) + "</section>")


def _check_report_arguments(models, data, path, figures_dir, command, title, truth) -> list:
    """The types of report()'s arguments (_args.py); one model or fit is a list of one."""
    if isinstance(models, (Model, Entry)) or (hasattr(models, "to_dict") and hasattr(models, "model")):
        models = [models]
    if not isinstance(models, (list, tuple)) or not models:
        _args.refuse("models", "a non-empty list of Models, FitResults or (label, Model, fit dict) entries", models)
    for m in models:
        if not (isinstance(m, (Model, Entry)) or (hasattr(m, "to_dict") and isinstance(getattr(m, "model", None), Model))
                or (isinstance(m, tuple) and len(m) == 3 and isinstance(m[0], str) and isinstance(m[1], Model)
                    and (m[2] is None or isinstance(m[2], dict)))):
            _args.refuse("models", "a list of Models, FitResults or (label, Model, fit dict) entries; one entry is", m)
    _args.dataset(data, Dataset, experiments=True)
    _args.path(path, "path")
    _args.path(figures_dir, "figures_dir", none=True)
    _args.text(command, "command", none=True)
    _args.text(title, "title", none=True)
    _args.instance(truth, dict, "truth", "a dict (label -> FitResult.recovery summary)", none=True)
    return list(models)


def report(models, data, path, *, figures_dir=None, command=None, title=None, truth=None, bands=None) -> str:
    """Writes the HTML report comparing ``models`` (Model, FitResult, or (label, Model, fit dict)
    entries) on ``data``; returns the HTML. ``truth`` (label -> FitResult.recovery summary, for data
    made from a known model) adds a section saying whether the fits recover it; ``bands`` (what
    ``tf.propagate`` returns) a section with the prediction bands."""
    models = _check_report_arguments(models, data, path, figures_dir, command, title, truth)
    entries = []
    for m in models:
        if isinstance(m, Entry):
            entries.append(m)
        elif isinstance(m, Model):
            entries.append(Entry(entry_label(m), m))
        elif hasattr(m, "to_dict") and hasattr(m, "model"):
            d = m.to_dict()
            entries.append(Entry(entry_label(m.model, d), m.model, d))
        else:
            label, model, fit = m
            entries.append(Entry(label, model, fit))
    if not entries:
        raise InputError("give at least one model")
    from ..data.force import is_force_data
    if is_force_data(getattr(data, "experiments", data)):  # measured force under measured motion: report/force.py
        from .force import render_force
        text = render_force(entries, data, figures_dir=figures_dir, command=command or " ".join(sys.argv), title=title)
    else:
        text = render(entries, data, figures_dir=figures_dir, command=command or " ".join(sys.argv), title=title,
                      truth=truth, bands=bands)
    with atomic_write(path, "w", encoding="utf-8") as fh:
        fh.write(text)
    return text



__all__ = ["report", "render", "Entry", "heating_report", "control_report"]
