"""The report page for displacement data: the paper's Figs. 3-7, 9-10 and Eq. (13), residuals, error and
comparison tables, and a footer that lets anyone reproduce it."""

from __future__ import annotations

import html
import math

import numpy as np

from ..errors import InputError
from ..models import ModelI, ModelII
from ..plausible import SUSPICIOUS
from ..validation import validate
from .entries import COMPARISON_COLUMNS, EXPERIMENT_COLUMNS, akaike, comparison_rows, parameter_section
from .captions import (definitions, fig_displacement, fig_errors, fig_model_i, fig_model_ii, fig_residuals,
                      fig_steps)
from .page import Figures, fmt_number, html_table, page_html

def render(entries, data, *, figures_dir=None, command=None, title=None, truth=None, bands=None) -> str:
    """The report's page for displacement data: the paper's figures and tables, the models compared on the
    held-out experiments (``report`` writes it to a file).

    Parameters
    ----------
    entries : list of Entry
        The models compared, each with its label and, when known, its fit and validation.
    data : Dataset
        The measurements; at least one experiment with role "validate".
    figures_dir : str or os.PathLike, optional
        A folder where the figures are also written as SVG and PNG files.
    command : str, optional
        The command line shown as how the report was made.
    title : str, optional
        The page's title.
    truth : dict, optional
        Label -> ``FitResult.recovery`` summary, for data made from a known model.
    bands : PropagationResult, optional
        Prediction bands (``propagate``) shown in a section of their own.

    Returns
    -------
    str
        The page's HTML.

    Raises
    ------
    InputError
        A dataset without a held-out ("validate") experiment.
    ComputationError
        A model's predictions failed.
    """
    exps = list(getattr(data, "experiments", data))
    if not any(getattr(e, "role", "fit") == "validate" for e in exps):
        raise InputError("the dataset has no experiment with role 'validate': a report compares predictions at "
                         "temperatures the models were not identified on")
    for e in entries:
        if e.validation is None:
            e.validation = validate(e.model, data)
    figs = Figures(figures_dir)
    parts = []
    parts.append(_cards(entries, exps))
    warns = _warnings(entries)
    if warns:
        parts.append("<section><h2>Warnings</h2>" + "".join(f'<div class="warn">{html.escape(w)}</div>'
                                                           for w in dict.fromkeys(warns)) + "</section>")
    groups = akaike(entries)[1]
    parts.append("<section><h2>Model comparison</h2>" +
                 html_table(COMPARISON_COLUMNS, comparison_rows(entries), text=(1,)) +
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
    parts.append(_errors_section(entries))
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


def _cards(entries, exps) -> str:
    """The page's head: the best model on held-out temperatures, the experiments, the identification times."""
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
    return f'<div class="cards">{card_html}</div>'


def _warnings(entries) -> list:
    """Never silently, and in every report: a suspicious unit first, then a fit that misses the data or did not
    converge."""
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
    return sorted(warns, key=lambda w: SUSPICIOUS not in w)  # a unit 1000x off first: it explains the rest


def _errors_section(entries) -> str:
    """Each model's errors on each experiment."""
    rows = []
    for e in entries:
        for m in e.validation.experiments:
            rows.append([e.label, m["file"], fmt_number(m["temperature"], "{:.4g}"),
                         "held out" if m["role"] == "validate" else m["role"],
                         fmt_number(m["max_error_pct"]), fmt_number(m["rmse_offset_removed"] * 1e9, "{:.4g}"),
                         fmt_number(m["nrmse"]), fmt_number(m["final_error_pct"], "{:+.3g}"),
                         fmt_number(m["step_error_pct"])])
    return ("<section><h2>Errors per experiment</h2>" + html_table(
        EXPERIMENT_COLUMNS, rows, row_class=lambda r: "held" if r[3] == "held out" else "", text=(1, 3)) +
        "<p class='note'>e = x_sim − x_meas at each sample: the predicted minus the measured end-effector "
        "displacement, both starting from zero (the measurement's arbitrary zero matched on the first 1 % "
        "of the run). Held-out rows are shaded.</p>" + definitions(*EXPERIMENT_COLUMNS[4:]) + "</section>")


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
                                fmt_number(100 * max(abs(r["value"] - r["truth"]) for r in mine) / scale, "{:.2g}"),
                                fmt_number(100 * max((r["upper"] - r["lower"]) / 2 for r in mine) / scale, "{:.2g}")])
            parts.append(html_table(["parameter", "covered", "largest error [% of the truth's largest value]",
                                 "largest interval half-width [%]"], summary, text=(0,)))
            detail = [[r["parameter"], fmt_number(r["temperature"], "{:.4g}"), fmt_number(r["truth"], "{:.5g}"),
                       fmt_number(r["value"], "{:.5g}"), f"[{r['lower']:.5g}, {r['upper']:.5g}]",
                       "yes" if r["covered"] else "NO"] for r in rows]
            parts.append("<details><summary>every (parameter, temperature) point</summary>" +
                         html_table(["parameter", "temperature [°C]", "truth", "fitted", "95 % interval", "covered"],
                                detail, text=(0, 5)) + "</details>")
    return ("<section><h2>Against the truth</h2><p class='note'>These data were made by simulation from a known "
            "model: each fitted law at the fit temperatures, with its 95 % interval (delta method over the fitted "
            "coefficients and breakpoints), against the truth. About 1 point in 20 outside its interval is what a "
            "95 % interval means.</p>" + "".join(parts) + "</section>")


__all__ = ["render", "truth_section"]
