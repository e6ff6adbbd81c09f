"""The HTML report: one self-contained file (figures inlined as SVG, no scripts) comparing models
on a dataset — the paper's Figs. 3-7, 9-10 and Eq. (13), residuals, error and comparison tables,
and a footer that lets anyone reproduce it."""

from __future__ import annotations

import dataclasses
import datetime
import hashlib
import html
import math
import sys

import numpy as np

from .._io import atomic_write
from ..errors import InputError
from ..models import Model, ModelI, ModelII
from ..validate import ValidationResult, validate
from .figures import fig_displacement, fig_model_i, fig_model_ii, fig_residuals, fig_steps
from .page import _CSS, Figures, _fmt, _table, _versions
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


def data_hash(experiments) -> str:
    """SHA-256 over the numbers of every experiment (time, voltage, displacement), in order."""
    h = hashlib.sha256()
    for e in experiments:
        for arr in (e.time, e.voltage, e.displacement):
            h.update(np.ascontiguousarray(arr, dtype=float).tobytes())
        h.update(repr(float(e.temperature)).encode())
    return h.hexdigest()



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


def comparison_rows(entries):
    rows = []
    aic, _ = akaike(entries)
    for e, a in zip(entries, aic):
        s = e.validation.summary()
        v = s.get("validate", s.get("fit", {}))
        f = e.fit or {}
        rows.append([e.label, e.model.friction.model, _fmt(v.get("max_error_pct")), _fmt(v.get("mean_max_error_pct")),
                     _fmt(v.get("rmse_offset_removed", math.nan) * 1e9, "{:.4g}"), _fmt(s.get("fit", {}).get("max_error_pct")),
                     _fmt(a[0] if a else None, "{:.1f}"), _fmt(a[1] if a else None, "{:.3f}"),
                     _fmt(f.get("wall_time"), "{:.2f} s")])
    return rows


def render(entries, data, *, figures_dir=None, command=None, title=None) -> str:
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
    cards = [("best on held-out temperatures", best.label, f"max error {bs['max_error_pct']:.2g} %"),
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
    parts.append("<section><h2>Model comparison</h2>" + _table(
        ["model", "friction", "max error, held out [%]", "mean max error, held out [%]",
         "RMSE, held out [nm] (offset removed)", "max error, fit [%]", "ΔAICc", "Akaike weight",
         "identification time"], comparison_rows(entries)) +
        "<p style='font-size:13px;color:#4a5266'>Max error is the paper's maximum prediction error, "
        "max |x_sim − x_meas| / (max x_meas − min x_meas). ΔAICc is each fit's AICc minus the lowest, and "
        "the Akaike weight exp(−ΔAICc/2) normalised to one: the weight of evidence for each model among "
        "those fitted to the same data" + ("" if akaike(entries)[1] <= 1 else
                                           " (fits of different data are compared within their own group)") +
        "; held-out errors compare them on temperatures none was fitted to.</p></section>")
    parts.append("<section><h2>Displacement</h2>" + fig_displacement(figs, entries) + fig_steps(figs, entries) +
                 "</section>")
    mi = [e for e in entries if isinstance(e.model.thermal, ModelI)]
    mii = [e for e in entries if isinstance(e.model.thermal, ModelII)]
    thermal = "".join(fig_model_i(figs, e) for e in mi) + "".join(fig_model_ii(figs, e) for e in mii)
    if thermal:
        parts.append("<section><h2>Thermal models</h2>" + thermal + "</section>")
    parts.append("<section><h2>Residuals</h2>" + fig_residuals(figs, entries) + "</section>")
    err_rows = []
    for e in entries:
        for m in e.validation.experiments:
            err_rows.append([e.label, m["file"], _fmt(m["temperature"], "{:.4g}"), m["role"],
                             _fmt(m["max_error_pct"]), _fmt(m["rmse_offset_removed"] * 1e9, "{:.4g}"), _fmt(m["nrmse"]),
                             _fmt(m["final_error_pct"], "{:+.3g}"), _fmt(m["step_error_pct"])])
    parts.append("<section><h2>Errors per experiment</h2>" + _table(
        ["model", "file", "T [°C]", "role", "max error [%]", "RMSE [nm] (offset removed)", "NRMSE", "final error [%]",
         "step error [%]"], err_rows) + "</section>")
    param_rows = []
    for e in entries:
        for name, p in ((e.fit or {}).get("parameters") or {}).items():
            ci = p.get("ci95") or ["", ""]
            param_rows.append([e.label, name, _fmt(p.get("value"), "{:.6g}"), _fmt(p.get("stderr"), "{:.3g}"),
                               f"[{_fmt(ci[0], '{:.5g}')}, {_fmt(ci[1], '{:.5g}')}]", p.get("unit", "")])
    if param_rows:
        parts.append("<section><h2>Identified parameters</h2>" + _table(
            ["model", "parameter", "value", "std. error", "95 % interval", "unit"], param_rows) + "</section>")
    versions = _versions()
    footer = (f"thermofriction {versions['thermofriction']} · Python {versions['python']} · NumPy "
              f"{versions['numpy']} · SciPy {versions['scipy']} · matplotlib {versions['matplotlib']} · "
              f"data SHA-256 <code>{data_hash(exps)}</code> · written "
              f"{datetime.datetime.now(datetime.timezone.utc).strftime('%Y-%m-%d %H:%M UTC')}"
              + (f"<br>command: <code>{html.escape(command)}</code>" if command else ""))
    name = html.escape(title or f"thermofriction report — {getattr(data, 'name', None) or 'dataset'}")
    return (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{name}</title>"
            f"<meta name='viewport' content='width=device-width, initial-scale=1'><style>{_CSS}</style></head>"
            f"<body><header><h1>{name}</h1><p>{', '.join(html.escape(e.label) for e in entries)} on "
            f"{len(exps)} experiments</p></header><main>{''.join(parts)}</main><footer>{footer}</footer></body></html>")


def report(models, data, path, *, figures_dir=None, command=None, title=None) -> str:
    """Writes the HTML report comparing ``models`` (Model, FitResult, or (label, Model, fit dict)
    entries) on ``data``; returns the HTML."""
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
    draw = render
    if is_force_data(getattr(data, "experiments", data)):  # measured force under measured motion: report/force.py
        from .force import render_force as draw
    text = draw(entries, data, figures_dir=figures_dir, command=command or " ".join(sys.argv), title=title)
    with atomic_write(path, "w", encoding="utf-8") as fh:
        fh.write(text)
    return text



__all__ = ["report", "render", "Entry", "data_hash", "heating_report", "control_report"]
