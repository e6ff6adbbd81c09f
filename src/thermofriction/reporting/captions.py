"""The figures of the main report, as HTML: each figure of figures/ (the one implementation, shared
with the results' ``.plot()``) rendered with a caption that says how to read it, and the
definitions of the metrics the report shows."""

from __future__ import annotations

import html

from ..models import ModelII
from ..figures import fit_plots, plots

#: every metric the report shows, defined where it is shown (docs/formats.md#validation-metrics);
#: e = x_sim − x_meas at each sample, x_meas zeroed so that the first 1 % of the run agrees on average
DEFINITIONS = {
    "max error [%]": "100 · max|e| / span, with e = x_sim − x_meas at each sample and span = max x_meas − "
                     "min x_meas: the paper's maximum prediction error (Li et al. 2009 report 7–8 %).",
    "RMSE [nm]": "the root mean square of e − mean(e): the error with the sensor's arbitrary zero removed, "
                 "as identification measures it.",
    "NRMSE": "RMSE / span: a fraction of the measured displacement's range, not a percentage.",
    "final error [%]": "100 · e_last / |x_meas,last − x_meas,first|: the error of the net displacement at the "
                       "end of the run, signed (positive: the model predicts too far).",
    "step error [%]": "100 · mean over whole input periods k of |s_sim,k − s_meas,k| / |mean s_meas,k|, where "
                      "s_k is the displacement over period k.",
    "max error, held out [%]": "the largest max error over the held-out experiments.",
    "mean max error, held out [%]": "the mean of the held-out experiments' max errors.",
    "RMSE, held out [nm]": "the root mean square of the held-out experiments' RMSEs.",
    "max error, fit [%]": "the largest max error over the experiments the model was fitted to.",
    "ΔAICc": "the fit's corrected Akaike information criterion minus the lowest among the fits of the same "
             "data: n ln(SSR/n) + 2k + 2k(k+1)/(n−k−1), n data points, k fitted parameters; below 2 the data "
             "hardly prefer the better fit, above 10 they rule the other out.",
    "Akaike weight": "exp(−ΔAICc/2), normalised to one over the fits of the same data: the weight of evidence "
                     "for each model among them.",
}


def definitions(*names) -> str:
    """The definitions of ``names`` as a definition list."""
    return ('<dl class="defs">' + "".join(f"<dt>{html.escape(n)}</dt><dd>{html.escape(DEFINITIONS[n])}</dd>"
                                          for n in names) + "</dl>")


def _pairs(entries):
    return [(e.label, e.validation) for e in entries]


def _held_out(entries):
    return sorted({p.temperature for e in entries for p in e.validation.predictions if p.role == "validate"})


def fig_errors(figs, entries):
    fig = plots.error_figure(_pairs(entries))
    band = any(str(p.get_label()).startswith("Li et al.") for p in fig.axes[0].patches)
    return figs.render(fig, "error-vs-temperature",
                       "Max error against temperature for each model: filled circles at the temperatures it was "
                       "fitted to, open diamonds on pale red bands at the held-out ones (never used in "
                       "identification). Max error = 100 · max|x_sim − x_meas| / (max x_meas − min x_meas), the "
                       "paper's maximum prediction error; " + (
                           "the grey band is the 7–8 % Li et al. (2009) report. " if band else
                           f"the 7–8 % Li et al. (2009) report is left out: every error here is below "
                           f"{plots.PAPER_BAND_FROM_PCT:g} %, and it would squash them. ") +
                       "A logarithmic axis where the models differ by decades.")


def fig_steps(figs, entries):
    return figs.render(plots.steps_figure(_pairs(entries)), "steps",
                       "Mean displacement per input period against temperature: measured (black) and predicted by "
                       "each model; open diamonds and pale red bands at the held-out temperatures.")


def fig_displacement(figs, entries):
    return figs.render(plots.displacement_figure(_pairs(entries)), "displacement",
                       "Measured (markers, a few dozen per run) and predicted (lines) end-effector displacement "
                       "at each temperature, as in the paper's Figs. 9–10. Temperatures the models were fitted to "
                       "in viridis colours, solid; held-out temperatures in reds, dashed, with open squares.")


def fig_residuals(figs, entries):
    return figs.render(plots.residual_figure(_pairs(entries)), "residuals",
                       "Residuals: the root mean square of predicted − measured displacement over each 2 % of the "
                       "run (measurement zeroed on the first 1 %), one line per experiment, coloured as above. "
                       "A model at the measurement noise lies on the dotted line; an error that builds up over the "
                       "run rises above it. (20 000 overlaid samples per trace would hide this; the RMS keeps it "
                       "legible per temperature.)")


def fig_model_i(figs, entry, held_out=()):
    if not entry.model.laws or not ((entry.fit or {}).get("details") or {}).get("per_temperature"):
        return ""
    paper = fit_plots.from_the_paper(entry.model)
    fig = fit_plots.laws_figure(entry.fit, entry.model, held_out, paper=paper)
    return figs.render(fig, "model-i-parameters",
                       f"{entry.label}: each parameter identified per temperature with its 95 % interval (an "
                       "orange triangle where the interval is open upwards: the data do not bound the parameter "
                       "there), the law fitted through those estimates (dotted), the law refined on all "
                       "experiments at once (solid; red rings where it leaves an interval)" +
                       (", and the paper's Eqs. (9)–(11) (grey, Figs. 3–5; the model was fitted from the paper's "
                        "preset)" if paper else "") + ". Pale red bands: held-out temperatures.")


def fig_model_ii(figs, entry, held_out=()):
    fit = entry.fit or {}
    det = fit.get("details") or {}
    alt = ((fit.get("alternatives") or {}).get("paper") or {}).get("details") or {}
    if not (det.get("paper") or alt.get("paper") or det.get("direct")) or not isinstance(entry.model.thermal, ModelII):
        return ""
    paper = fit_plots.from_the_paper(entry.model)
    fig = fit_plots.model_ii_figure(fit, entry.model, held_out, paper=paper)
    return figs.render(fig, "model-ii",
                       f"{entry.label}: the paper's procedure (net displacement against temperature with an "
                       "estimated breakpoint, Fig. 6; net displacement against dF by simulation, Fig. 7) where it "
                       "ran, and dF(T): fitted per temperature on the trajectories (direct, 95 % intervals), the "
                       "fitted piecewise-linear law with its breakpoints" +
                       (", and the paper's Eq. (13) (grey; the model was fitted from the paper's preset)" if paper
                        else "") + ".")


__all__ = ["DEFINITIONS", "definitions", "fig_errors", "fig_steps", "fig_displacement", "fig_residuals",
           "fig_model_i", "fig_model_ii"]
