"""Figures as matplotlib ``Figure`` objects: one implementation for the HTML report and for the
``.plot()`` methods of simulation, identification and validation results.

Figures are made without pyplot (``matplotlib.figure.Figure``): making one never opens a window
or changes the user's backend, a notebook shows a returned figure once, and ``fig.savefig(...)``
writes it. Every figure uses one visual language:

- temperatures the model was fitted to: a sequential colour scale (viridis), solid lines, filled markers;
- held-out temperatures: their own colours (reds), dashed lines, open markers, and on temperature
  axes a pale red band;
- models: one colour each (blue, green, purple, ...), the same in every figure;
- the paper's values: grey, dashed.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from .units import scaled_axis

#: font sizes in points; the report draws each figure at its own size (a point is 1.33 px: 9 pt legend text is
#: 12 px on the page), shrunk only where the page is narrower than the figure
STYLE = {"font.size": 10, "axes.titlesize": 11, "axes.labelsize": 10.5, "xtick.labelsize": 9.5,
         "ytick.labelsize": 9.5, "legend.fontsize": 9, "legend.title_fontsize": 9.5, "axes.grid": True,
         "grid.alpha": 0.3, "axes.spines.top": False, "axes.spines.right": False, "legend.frameon": False,
         "svg.fonttype": "none", "figure.dpi": 100, "axes.formatter.useoffset": False}
WIDE = 11.0                      # a full-width figure [in]: the widest the report's card holds (~1070 px)
HALF = 5.6                       # one of two side by side [in]
PANEL = 3.4                      # one panel of a grid [in]
KEY = 1.8                        # a legend outside on the right [in]
MODEL_COLOURS = ("#1f77b4", "#2ca02c", "#9467bd", "#8c6d31", "#17becf", "#7f7f7f")
HELD_OUT_COLOURS = ("#d62728", "#ff7f0e", "#e377c2", "#8c564b")
HELD_OUT_BAND = "#f7c6c5"
PAPER = dict(color="#555555", ls="--", lw=1.2)
#: Li et al. (2009) report maximum prediction errors of 7-8 % for their models on the real actuator
PAPER_ERROR_PCT = (7.0, 8.0)
#: the paper's band is drawn (unless asked for or against) when the largest max error shown reaches this [%]:
#: errors on the band's scale; smaller ones would be squashed into the bottom of a panel that reaches 8 %
PAPER_BAND_FROM_PCT = 2.0


def styled(fn):
    """Runs a figure function inside the report's style (rcParams are read as artists are made)."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        import matplotlib
        with matplotlib.rc_context(STYLE):
            return fn(*args, **kwargs)
    return wrapper


def new_figure(width, height, **subplots):
    """A pyplot-free figure with constrained layout and its axes (``squeeze=False``)."""
    from matplotlib.figure import Figure
    fig = Figure(figsize=(width, height), layout="constrained")
    if subplots.pop("none", False):
        return fig, None
    return fig, fig.subplots(squeeze=False, **subplots)


def thin(t, y, n=600):
    """At most ~2n points that keep each bucket's minimum and maximum: a 20 000-sample curve draws
    the same in a panel a few hundred pixels wide, in a fraction of the file size."""
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


# -- the visual language -----------------------------------------------------------------------

def is_held_out(role) -> bool:
    return role == "validate"


def temperature_styles(pairs):
    """(temperature, role) -> line and marker style: fit temperatures on viridis by value, held-out
    ones in reds, dashed, with open markers."""
    import matplotlib
    fit = sorted({float(T) for T, r in pairs if not is_held_out(r)})
    held = sorted({float(T) for T, r in pairs if is_held_out(r)})
    cmap = matplotlib.colormaps["viridis"]
    lo, hi = (min(fit), max(fit)) if fit else (0.0, 1.0)
    out = {}
    for T in fit:
        c = cmap(0.05 + 0.8 * ((T - lo) / (hi - lo) if hi > lo else 0.5))
        out[(T, "fit")] = dict(color=c, ls="-", lw=1.3, marker="o", mfc=c, ms=3.2, label=f"{T:.1f} °C", held=False)
    for i, T in enumerate(held):
        c = HELD_OUT_COLOURS[i % len(HELD_OUT_COLOURS)]
        out[(T, "validate")] = dict(color=c, ls="--", lw=2.0, marker="s", mfc="none", ms=4.5,
                                    label=f"{T:.1f} °C, held out", held=True)
    return out


def style_of(styles, T, role):
    return styles[(float(T), "validate" if is_held_out(role) else "fit")]


def temperature_key(fig, styles, title="temperature", extra=()):
    """One legend for the figure, outside on the right: fit temperatures, then held-out ones."""
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], color=s["color"], ls=s["ls"], lw=s["lw"], marker=s["marker"], mfc=s["mfc"],
                      ms=s["ms"] + 1, label=s["label"])
               for _, s in sorted(styles.items(), key=lambda kv: (kv[1]["held"], kv[0][0]))]
    legend(fig, list(handles) + list(extra), title=title, loc="outside right upper")


def mark_held_out(ax, temperatures, label=True):
    """Pale red bands at held-out temperatures on a temperature axis."""
    for i, T in enumerate(sorted(set(temperatures))):
        ax.axvspan(T - 0.15, T + 0.15, color=HELD_OUT_BAND, alpha=0.6, lw=0, zorder=0,
                   label="held-out temperature" if (label and i == 0) else None)


def panels_width(cols, key=True) -> float:
    """A figure's width [in] from its number of panel columns (and a legend on the right): a single panel is not
    stretched to the page's width (it gets HALF, the pair's width, so that the plot and not its legend fills the
    figure); at most WIDE."""
    return min(WIDE, max(PANEL * cols, HALF) + (KEY if key else 0.3))


def legend(target, handles=None, **kwargs):
    """One legend on ``target`` (a Figure, SubFigure or Axes) with one entry per label: ``handles``, or every
    labelled artist of its axes; a label met again (the same model in two panels) is dropped, the first kept."""
    if handles is None:
        axes = target.get_axes() if hasattr(target, "get_axes") else [target]  # a figure's, or the axes alone
        handles = [h for ax in axes for h in ax.get_legend_handles_labels()[0]]
    first = {}
    for h in handles:
        label = str(h.get_label())
        if label and not label.startswith("_"):
            first.setdefault(label, h)
    return target.legend(handles=list(first.values()), labels=list(first), **kwargs)


def panel_grid(n, per_row=3):
    cols = min(n, per_row)
    return math.ceil(n / cols), cols


def hide_unused(axes, n):
    for ax in axes.flat[n:]:
        ax.set_visible(False)


# -- measured against predicted --------------------------------------------------------------

def _predictions(entries):
    """[(label, [Prediction])] from [(label, ValidationResult)]."""
    return [(label, list(v.predictions)) for label, v in entries]


def draw_displacement(ax, predictions, styles, markers=None, points=400):
    """Measured displacement (markers, ~``markers`` per trace: by default 60, fewer when there are
    many traces, ~600 in a panel) and predicted (lines) per experiment."""
    markers = markers or int(np.clip(600 // max(len(predictions), 1), 20, 60))
    order = sorted(predictions, key=lambda p: (is_held_out(p.role), p.temperature))
    # the unit from the measurements alone: every model's panel of the same data draws in the same one
    k = scaled_axis(ax, "y", np.concatenate([p.measured for p in order]) if order else [], "displacement", "m")
    for p in order:
        s = style_of(styles, p.temperature, p.role)
        stride = max(len(p.time) // markers, 1)
        z = 3 if s["held"] else 2
        ax.plot(p.time[::stride], p.measured[::stride] * k, ls="none", marker=s["marker"], ms=s["ms"],
                mfc=s["mfc"], mec=s["color"], mew=0.9, zorder=z)
        ax.plot(*thin(p.time, p.predicted * k, points), ls=s["ls"], lw=s["lw"], color=s["color"], zorder=z + 0.5)
    ax.set_xlabel("time [s]")


def window_rms(time, residual, windows=50):
    """(window centres, RMS of the residual in each of ``windows`` equal windows of the run)."""
    time, residual = np.asarray(time), np.asarray(residual)
    edges = np.linspace(0, len(time), min(windows, len(time)) + 1).astype(int)
    centres = np.array([0.5 * (time[a] + time[b - 1]) for a, b in zip(edges[:-1], edges[1:])])
    rms = np.array([math.sqrt(float(np.mean(residual[a:b] ** 2))) for a, b in zip(edges[:-1], edges[1:])])
    return centres, rms


def noise_level(predictions):
    """The measurement noise estimated from the data (median over the experiments), or None."""
    vals = [float(p.fit_quality["noise"]) for p in predictions
            if p.fit_quality and p.fit_quality.get("noise") is not None
            and math.isfinite(float(p.fit_quality["noise"]))]
    return float(np.median(vals)) if vals else None


def draw_residuals(ax, predictions, styles, windows=50):
    """RMS of predicted - measured in short windows, one line per experiment, with the noise level."""
    rms = [(p, *window_rms(p.time, p.predicted - p.measured, windows))
           for p in sorted(predictions, key=lambda p: (is_held_out(p.role), p.temperature))]
    noise = noise_level(predictions)
    k = scaled_axis(ax, "y", np.concatenate([r for _, _, r in rms] + [[noise or 0.0]]), "RMS(predicted − measured)",
                    "m")
    for p, t, r in rms:
        s = style_of(styles, p.temperature, p.role)
        ax.plot(t, r * k, ls=s["ls"], lw=s["lw"], color=s["color"], zorder=3 if s["held"] else 2)
    if noise:
        ax.axhline(noise * k, color="k", ls=":", lw=1.2, zorder=4)
        ax.annotate("noise", (1.0, noise * k), xycoords=("axes fraction", "data"), xytext=(-2, 3),
                    textcoords="offset points", ha="right", va="bottom", fontsize=9)
    ax.set_ylim(bottom=0)
    ax.set_xlabel("time [s]")


def noise_handle():
    from matplotlib.lines import Line2D
    return Line2D([], [], color="k", ls=":", lw=1.2, label="measurement noise\n(estimated from the data)")


def _style_handles():
    from matplotlib.lines import Line2D
    return [Line2D([], [], color="0.3", ls="none", marker="o", ms=4, label="markers: measured"),
            Line2D([], [], color="0.3", ls="-", lw=1.3, label="lines: predicted")]


def _panel_per_model(entries, row_height, draw, key_extra, **subplots):
    """One panel per model ([(label, ValidationResult)]) drawn by ``draw(ax, predictions, styles)``,
    the y label on the first column only, one temperature key for the figure."""
    preds = _predictions(entries)
    styles = temperature_styles([(p.temperature, p.role) for _, ps in preds for p in ps])
    rows, cols = panel_grid(len(preds))
    fig, axes = new_figure(panels_width(cols), row_height * rows + 0.4, nrows=rows, ncols=cols, **subplots)
    for ax, (label, ps) in zip(axes.flat, preds):
        draw(ax, ps, styles)
        ax.set_title(label)
    for ax in axes[:, 1:].flat:  # the label once per row, unless a panel's unit differs from the row's first
        if ax.get_ylabel() == axes[0, 0].get_ylabel():
            ax.set_ylabel("")
    hide_unused(axes, len(preds))
    temperature_key(fig, styles, extra=key_extra)
    return fig


@styled
def displacement_figure(entries):
    """Measured and predicted displacement, one panel per model: [(label, ValidationResult)]."""
    return _panel_per_model(entries, 3.5, draw_displacement, _style_handles(), sharey=True)


@styled
def residual_figure(entries):
    """Windowed RMS residuals, one panel per model: [(label, ValidationResult)]."""
    return _panel_per_model(entries, 3.2, draw_residuals, [noise_handle()])


# -- against temperature ---------------------------------------------------------------------

def _by_temperature(predictions, value):
    T = np.array([p.temperature for p in predictions], float)
    v = np.array([value(p) for p in predictions], float)
    held = np.array([is_held_out(p.role) for p in predictions])
    order = np.argsort(T, kind="stable")
    return T[order], v[order], held[order]


def _fit_held_handles(color="0.3"):
    from matplotlib.lines import Line2D
    return [Line2D([], [], color=color, ls="none", marker="o", ms=6, label="fit temperature"),
            Line2D([], [], color=color, ls="none", marker="D", mfc="none", mew=1.6, ms=7, label="held out")]


def _points(ax, T, v, held, color, label, line=True):
    ok = np.isfinite(v)
    if line:
        ax.plot(T[ok], v[ok], "-", color=color, lw=1.3, label=label, zorder=2)
    ax.plot(T[~held & ok], v[~held & ok], "o", ms=6, color=color, zorder=3, label=None if line else label)
    ax.plot(T[held & ok], v[held & ok], "D", ms=7, color=color, mfc="white", mec=color, mew=1.8, zorder=4)


METRIC_LABELS = {"max_error_pct": "max error [%]", "final_error_pct": "final error [%]",
                 "step_error_pct": "step error [%]", "nrmse": "NRMSE", "rmse": "RMSE [nm]"}


def draw_errors(ax, entries, metric="max_error_pct", paper=None):
    """One line per model of ``metric`` against temperature; fit temperatures filled circles,
    held-out ones open diamonds on a pale red band; for the max error the paper's 7-8 % as a grey band
    when ``paper`` is True, or (None) when the errors reach PAPER_BAND_FROM_PCT: errors on its scale."""
    if metric not in METRIC_LABELS:
        raise ValueError(f"unknown metric {metric!r}: choose from {', '.join(METRIC_LABELS)}")
    values = []
    held_T = set()
    for i, (label, v) in enumerate(entries):
        T, e, held = _by_temperature(v.predictions, lambda p: p.rmse * 1e9 if metric == "rmse" else getattr(p, metric))
        if metric == "final_error_pct":
            e = np.abs(e)
        held_T |= set(T[held])
        values.extend(e[np.isfinite(e)])
        _points(ax, T, e, held, MODEL_COLOURS[i % len(MODEL_COLOURS)], label)
    mark_held_out(ax, held_T)
    if paper is None:
        paper = bool(values) and max(values) >= PAPER_BAND_FROM_PCT
    if paper and metric == "max_error_pct":
        ax.axhspan(*PAPER_ERROR_PCT, color="0.6", alpha=0.35, lw=0, zorder=1,
                   label="Li et al. (2009): 7–8 %")
        values.extend(PAPER_ERROR_PCT)
    pos = [x for x in values if x > 0]
    if pos and max(pos) / min(pos) > 30:  # models that differ by decades: each stays readable
        from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
        ax.set_yscale("log")
        ax.yaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.yaxis.set_minor_formatter(NullFormatter())
    else:
        ax.set_ylim(bottom=0)
    ax.set_xlabel("temperature [°C]")
    ax.set_ylabel(("|final error| [%]" if metric == "final_error_pct" else METRIC_LABELS.get(metric, metric)))
    handles, labels = ax.get_legend_handles_labels()
    below(ax, handles + _fit_held_handles())


def below(ax, handles):
    """The panel's legend under its x axis, in columns: nothing of the data hidden."""
    legend(ax, handles, loc="upper center", bbox_to_anchor=(0.5, -0.16), ncols=2 if len(handles) > 4 else 1)


@styled
def error_figure(entries, metric="max_error_pct", ax=None, width=HALF, paper=None, title=None):
    """Error against temperature for each model: [(label, ValidationResult)]; the paper's band as
    draw_errors says. Draws into ``ax`` when given (and returns its figure)."""
    if ax is not None:
        draw_errors(ax, entries, metric, paper)
        return ax.figure
    fig, axes = new_figure(width, 5.6)
    draw_errors(axes[0, 0], entries, metric, paper)
    axes[0, 0].set_title(title or f"{METRIC_LABELS[metric].split(' [')[0]} against temperature")
    return fig


@styled
def steps_figure(entries, width=HALF):
    """Mean step per cycle against temperature, measured and predicted by each model."""
    from matplotlib.lines import Line2D
    fig, axes = new_figure(width, 5.6)
    ax = axes[0, 0]
    preds = entries[0][1].predictions

    def mean_step(which):
        return lambda p: np.mean(getattr(p, which)) if getattr(p, which).size else np.nan
    T, meas, held = _by_temperature(preds, mean_step("measured_steps"))
    k = scaled_axis(ax, "y", meas, "mean step per cycle", "m")
    for i, (label, v) in enumerate(entries):
        Tm, pr, hm = _by_temperature(v.predictions, mean_step("predicted_steps"))
        _points(ax, Tm, pr * k, hm, MODEL_COLOURS[i % len(MODEL_COLOURS)], label)
    ax.plot(T[~held], meas[~held] * k, "o", ms=7, color="k", mfc="none", mew=1.6, zorder=5)
    ax.plot(T[held], meas[held] * k, "D", ms=8, color="k", mfc="none", mew=1.6, zorder=5)
    mark_held_out(ax, T[held])
    ax.set_xlabel("temperature [°C]")
    ax.set_title("mean step per cycle against temperature")
    handles, _ = ax.get_legend_handles_labels()
    handles.insert(0, Line2D([], [], color="k", mfc="none", mew=1.6, ls="none", marker="o", ms=7, label="measured"))
    below(ax, handles + _fit_held_handles())
    return fig


__all__ = ["STYLE", "displacement_figure", "residual_figure", "error_figure", "steps_figure",
           "temperature_styles", "window_rms"]
