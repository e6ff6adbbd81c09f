"""Figures of the studies beyond the paper, for their results' ``plot()``: a long heated run (temperature and
step per cycle against time) and a closed-loop run (position and tracking error against time); in the visual
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
    """Reference and position, and the tracking error, of a LoopResult against time."""
    fig, axes = new_figure(WIDE, HALF * 0.75, nrows=1, ncols=2)
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
    return fig


__all__ = ["heating_figure", "loop_figure"]
