"""Figures of the studies beyond the paper, for their results' ``plot()``: a long heated run (temperature and
step per cycle against time) and a closed-loop run (position, tracking error, friction- and temperature-estimate
errors against time); in the visual
language of plots.py."""

from __future__ import annotations

import numpy as np

from .plots import HALF, WIDE, legend, new_figure, styled, thin
from .units import scaled_axis


@styled
def heating_figure(result):
    """Temperature and step per cycle of a HeatingResult against time."""
    fig, axes = new_figure(WIDE, HALF * 0.75, nrows=1, ncols=2)
    (a, b) = axes[0]
    a.plot(*thin(result.time, result.temperature), color="#d62728")
    a.set_xlabel("time [s]")
    a.set_ylabel("temperature [°C]")
    a.set_title("interface temperature")
    k = scaled_axis(b, "y", result.step_size, "step per cycle", "m")
    b.plot(*thin(result.time, np.asarray(result.step_size) * k), color="#1f77b4")
    b.set_xlabel("time [s]")
    b.set_title(f"step per cycle ({result.method})")
    return fig


@styled
def loop_figure(result):
    """Reference and position, and the tracking error, of a LoopResult against time; with compensation,
    the friction-estimate error (compensation minus the stage's friction), and where the compensation
    was told a temperature other than the stage's, the temperatures and the temperature-estimate error."""
    dF = result.friction_error if np.any(result.compensation) else None
    dT = result.temperature_error
    dT = dT if dT is not None and np.all(np.isfinite(dT)) and np.any(dT) else None
    rows = 1 + (dF is not None or dT is not None)
    fig, axes = new_figure(WIDE, HALF * 0.75 * rows, nrows=rows, ncols=2)
    (a, b) = axes[0]
    k = scaled_axis(a, "y", np.concatenate([result.reference, result.position]), "position", "m")
    a.plot(*thin(result.time, result.reference * k), color="0.5", ls="--", label="reference")
    a.plot(*thin(result.time, result.position * k), color="#1f77b4", label="position")
    a.set_xlabel("time [s]")
    a.set_title("tracking")
    legend(a, fontsize=8, frameon=False)
    k = scaled_axis(b, "y", result.error, "error", "m")
    b.plot(*thin(result.time, result.error * k), color="#d62728")
    b.set_xlabel("time [s]")
    unit = b.get_ylabel().rsplit("[", 1)[-1].rstrip("]")
    b.set_title(f"tracking error (RMS {result.rms_error * k:.3g} {unit})")
    if rows == 1:
        return fig
    c, d = axes[1]
    if dF is not None:
        k = scaled_axis(c, "y", dF, "compensation - friction", "N")
        c.plot(*thin(result.time, dF * k), color="#9467bd")
        c.set_title(f"friction-estimate error (RMS {np.sqrt(np.mean(dF ** 2)) * k:.3g} "
                    f"{c.get_ylabel().rsplit('[', 1)[-1].rstrip(']')})")
    else:
        c.set_visible(False)
    c.set_xlabel("time [s]")
    if dT is not None:
        d.plot(*thin(result.time, dT), color="#2ca02c")
        d.axhline(0.0, color="0.8", lw=0.8)
        d.set_ylabel("told - stage temperature [K]")
        d.set_title(f"temperature-estimate error (RMS {np.sqrt(np.mean(dT ** 2)):.3g} K)")
    else:
        d.plot(*thin(result.time, result.plant_temperature), color="#d62728", label="stage")
        d.set_ylabel("temperature [°C]")
        d.set_title("the stage's temperature (told to the compensation)")
    d.set_xlabel("time [s]")
    return fig


__all__ = ["heating_figure", "loop_figure"]
