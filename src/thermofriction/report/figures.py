"""The figures of the main report: the paper's Figs. 3-7 and 9-10, residuals, step sizes, and
the identified laws against the paper's."""

from __future__ import annotations

import numpy as np

from ..models import PARAMETER_UNITS, ModelII, load_model
from .page import _colors, _plt, _thin

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
    paper = load_model("li2009-model-i").laws  # the paper's Eqs. (9)-(11)
    for ax, n in zip(axes[0], names):
        vals = np.array([r["parameters"][n]["value"] for r in per_T], dtype=float)
        ci = np.array([r["parameters"][n]["ci95"] or [np.nan, np.nan] for r in per_T], dtype=object)
        lo = np.array([float(c[0]) if c[0] not in ("inf", "-inf", None) else np.nan for c in ci])
        hi = np.array([float(c[1]) if c[1] not in ("inf", "-inf", None) else np.nan for c in ci])
        # an interval that spans decades (a parameter the data do not determine) would flatten the
        # panel: it is drawn to the panel's edge instead (arrow) and named in the warnings
        span = np.nanmax(np.abs(vals)) if np.any(np.isfinite(vals)) else 1.0
        open_hi = ~np.isfinite(hi) | (hi > vals + 3 * span)
        hi = np.where(open_hi, np.nan, hi)
        yerr = np.vstack([np.clip(vals - lo, 0, None), np.clip(hi - vals, 0, None)])
        yerr = np.where(np.isfinite(yerr), yerr, 0)
        ax.errorbar(T, vals, yerr=yerr, fmt="o", ms=4, capsize=2, color="k", label="per temperature (95 %)")
        if open_hi.any():
            ax.plot(T[open_hi], vals[open_hi], "^", ms=6, color="C1", label="interval open upwards")
        law = entry.model.laws.get(n)
        if law is not None:
            ax.plot(grid, law(grid), "-", color="C0", label=f"fitted law ({law.kind})")
        if n in paper:
            ax.plot(grid, paper[n](grid), "--", color="C3", lw=1, label="paper, Eqs. (9)-(11)")
        ax.set_xlabel("temperature [°C]")
        ax.set_ylabel(f"{n} [{PARAMETER_UNITS.get(n, '')}]")
        ax.set_title(f"{n}: {laws[n].get('chosen', '')}", fontsize=9)
    axes[0][0].legend(fontsize=7, frameon=False)
    return figs.render(fig, "model-i-parameters", "Model I: each identified parameter against temperature with its "
                       "95 % interval (an orange triangle where it is open upwards: the data do not bound the parameter "
                       "there), the law fitted through them (refined on all experiments), and the paper's "
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
    eq13 = load_model("li2009-model-ii").thermal.dF(grid)  # the paper's Eq. (13)
    ax.plot(grid, eq13, "--", color="C3", lw=1, label="paper, Eq. (13)")
    ax.set_xlabel("temperature [°C]")
    ax.set_ylabel("dF [N]")
    ax.set_title("thermal-induced friction (Eq. 13)", fontsize=9)
    ax.legend(fontsize=7, frameon=False)
    return figs.render(fig, "model-ii", "Model II: the paper's procedure (displacement against temperature with "
                       "an estimated breakpoint, displacement against dF by simulation) and the direct one "
                       "(dF fitted per temperature on the trajectories), with the paper's Eq. (13).")


