"""Figures of friction against time and against displacement: a simulation result's panels over time and its
hysteresis (friction against displacement), and force data's measured and predicted friction against the
measured position; in the visual language of plots.py, with units chosen from the data (units.py)."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .plots import HALF, MODEL_COLOURS, WIDE, legend, new_figure, styled, thin
from .units import plain, scaled_axis

#: the friction axis of a run whose few short spikes (a stick-slip sawtooth's flyback) would set its scale is
#: cut to these percentiles of the samples, widened by ROBUST_PAD of their span, and says so on the panel
ROBUST_PERCENTILES = (1.0, 99.0)
ROBUST_PAD = 0.25
#: the most points a hysteresis line is drawn with (evenly strided beyond: a loop keeps its order)
MAX_LOOP_POINTS = 20_000


def robust_ylim(ax, y, unit_name=""):
    """Cuts ``ax``'s y range to the central ROBUST_PERCENTILES of ``y`` (already scaled) when values outside
    them reach more than the central span beyond it (short spikes dominating the panel); notes the cut and the
    peaks on the panel. Returns True when it cut."""
    y = np.asarray(y, float)
    y = y[np.isfinite(y)]
    if y.size < 10:
        return False
    lo, hi = np.percentile(y, ROBUST_PERCENTILES)
    span = hi - lo
    if not span > 0 or (y.max() - hi <= span and lo - y.min() <= span):
        return False
    ax.set_ylim(lo - ROBUST_PAD * span, hi + ROBUST_PAD * span)
    u = f" {unit_name}" if unit_name else ""
    ax.text(0.995, 0.98, f"range cut to the {ROBUST_PERCENTILES[0]:g}–{ROBUST_PERCENTILES[1]:g} % percentiles; "
            f"peaks {y.min():.3g} to {y.max():.3g}{u} not shown", transform=ax.transAxes, ha="right", va="top",
            fontsize=8, color="0.3", bbox={"facecolor": "white", "edgecolor": "none", "alpha": 0.8, "pad": 1})
    return True


def _temperature_text(T) -> str:
    T = np.asarray(T, float)
    T = T[np.isfinite(T)]
    if T.size == 0:  # a model without a thermal part, simulated without a temperature
        return ""
    lo, hi = float(np.min(T)), float(np.max(T))
    return f"{lo:.1f} °C" if hi - lo < 0.05 else f"{lo:.1f}–{hi:.1f} °C"


def simulation_title(result) -> str:
    """The model's name (or "simulation") and the temperature, e.g. "li2009-model-i at 35.0 °C"."""
    name = getattr(result, "model_name", None) or "simulation"
    T = _temperature_text(result.temperature)
    return f"{name} at {T}" if T else name


def _units(result):
    """(displacement, velocity, force) SI units of a result: rotary plants' in angles and torques."""
    return ("rad", "rad/s", "N m") if getattr(result, "rotary", False) else ("m", "m/s", "N")


def _panels(result):
    x, v, f = _units(result)
    return {"input": ("input", result.input_unit), "displacement": ("displacement", x),
            "velocity": ("velocity", v), "friction_force": ("friction torque" if f == "N m" else "friction force", f),
            "temperature": ("temperature", "°C"), "relative_displacement": ("x_e − x_p", x),
            "stage_displacement": ("stage displacement", x)}


@styled
def simulation_figure(result, what=None, title=None):
    """A simulation result against time: input, displacement, friction force, and the temperature when it
    changes (``what`` picks the panels by field name); ``what="hysteresis"``: the friction against the
    displacement instead (hysteresis_figure). Units from the data; the friction panel's range cut to its
    central percentiles when a sawtooth's flyback spikes would set it (said on the panel)."""
    if isinstance(what, str) and what == "hysteresis":
        return hysteresis_figure(result, title=title)
    panels = [what] if isinstance(what, str) else list(what) if what else ["input", "displacement", "friction_force"]
    if what is None and np.ptp(result.temperature) > 1e-9:
        panels.append("temperature")
    names = _panels(result)
    for p in panels:
        if p not in names or getattr(result, p, None) is None:
            raise InputError(f"what: cannot plot {p!r}: choose 'hysteresis' or from "
                             f"{', '.join(k for k in names if getattr(result, k, None) is not None)}")
    fig, axes = new_figure(9.0, 1.9 * len(panels) + 0.8, nrows=len(panels), ncols=1, sharex=True)
    for ax, p in zip(axes[:, 0], panels):
        quantity, unit = names[p]
        y = getattr(result, p)
        both = [y, result.stage_displacement] if p == "displacement" and result.stage_displacement is not None else [y]
        k = scaled_axis(ax, "y", np.concatenate(both), quantity, unit)
        ax.plot(*thin(result.time, y * k, 1500), lw=1.1, color=MODEL_COLOURS[0])
        if len(both) > 1:
            ax.plot(*thin(result.time, both[1] * k, 1500), lw=0.9, color="0.55", label="stage")
            ax.lines[0].set_label("end effector")
            legend(ax, loc="best")
        if p == "friction_force":
            robust_ylim(ax, y * k, ax.get_ylabel().rsplit("[", 1)[-1].rstrip("]"))
    axes[-1, 0].set_xlabel("time [s]")
    plain(axes[-1, 0], "x")
    fig.suptitle(title or simulation_title(result))
    return fig


def _strided(*arrays, n=MAX_LOOP_POINTS):
    stride = max(len(arrays[0]) // n, 1)
    return [np.asarray(a)[::stride] for a in arrays]


@styled
def hysteresis_figure(result, title=None):
    """A simulation's friction force against displacement: against x_e − x_p (the sliding between stage and
    end effector, where the friction acts) for stick-slip plants, against the displacement otherwise. The
    friction axis is cut like the time plot's when short spikes would set it."""
    x_u, _, f_u = _units(result)
    stage = result.stage_displacement is not None
    x = result.relative_displacement if stage else result.displacement
    fig, axes = new_figure(HALF + 0.6, 4.4)
    ax = axes[0, 0]
    kx = scaled_axis(ax, "x", x, "x_e − x_p (sliding)" if stage else "displacement", x_u)
    ky = scaled_axis(ax, "y", result.friction_force, "friction torque" if f_u == "N m" else "friction force", f_u)
    xs, fs = _strided(x, result.friction_force)
    ax.plot(xs * kx, fs * ky, "-", lw=1.0, color=MODEL_COLOURS[0], label="friction")
    ax.plot([xs[0] * kx], [fs[0] * ky], "o", ms=5, color="k", label="start", zorder=3)
    legend(ax, loc="lower right")
    ax.set_title(title or simulation_title(result))
    return fig


def force_units(predictions):
    """(position, force) SI units of force predictions: rotary data's rad and N m."""
    rotary = bool(predictions) and predictions[0].unit == "N m"
    return ("rad", "N m") if rotary else ("m", "N")


@styled
def force_hysteresis_figure(validation, files=None, max_panels=4, title=None, label=None):
    """Force data: measured (markers) and predicted (line) friction against the measured position, one panel
    per experiment (``files``, or held-out experiments first, at most ``max_panels``)."""
    preds = list(validation.predictions)
    if not preds or not hasattr(preds[0], "position"):
        raise InputError("a hysteresis view needs force (torque) data: measured friction against position")
    shown = [p for p in preds if p.file in files] if files else \
        sorted(preds, key=lambda p: (p.role != "validate", p.temperature))[:max_panels]
    x_u, f_u = force_units(preds)
    what = "torque" if f_u == "N m" else "force"
    cols = min(len(shown), 2)
    rows = -(-len(shown) // cols)
    fig, axes = new_figure(WIDE if cols > 1 else HALF + 0.6, 3.6 * rows + 0.6, nrows=rows, ncols=cols)
    for ax, p in zip(axes.flat, shown):
        draw_force_hysteresis(ax, p, x_u, f_u, what)
    for ax in axes.flat[len(shown):]:
        ax.set_visible(False)
    legend(axes.flat[0], loc="best")
    label = label or getattr(validation.model, "name", None) or "model"
    fig.suptitle(title or f"{label}: friction {what} against position")
    return fig


def draw_force_hysteresis(ax, p, x_u, f_u, what="force"):
    """One force experiment: measured friction (markers, ~1500) and predicted (line) against the position."""
    kx = scaled_axis(ax, "x", p.position, "position", x_u)
    ky = scaled_axis(ax, "y", np.concatenate([p.measured, p.predicted]), f"friction {what}", f_u)
    xm, fm = _strided(p.position, p.measured, n=1500)
    ax.plot(xm * kx, fm * ky, "o", ms=2.2, mfc="none", color="0.45", mew=0.6, label="measured")
    xp, fp = _strided(p.position, p.predicted)
    ax.plot(xp * kx, fp * ky, "-", lw=1.1, color=MODEL_COLOURS[0], label="predicted")
    ax.set_title(f"{p.file}, {p.temperature:.1f} °C" + (" (held out)" if p.role == "validate" else ""))


def force_overview(fig, validation):
    """Force data in one row of ``fig`` (a figure or subfigure): one experiment (the first held out, else the
    first) measured and predicted over time, and against the position."""
    preds = sorted(validation.predictions, key=lambda p: (p.role != "validate", p.temperature))
    p = preds[0]
    x_u, f_u = force_units(preds)
    what = "torque" if f_u == "N m" else "force"
    a = fig.subplots(1, 2)
    k = scaled_axis(a[0], "y", np.concatenate([p.measured, p.predicted]), f"friction {what}", f_u)
    tm, fm = _strided(p.time, p.measured, n=1500)
    a[0].plot(tm, fm * k, "o", ms=2.2, mfc="none", color="0.45", mew=0.6, label="measured")
    a[0].plot(*thin(p.time, p.predicted * k, 1500), "-", lw=1.1, color=MODEL_COLOURS[0], label="predicted")
    a[0].set_xlabel("time [s]")
    a[0].set_title("over time")
    legend(a[0], loc="best")
    draw_force_hysteresis(a[1], p, x_u, f_u, what)
    a[1].set_title("against position")
    fig.suptitle(f"{p.file}, {p.temperature:.1f} °C" + (" (held out)" if p.role == "validate" else ""))
    return a


__all__ = ["force_overview", "simulation_figure", "hysteresis_figure", "force_hysteresis_figure", "draw_force_hysteresis",
           "robust_ylim", "simulation_title", "ROBUST_PERCENTILES"]
