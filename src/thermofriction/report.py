"""The HTML report: one self-contained file (figures inlined as SVG, no scripts) comparing models
on a dataset — the paper's Figs. 3-7, 9-10 and Eq. (13), residuals, error and comparison tables,
and a footer that lets anyone reproduce it."""

from __future__ import annotations

import dataclasses
import datetime
import hashlib
import html
import io
import math
import platform
import re
import sys
from pathlib import Path

import numpy as np

from ._io import atomic_write
from .errors import InputError
from .models import Model, ModelI, ModelII
from .validate import ValidationResult, validate

_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:0;color:#1d2433;background:#f6f7fb}
header{background:#1d2433;color:#fff;padding:24px 40px}
header h1{margin:0 0 6px;font-size:24px}
header p{margin:0;color:#c9d1e3}
main{padding:24px 40px;max-width:1200px}
section{background:#fff;border-radius:10px;box-shadow:0 1px 3px rgba(0,0,0,.08);padding:20px 24px;margin:0 0 22px}
h2{font-size:18px;margin:0 0 12px}
.cards{display:flex;flex-wrap:wrap;gap:14px;margin-bottom:22px}
.card{background:#fff;border-radius:10px;box-shadow:0 1px 3px rgba(0,0,0,.08);padding:14px 18px;min-width:200px;flex:1}
.card .k{font-size:12px;text-transform:uppercase;color:#6b7389;letter-spacing:.04em}
.card .v{font-size:22px;font-weight:600;margin-top:4px}
.card .s{font-size:13px;color:#6b7389}
table{border-collapse:collapse;font-size:13px;width:100%}
th,td{padding:5px 9px;border-bottom:1px solid #e6e8ef;text-align:right}
th:first-child,td:first-child{text-align:left}
thead th{background:#f0f2f7}
figure{margin:8px 0 18px}
figure svg{max-width:100%;height:auto}
figcaption{font-size:13px;color:#4a5266;margin-top:4px}
.warn{background:#fff6e0;border-left:4px solid #f0a500;padding:8px 12px;font-size:13px;margin:6px 0}
footer{font-size:12px;color:#6b7389;padding:0 40px 30px}
code{background:#eef0f5;padding:1px 4px;border-radius:3px}
"""


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


# -- figures ------------------------------------------------------------------------------------

def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    plt.rcParams.update({"svg.fonttype": "none", "font.size": 9, "axes.grid": True, "grid.alpha": 0.3,
                         "axes.spines.top": False, "axes.spines.right": False})
    return plt


class Figures:
    """Renders figures as inline SVG (unique ids per figure) and, on request, SVG and PNG files."""

    def __init__(self, folder=None):
        self.folder = Path(folder) if folder else None
        self.count = 0
        if self.folder:
            self.folder.mkdir(parents=True, exist_ok=True)

    def render(self, fig, name, caption) -> str:
        plt = _plt()
        self.count += 1
        plt.rcParams["svg.hashsalt"] = f"thermofriction-{self.count}-{name}"  # no id clashes between figures
        buf = io.StringIO()
        fig.savefig(buf, format="svg", bbox_inches="tight")
        svg = buf.getvalue()
        svg = svg[svg.index("<svg"):]
        svg = re.sub(r"<metadata>.*?</metadata>", "", svg, flags=re.S)  # RDF boilerplate, a date: noise
        if self.folder:
            with atomic_write(self.folder / f"{name}.svg", "w") as fh:
                fh.write(svg)
            with atomic_write(self.folder / f"{name}.png", "wb") as fh:
                fig.savefig(fh, format="png", dpi=150, bbox_inches="tight")
        plt.close(fig)
        return f'<figure id="fig-{name}">{svg}<figcaption>{html.escape(caption)}</figcaption></figure>'


def _thin(t, y, n=1200):
    """At most ~2n points that keep each bucket's minimum and maximum, so that a 20 000-sample curve
    draws the same in a figure a few hundred pixels wide, in a fraction of the file size."""
    t, y = np.asarray(t), np.asarray(y)
    if len(t) <= 2 * n:
        return t, y
    edges = np.linspace(0, len(t), n + 1).astype(int)
    idx = []
    for a, b in zip(edges[:-1], edges[1:]):
        seg = y[a:b]
        i, j = a + int(np.argmin(seg)), a + int(np.argmax(seg))
        idx.extend(sorted({i, j}))
    idx = np.array(idx)
    return t[idx], y[idx]


def _colors(temps):
    plt = _plt()
    lo, hi = min(temps), max(temps)
    cmap = plt.get_cmap("plasma")
    return {T: cmap(0.1 + 0.75 * ((T - lo) / (hi - lo) if hi > lo else 0.5)) for T in temps}


def fig_displacement(figs, entries):
    plt = _plt()
    n = len(entries)
    fig, axes = plt.subplots(1, n, figsize=(4.2 * n, 3.4), squeeze=False, sharey=True)
    temps = sorted({p.temperature for p in entries[0].validation.predictions})
    col = _colors(temps)
    for ax, e in zip(axes[0], entries):
        for p in e.validation.predictions:
            stride = max(len(p.time) // 60, 1)
            ax.plot(p.time[::stride], p.measured[::stride] * 1e6, "o", ms=3, mfc="none", color=col[p.temperature],
                    alpha=0.8)
            ax.plot(*_thin(p.time, p.predicted * 1e6), "-", lw=1.2, color=col[p.temperature],
                    label=f"{p.temperature:.1f} °C" + (" (held out)" if p.role == "validate" else ""))
        ax.set_title(e.label)
        ax.set_xlabel("time [s]")
    axes[0][0].set_ylabel("displacement [µm]")
    axes[0][-1].legend(fontsize=7, loc="upper left", frameon=False)
    return figs.render(fig, "displacement", "Measured (markers) and predicted (lines) end-effector displacement at "
                       "each temperature, as in the paper's Figs. 9-10. Held-out temperatures were not used "
                       "for identification.")


def fig_residuals(figs, entries):
    plt = _plt()
    n = len(entries)
    fig, axes = plt.subplots(1, n, figsize=(4.2 * n, 2.8), squeeze=False)
    temps = sorted({p.temperature for p in entries[0].validation.predictions})
    col = _colors(temps)
    for ax, e in zip(axes[0], entries):
        for p in e.validation.predictions:
            ax.plot(*_thin(p.time, (p.predicted - p.measured) * 1e9), lw=0.6, color=col[p.temperature])
        ax.set_title(e.label)
        ax.set_xlabel("time [s]")
    axes[0][0].set_ylabel("predicted − measured [nm]")
    return figs.render(fig, "residuals", "Residuals of each model at each temperature.")


def fig_steps(figs, entries):
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.5, 3.4))
    preds = entries[0].validation.predictions
    T = np.array([p.temperature for p in preds])
    meas = np.array([np.mean(p.measured_steps) if p.measured_steps.size else np.nan for p in preds]) * 1e6
    order = np.argsort(T)
    ax.plot(T[order], meas[order], "ko", label="measured", zorder=5)
    for e, marker in zip(entries, "s^dv<>"):
        pr = np.array([np.mean(p.predicted_steps) if p.predicted_steps.size else np.nan
                       for p in e.validation.predictions]) * 1e6
        ax.plot(T[order], pr[order], marker + "-", ms=4, lw=1, label=e.label)
    ax.set_xlabel("temperature [°C]")
    ax.set_ylabel("step per cycle [µm]")
    ax.legend(frameon=False, fontsize=8)
    return figs.render(fig, "steps", "Mean step per cycle against temperature: measured and predicted.")


def fig_model_i(figs, entry):
    det = (entry.fit or {}).get("details", {})
    per_T, laws = det.get("per_temperature"), det.get("laws")
    if not per_T or not laws:
        return ""
    plt = _plt()
    names = list(laws)
    fig, axes = plt.subplots(1, len(names), figsize=(3.6 * len(names), 3.0), squeeze=False)
    T = np.array([r["temperature"] for r in per_T])
    grid = np.linspace(T.min() - 0.5, T.max() + 0.5, 200)
    paper = {"sigma0": lambda t: 1.15072e8 * np.exp(-0.136 * t), "sigma1": lambda t: -0.138 * t + 6.445,
             "fc": lambda t: 106.04 * np.exp(-0.159 * t)}
    units = {"sigma0": "N/m", "sigma1": "N s/m", "fc": "N"}
    for ax, n in zip(axes[0], names):
        vals = np.array([r["parameters"][n]["value"] for r in per_T], dtype=float)
        ci = np.array([r["parameters"][n]["ci95"] or [np.nan, np.nan] for r in per_T], dtype=object)
        lo = np.array([float(c[0]) if c[0] not in ("inf", "-inf", None) else np.nan for c in ci])
        hi = np.array([float(c[1]) if c[1] not in ("inf", "-inf", None) else np.nan for c in ci])
        yerr = np.vstack([np.clip(vals - lo, 0, None), np.clip(hi - vals, 0, None)])
        yerr = np.where(np.isfinite(yerr), yerr, 0)
        ax.errorbar(T, vals, yerr=yerr, fmt="o", ms=4, capsize=2, color="k", label="per temperature (95 %)")
        law = entry.model.laws.get(n)
        if law is not None:
            ax.plot(grid, law(grid), "-", color="C0", label=f"fitted law ({law.kind})")
        if n in paper:
            ax.plot(grid, paper[n](grid), "--", color="C3", lw=1, label="paper, Eqs. (9)-(11)")
        ax.set_xlabel("temperature [°C]")
        ax.set_ylabel(f"{n} [{units.get(n, '')}]")
        ax.set_title(f"{n}: {laws[n].get('chosen', '')}", fontsize=9)
    axes[0][0].legend(fontsize=7, frameon=False)
    return figs.render(fig, "model-i-parameters", "Model I: each identified parameter against temperature with its "
                       "95 % interval, the law fitted through them (refined on all experiments), and the paper's "
                       "Eqs. (9)-(11) (Figs. 3-5).")


def fig_model_ii(figs, entry):
    fit = entry.fit or {}
    det = fit.get("details", {})
    alt = (fit.get("alternatives") or {}).get("paper", {}).get("details", {})
    paper = det.get("paper") or alt.get("paper")
    direct = det.get("direct")
    if not paper and not direct:
        return ""
    plt = _plt()
    panels = (2 if paper else 0) + 1
    fig, axes = plt.subplots(1, panels, figsize=(3.9 * panels, 3.1), squeeze=False)
    ax_list = list(axes[0])
    if paper:
        ax = ax_list.pop(0)
        T = np.array(paper["temperatures"], float)
        D = np.array(paper["displacement"], float)
        ax.plot(T, D * 1e6, "ko", ms=4, label="measured")
        knots = np.array(paper["displacement_law"]["T"], float)
        vals = np.array(paper["displacement_law"]["values"], float)
        ax.plot(knots, vals * 1e6, "-", color="C0", label=f"two segments, break {paper['breakpoint']:.1f} °C")
        ax.set_xlabel("temperature [°C]")
        ax.set_ylabel("net displacement [µm]")
        ax.set_title("displacement vs temperature (Fig. 6)", fontsize=9)
        ax.legend(fontsize=7, frameon=False)
        ax = ax_list.pop(0)
        dF = np.array(paper["dF_grid"], float)
        Ds = np.array(paper["displacement_vs_dF"], float)
        lf = paper["linear_fit"]
        ax.plot(dF, Ds * 1e6, "ko", ms=4, label="simulated")
        ax.plot(dF, (lf["intercept"] + lf["slope"] * dF) * 1e6, "-", color="C0", label=f"linear, R² = {lf['r2']:.4f}")
        ax.set_xlabel("thermal-induced friction dF [N]")
        ax.set_ylabel("net displacement [µm]")
        ax.set_title("displacement vs dF (Fig. 7)", fontsize=9)
        ax.legend(fontsize=7, frameon=False)
    ax = ax_list.pop(0)
    lo_hi = [30.0, 41.5]
    if direct:
        T = np.array(direct["temperatures"], float)
        v = np.array(direct["dF"], float)
        se = np.array([float(x) if x not in ("inf", None) else np.nan for x in direct["stderr"]])
        ax.errorbar(T, v, yerr=np.where(np.isfinite(se), 1.96 * se, 0), fmt="o", ms=4, capsize=2, color="k",
                    label="per temperature (direct, 95 %)")
        lo_hi = [T.min(), T.max()]
    grid = np.linspace(lo_hi[0] - 0.5, lo_hi[1] + 0.5, 200)
    if isinstance(entry.model.thermal, ModelII):
        ax.plot(grid, entry.model.thermal.dF(grid), "-", color="C0", label=f"{entry.label}")
    if paper:
        law = paper["dF_law"]
        ax.plot(law["T"], law["values"], "-", color="C2", label="paper's procedure")
    eq13 = np.where(grid <= 38.4, (-0.29 * grid + 8.704) / 16.8, (-1.8 * grid + 66.678) / 16.8)
    ax.plot(grid, eq13, "--", color="C3", lw=1, label="paper, Eq. (13)")
    ax.set_xlabel("temperature [°C]")
    ax.set_ylabel("dF [N]")
    ax.set_title("thermal-induced friction (Eq. 13)", fontsize=9)
    ax.legend(fontsize=7, frameon=False)
    return figs.render(fig, "model-ii", "Model II: the paper's procedure (displacement against temperature with "
                       "an estimated breakpoint, displacement against dF by simulation) and the direct one "
                       "(dF fitted per temperature on the trajectories), with the paper's Eq. (13).")


# -- tables -------------------------------------------------------------------------------------

def _table(head, rows):
    h = "".join(f"<th>{html.escape(c)}</th>" for c in head)
    b = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in r) + "</tr>" for r in rows)
    return f"<table><thead><tr>{h}</tr></thead><tbody>{b}</tbody></table>"


def _fmt(x, f="{:.3g}"):
    try:
        x = float(x)
    except (TypeError, ValueError):
        return "—"
    return f.format(x) if math.isfinite(x) else "—"


def comparison_rows(entries):
    rows = []
    for e in entries:
        s = e.validation.summary()
        v = s.get("validate", s.get("fit", {}))
        f = e.fit or {}
        rows.append([e.label, _fmt(v.get("max_error_pct")), _fmt(v.get("mean_max_error_pct")),
                     _fmt(v.get("rmse", math.nan) * 1e9, "{:.4g}"), _fmt(s.get("fit", {}).get("max_error_pct")),
                     _fmt(f.get("aicc"), "{:.1f}"), _fmt(f.get("wall_time"), "{:.2f} s")])
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
    warns = [f"{e.label}: the fit did not converge: {(e.fit or {}).get('message', '')}" for e in entries
             if (e.fit or {}).get("success") is False]  # never silently: first, and in every report
    warns += [f"{e.label}: {w}" for e in entries for w in e.validation.warnings + (e.fit or {}).get("warnings", [])]
    if warns:
        parts.append("<section><h2>Warnings</h2>" + "".join(f'<div class="warn">{html.escape(w)}</div>'
                                                           for w in dict.fromkeys(warns)) + "</section>")
    parts.append("<section><h2>Model comparison</h2>" + _table(
        ["model", "max error, held out [%]", "mean max error, held out [%]", "RMSE, held out [nm]",
         "max error, fit [%]", "AICc", "identification time"], comparison_rows(entries)) +
        "<p style='font-size:13px;color:#4a5266'>Max error is the paper's maximum prediction error, "
        "max |x_sim − x_meas| / (max x_meas − min x_meas).</p></section>")
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
                             _fmt(m["max_error_pct"]), _fmt(m["rmse"] * 1e9, "{:.4g}"), _fmt(m["nrmse"]),
                             _fmt(m["final_error_pct"], "{:+.3g}"), _fmt(m["step_error_pct"])])
    parts.append("<section><h2>Errors per experiment</h2>" + _table(
        ["model", "file", "T [°C]", "role", "max error [%]", "RMSE [nm]", "NRMSE", "final error [%]",
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


def _versions():
    import matplotlib
    import scipy

    from . import __version__
    return {"thermofriction": __version__, "python": platform.python_version(), "numpy": np.__version__,
            "scipy": scipy.__version__, "matplotlib": matplotlib.__version__}


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
    text = render(entries, data, figures_dir=figures_dir, command=command or " ".join(sys.argv), title=title)
    with atomic_write(path, "w", encoding="utf-8") as fh:
        fh.write(text)
    return text


__all__ = ["report", "render", "Entry", "data_hash"]


# -- self-heating (SPEC 5.3) ----------------------------------------------------------------------

def heating_report(runs, path, *, figures_dir=None, title=None, command=None) -> str:
    """Writes an HTML report of long heated runs: ``runs`` is a list of dicts with ``label``,
    ``result`` (a HeatingResult, the prediction with self-heating), optionally ``reference`` (the
    full simulation on the same grid) and ``constant`` (the displacement predicted at the start
    temperature, on the same grid). Figures: temperature rise, step-size drift, and the error of
    the constant-temperature prediction; a table of the figures that matter."""
    plt = _plt()
    figs = Figures(figures_dir)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    parts = []
    fig, ax = plt.subplots(figsize=(7, 3.4))
    for i, r in enumerate(runs):
        res = r["result"]
        ax.plot(res.time, res.temperature, color=colors[i % len(colors)], label=r["label"])
        if r.get("reference") is not None:
            ax.plot(r["reference"].time, r["reference"].temperature, ":", color="k", lw=1)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("interface temperature [°C]")
    ax.legend()
    temp_fig = figs.render(fig, "heating_temperature", "Temperature of the friction interface (lines: two-time-scale "
                           "method; dotted: the full simulation through every cycle).")
    fig, ax = plt.subplots(figsize=(7, 3.4))
    for i, r in enumerate(runs):
        res = r["result"]
        ax.plot(res.time, res.step_size * 1e6, color=colors[i % len(colors)], label=r["label"])
        if r.get("reference") is not None:
            ref = r["reference"]
            ax.plot(ref.time, ref.step_size * 1e6, ":", color="k", lw=1)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("step per cycle [µm]")
    ax.legend()
    step_fig = figs.render(fig, "heating_step_size", "Step size drift as the interface heats (dotted: full simulation).")
    fig, ax = plt.subplots(figsize=(7, 3.4))
    rows = []
    for i, r in enumerate(runs):
        res, ref, const = r["result"], r.get("reference"), r.get("constant")
        truth = ref if ref is not None else res
        if const is not None:
            err = (const - truth.displacement) / np.maximum(np.abs(truth.displacement), 1e-300) * 100
            ax.plot(truth.time[1:], err[1:], color=colors[i % len(colors)], label=r["label"])
        rows.append([r["label"], _fmt(res.temperature[-1] - res.temperature[0], "{:.3g}"),
                     _fmt(res.step_size[0] * 1e6, "{:.4g}"), _fmt(res.step_size[-1] * 1e6, "{:.4g}"),
                     _fmt(truth.displacement[-1] * 1e3, "{:.5g}"),
                     _fmt(None if const is None else (const[-1] - truth.displacement[-1]) * 1e3, "{:+.4g}"),
                     _fmt(None if ref is None else np.max(np.abs(res.temperature - ref.temperature)), "{:.2g}"),
                     _fmt(None if ref is None else abs(res.displacement[-1] - ref.displacement[-1])
                          / abs(ref.displacement[-1]) * 100, "{:.2g}"),
                     _fmt(res.stats.get("seconds"), "{:.3g}"),
                     _fmt(None if ref is None else ref.stats.get("seconds"), "{:.3g}")])
    ax.set_xlabel("time [s]")
    ax.set_ylabel("constant-temperature error [%]")
    ax.set_yscale("symlog", linthresh=1.0)
    ax.legend()
    err_fig = figs.render(fig, "heating_constant_temperature_error", "Error of the displacement predicted at the "
                          "start temperature (no self-heating), relative to the prediction with self-heating.")
    parts.append("<section><h2>Summary</h2>" + _table(
        ["run", "temperature rise [K]", "first step [µm]", "last step [µm]", "displacement [mm]",
         "constant-T error [mm]", "max |ΔT| vs full [K]", "displacement error vs full [%]",
         "two-time-scale [s]", "full [s]"], rows) + "</section>")
    parts.append("<section><h2>Temperature</h2>" + temp_fig + "</section>")
    parts.append("<section><h2>Step size</h2>" + step_fig + err_fig + "</section>")
    return _write_page(path, title or "thermofriction — self-heating", ", ".join(r["label"] for r in runs), parts,
                       command)


def _write_page(path, title, subtitle, parts, command=None) -> str:
    """A standalone report page (the main report's style) written atomically; returns the HTML."""
    name = html.escape(title)
    footer = " · ".join(f"{k} {v}" for k, v in _versions().items()) + (
        f"<br>command: <code>{html.escape(command)}</code>" if command else "")
    text = (f"<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'><title>{name}</title>"
            f"<meta name='viewport' content='width=device-width, initial-scale=1'><style>{_CSS}</style></head>"
            f"<body><header><h1>{name}</h1><p>{html.escape(subtitle)}</p></header>"
            f"<main>{''.join(parts)}</main><footer>{footer}</footer></body></html>")
    with atomic_write(path, "w", encoding="utf-8") as fh:
        fh.write(text)
    return text


# -- friction compensation in closed loop -----------------------------------------------------------

def control_report(rows, path, *, figures_dir=None, title=None, command=None) -> str:
    """Writes an HTML report of thermofriction.control.compare_compensation's rows: the table of RMS
    and maximum tracking errors per reference, stage temperature and compensation, and for each
    reference the tracking error over time at the hottest temperature."""
    plt = _plt()
    figs = Figures(figures_dir)
    table = [[r["reference"], _fmt(r["temperature"], "{:.1f}"), r["compensation"], _fmt(r["rms_error"] * 1e6, "{:.3g}"),
              _fmt(r["max_error"] * 1e6, "{:.3g}")] for r in rows]
    parts = ["<section><h2>Tracking error</h2>" + _table(
        ["reference", "stage T [°C]", "compensation", "RMS error [µm]", "max error [µm]"], table) +
        "<p style='font-size:13px;color:#4a5266'>Blind: the compensation's model is told the calibration "
        "temperature (30 °C); aware: the measured temperature.</p></section>"]
    hottest = max(r["temperature"] for r in rows)
    for i, name in enumerate(dict.fromkeys(r["reference"] for r in rows)):
        fig, ax = plt.subplots(figsize=(7, 3.4))
        for r in rows:
            if r["reference"] == name and r["temperature"] == hottest:
                res = r["result"]
                ax.plot(res.time, res.error * 1e6, label=r["compensation"], lw=1)
        ax.set_xlabel("time [s]")
        ax.set_ylabel("tracking error [µm]")
        ax.set_yscale("symlog", linthresh=0.1)
        ax.legend(fontsize=8)
        parts.append("<section><h2>" + html.escape(name) + "</h2>" + figs.render(
            fig, f"control_error_{i}", f"Tracking error at {hottest:g} °C, {name}: no compensation, and "
            f"feed-forward or observer compensation, temperature-blind or temperature-aware.") + "</section>")
    return _write_page(path, title or "thermofriction — friction compensation", "closed-loop tracking", parts, command)


__all__ += ["heating_report", "control_report"]
