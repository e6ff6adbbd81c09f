"""Figures of a fit: the temperature laws with their per-temperature estimates and intervals (Model I), dF(T)
(Model II), and a fit's overview; in the visual language of plots.py."""

from __future__ import annotations

import math
import os

import numpy as np

from ..models import PARAMETER_UNITS, Model, ModelII, load_model
from ..models.laws import law_from_dict
from ..models.model import model_from_dict
from .friction_plots import force_overview
from .units import scaled_axis, scaled_ticks
from .plots import (HALF, MODEL_COLOURS, PAPER, WIDE, draw_displacement, draw_residuals, hide_unused, is_held_out,
                    legend, mark_held_out, new_figure, noise_handle, panel_grid, panels_width, styled, temperature_key,
                    temperature_styles)

#: the presets of Li et al. (2009)'s actuator: their published laws (Eqs. 9-11, 13) are drawn beside a fit only
#: when the model is one of them or was fitted from one
PAPER_PRESETS = "li2009-"


def from_the_paper(model) -> bool:
    """Whether ``model`` is one of the paper's presets (li2009-*) or was identified starting from one (its
    provenance's ``initial_model``): the paper's laws then describe the same actuator. A user's own actuator,
    started from a model of its own or from the data, is not compared with them."""
    names = [getattr(model, "name", None), ((getattr(model, "provenance", None) or {}).get("initial_model"))]
    return any(os.path.basename(str(n)).startswith(PAPER_PRESETS) for n in names if n)


def as_float(x):
    try:
        x = float(x)
    except (TypeError, ValueError):
        return math.nan
    return x


def per_temperature_estimates(fit: dict, name: str):
    """(T, value, lower, upper) arrays of a Model I parameter's per-temperature estimates and their
    95 % intervals (NaN where open), from a fit's results (FitResult.to_dict())."""
    per_T = ((fit or {}).get("details") or {}).get("per_temperature") or []
    rows = [(r["temperature"], r["parameters"][name]) for r in per_T if name in r.get("parameters", {})]
    T = np.array([t for t, _ in rows], float)
    v = np.array([as_float(p.get("value")) for _, p in rows])
    ci = [p.get("ci95") or [None, None] for _, p in rows]
    lo = np.array([as_float(c[0]) for c in ci])
    hi = np.array([as_float(c[1]) for c in ci])
    return T, v, lo, hi


def law_outside_intervals(fit: dict, model) -> dict:
    """parameter -> temperatures where the (refined) law lies outside the per-temperature 95 % interval."""
    out = {}
    for name, law in model.laws.items():
        T, v, lo, hi = per_temperature_estimates(fit, name)
        if not T.size:
            continue
        at = np.asarray(law(T), float)
        bad = (np.isfinite(lo) & (at < lo)) | (np.isfinite(hi) & (at > hi))
        if bad.any():
            out[name] = [float(x) for x in T[bad]]
    return out


def draw_law(ax, fit, model, name, held_out=(), paper=True):
    """A Model I parameter against temperature: per-temperature estimates with 95 % intervals,
    the law through them before refinement, the refined law, the paper's, held-out temperatures."""
    T, vals, lo, hi = per_temperature_estimates(fit, name)
    unit = PARAMETER_UNITS.get(name, "")
    lims = [x for x in vals if math.isfinite(x)]
    if T.size:
        # an interval that spans decades (a parameter the data do not determine) would flatten the
        # panel: it is drawn to the panel's edge instead (an upward triangle)
        span = np.nanmax(np.abs(vals)) if np.any(np.isfinite(vals)) else 1.0
        open_hi = ~np.isfinite(hi) | (hi > vals + 3 * span)
        hi_d = np.where(open_hi, np.nan, hi)
        yerr = np.vstack([np.clip(vals - lo, 0, None), np.clip(hi_d - vals, 0, None)])
        yerr = np.where(np.isfinite(yerr), yerr, 0)
        ax.errorbar(T, vals, yerr=yerr, fmt="o", ms=5, capsize=3, color="k", zorder=4,
                    label="per temperature, 95 % interval")
        if open_hi.any():
            ax.plot(T[open_hi], vals[open_hi], "^", ms=8, color="#ff7f0e", zorder=5, label="interval open upwards")
        lims += [x for x in np.concatenate([lo, hi_d]) if math.isfinite(x)]
    lo_T, hi_T = (float(T.min()), float(T.max())) if T.size else (model.laws[name].range or (30.0, 40.0))
    allT = list(held_out) + ([lo_T, hi_T])
    grid = np.linspace(min(allT) - 0.5, max(allT) + 0.5, 200)
    chosen = (((fit or {}).get("details") or {}).get("laws") or {}).get(name, {})
    first = (chosen.get("candidates") or {}).get(chosen.get("chosen"), {}).get("law")
    if first:
        try:
            before = law_from_dict(first, name)
            ax.plot(grid, before(grid), ":", color=MODEL_COLOURS[0], lw=1.4, label="law through the estimates")
        except Exception:  # a law the reader does not know: the refined one is still drawn
            pass
    law = model.laws.get(name)
    if law is not None:
        y = law(grid)
        ax.plot(grid, y, "-", color=MODEL_COLOURS[0], lw=2, label=f"refined law ({law.kind})", zorder=3)
        lims += list(y)
        if T.size:
            at = np.asarray(law(T), float)
            bad = (np.isfinite(lo) & (at < lo)) | (np.isfinite(hi) & (at > hi))
            if bad.any():
                ax.plot(T[bad], vals[bad], "o", ms=12, mfc="none", mec="#d62728", mew=1.6, zorder=6,
                        label="law outside the interval")
    if paper:
        ref = load_model("li2009-model-i").laws  # the paper's Eqs. (9)-(11)
        if name in ref:
            ax.plot(grid, ref[name](grid), label="paper, Eqs. (9)–(11)", **PAPER)
    mark_held_out(ax, held_out)
    if lims:  # the paper's law may leave the panel; the data and the fitted law may not
        a, b = min(lims), max(lims)
        pad = 0.08 * (b - a if b > a else abs(a) or 1.0)
        ax.set_ylim(a - pad, b + pad)
    ax.set_xlabel("temperature [°C]")
    scaled_ticks(ax, "y", lims, name, unit)
    ax.set_title(name)


@styled
def laws_figure(fit, model, held_out=(), paper=None):
    """Model I: every parameter with a law, one panel each (a fit's results dict and its model); the paper's laws
    where ``paper``, by default where the model is the paper's (:func:`from_the_paper`)."""
    names = list(model.laws)
    if not names:
        return None
    paper = from_the_paper(model) if paper is None else paper
    rows, cols = panel_grid(len(names))
    fig, axes = new_figure(panels_width(cols), 3.6 * rows + 0.3, nrows=rows, ncols=cols)
    for ax, n in zip(axes.flat, names):
        draw_law(ax, fit, model, n, held_out, paper)
    hide_unused(axes, len(names))
    legend(fig, loc="outside right upper")
    return fig


def draw_dF(ax, fit, model, label="fitted dF(T)", held_out=(), paper=True):
    """Model II's dF(T): per-temperature (direct) estimates, the fitted law with its breakpoints,
    the paper's procedure's law and Eq. (13)."""
    det = (fit or {}).get("details") or {}
    alt = (((fit or {}).get("alternatives") or {}).get("paper") or {}).get("details") or {}
    procedure = det.get("paper") or alt.get("paper")
    direct = det.get("direct")
    Ts = list(held_out)
    if direct:
        T = np.array(direct["temperatures"], float)
        v = np.array(direct["dF"], float)
        se = np.array([as_float(x) for x in direct["stderr"]])
        ax.errorbar(T, v, yerr=np.where(np.isfinite(se), 1.96 * se, 0), fmt="o", ms=5, capsize=3, color="k",
                    zorder=4, label="per temperature (direct), 95 % interval")
        Ts += list(T)
    dF = model.thermal.dF if isinstance(model.thermal, ModelII) else None
    if dF is not None and getattr(dF, "range", None):
        Ts += list(dF.range)
    if not Ts:
        Ts = [30.0, 41.5]
    grid = np.linspace(min(Ts) - 0.5, max(Ts) + 0.5, 200)
    if dF is not None:
        ax.plot(grid, dF(grid), "-", color=MODEL_COLOURS[0], lw=2, label=label, zorder=3)
        if dF.kind in ("pwl", "table"):
            ax.plot(dF.T, dF.values, "s", ms=7, color=MODEL_COLOURS[0], zorder=5, label="breakpoints")
            for t, y in zip(dF.T, dF.values):
                ax.annotate(f"{t:.1f} °C", (t, y), xytext=(4, 6), textcoords="offset points", fontsize=9,
                            color=MODEL_COLOURS[0])
    if procedure:
        law = procedure["dF_law"]
        ax.plot(law["T"], law["values"], "-", color=MODEL_COLOURS[1], lw=1.4, label="the paper's procedure")
    if paper:
        ax.plot(grid, load_model("li2009-model-ii").thermal.dF(grid), label="paper, Eq. (13)", **PAPER)
    mark_held_out(ax, held_out)
    ax.set_xlabel("temperature [°C]")
    scaled_ticks(ax, "y", np.concatenate([np.asarray(ax.dataLim.intervaly)]), "dF", "N")
    ax.set_title("dF(T)")


@styled
def model_ii_figure(fit, model, held_out=(), paper=None):
    """Model II: the paper's procedure (displacement against temperature, against dF) when it ran,
    and dF(T); the paper's Eq. (13) where ``paper``, by default where the model is the paper's."""
    paper = from_the_paper(model) if paper is None else paper
    det = (fit or {}).get("details") or {}
    alt = (((fit or {}).get("alternatives") or {}).get("paper") or {}).get("details") or {}
    procedure = det.get("paper") or alt.get("paper")
    if not procedure and not det.get("direct") and not isinstance(model.thermal, ModelII):
        return None
    panels = 3 if procedure else 1
    fig, axes = new_figure(panels_width(panels), 3.9, nrows=1, ncols=panels)
    axl = list(axes[0])
    if procedure:
        ax = axl.pop(0)
        T = np.array(procedure["temperatures"], float)
        D = np.array(procedure["displacement"], float)
        k = scaled_axis(ax, "y", D, "net displacement", "m")
        ax.plot(T, D * k, "ko", ms=5, label="measured")
        knots = np.array(procedure["displacement_law"]["T"], float)
        vals = np.array(procedure["displacement_law"]["values"], float)
        ax.plot(knots, vals * k, "-", color=MODEL_COLOURS[1],
                label=f"two segments,\nbreak at {procedure['breakpoint']:.1f} °C")
        mark_held_out(ax, held_out, label=False)
        ax.set_xlabel("temperature [°C]")
        ax.set_title("Fig. 6: against T")
        legend(ax, loc="best")
        ax = axl.pop(0)
        dFg = np.array(procedure["dF_grid"], float)
        Ds = np.array(procedure["displacement_vs_dF"], float)
        lf = procedure["linear_fit"]
        k = scaled_axis(ax, "y", Ds, "net displacement", "m")
        ax.plot(dFg, Ds * k, "ko", ms=5, label="simulated")
        ax.plot(dFg, (lf["intercept"] + lf["slope"] * dFg) * k, "-", color=MODEL_COLOURS[1],
                label=f"linear, R² = {lf['r2']:.4f}")
        ax.set_xlabel("dF [N]")
        ax.set_title("Fig. 7: against dF")
        legend(ax, loc="best")
    ax = axl.pop(0)
    draw_dF(ax, fit, model, held_out=held_out, paper=paper)
    legend(fig, ax.get_legend_handles_labels()[0], loc="outside right upper")
    return fig


# -- the result objects' .plot() ---------------------------------------------------------------

def _held_out_temperatures(predictions):
    return sorted({p.temperature for p in predictions if is_held_out(p.role)})


@styled
def parameters_figure(fit: dict):
    """A fit's parameters with their 95 % intervals, relative to each value (log axis): how well the data
    determine each. For a fit without a thermal law, when no data are given to compare with."""
    rows = [(n, p) for n, p in (fit.get("parameters") or {}).items() if p.get("vary")]
    fig, axes = new_figure(HALF, 0.5 + 0.45 * max(len(rows), 1))
    ax = axes[0][0]
    for k, (name, p) in enumerate(rows):
        v, ci = as_float(p.get("value")), p.get("ci95") or [None, None]
        lo, hi = as_float(ci[0]), as_float(ci[1])
        if not (v > 0 and math.isfinite(lo) and math.isfinite(hi)):
            ax.text(1.0, k, "interval not finite", fontsize=8, ha="center", va="center", color="#d62728",
                    bbox={"facecolor": "white", "edgecolor": "none", "pad": 1})
            continue
        ax.plot([max(lo / v, 1e-3), min(hi / v, 1e3)], [k, k], color=MODEL_COLOURS[0], lw=2)
        ax.plot([1.0], [k], "o", color=MODEL_COLOURS[0])
    ax.set_yticks(range(len(rows)), [f"{n} [{p.get('unit', '')}]" for n, p in rows])
    ax.set_ylim(-0.6, len(rows) - 0.4)
    ax.set_xlim(1e-3, 1e3)
    ax.set_xscale("log")
    ax.axvline(1.0, color="0.6", lw=0.8)
    ax.set_xlabel("95 % interval / value")
    ax.set_title(f"{fit.get('method', 'fit')}: parameters")
    return fig


def _displacement_row(sub, preds, styles):
    a = sub.subplots(1, 2)
    draw_displacement(a[0], preds, styles)
    a[0].set_title("measured (markers), predicted (lines)")
    draw_residuals(a[1], preds, styles)
    a[1].set_title("residual RMS, 2 % windows")
    temperature_key(sub, styles, extra=[noise_handle()])


@styled
def fit_figure(fit, validation=None, paper=False):
    """An identification result (FitResult or its dict with ``model``): measured vs predicted and
    residual RMS (when ``validation`` of its model on the data is given), and its thermal law(s)
    with the per-temperature estimates and intervals."""
    d = fit.to_dict() if hasattr(fit, "to_dict") else fit
    model = fit.model if isinstance(getattr(fit, "model", None), Model) else model_from_dict(d["model"])
    laws = list(model.laws)
    model_ii = isinstance(model.thermal, ModelII)
    law_panels = len(laws) + (1 if model_ii else 0)
    rows = (1 if validation is not None else 0) + (1 if law_panels else 0)
    if rows == 0:  # no law and no data: the parameters with their intervals
        return parameters_figure(d)
    fig, _ = new_figure(WIDE, 3.7 * rows + 0.3, none=True)
    subs = fig.subfigures(rows, 1, squeeze=False)[:, 0] if rows > 1 else [fig]
    held = []
    k = 0
    if validation is not None:
        preds = list(validation.predictions)
        held = _held_out_temperatures(preds)
        styles = temperature_styles([(p.temperature, p.role) for p in preds])
        sub = subs[k]
        k += 1
        if hasattr(preds[0], "position"):  # force (torque) data: the friction over time and against position
            force_overview(sub, validation)
        else:
            _displacement_row(sub, preds, styles)
    if law_panels:
        sub = subs[k]
        a = sub.subplots(1, max(law_panels, 2) if rows > 1 else law_panels, squeeze=False)[0]
        for ax, n in zip(a, laws):
            draw_law(ax, d, model, n, held, paper)
        if model_ii:
            draw_dF(a[len(laws)], d, model, held_out=held, paper=paper)
        for ax in a[law_panels:]:
            ax.set_visible(False)
        legend(sub, [h for ax in a[:law_panels] for h in ax.get_legend_handles_labels()[0]], loc="outside right upper")
    name = f"{model.name or 'fitted model'} ({d.get('method') or 'fit'})"
    inner = fig.get_suptitle()  # a single row of force data names its experiment there
    fig.suptitle(f"{name}: {inner}" if inner else name)
    return fig


__all__ = ["parameters_figure", "per_temperature_estimates", "law_outside_intervals", "draw_law", "laws_figure", "draw_dF",
           "model_ii_figure", "fit_figure"]
