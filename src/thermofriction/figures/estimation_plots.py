"""The figure of an online temperature estimate (``TemperatureEstimate.plot()``): the contact temperature
estimate with its 2-sigma band, and the friction estimate, against time; in the visual language of plots.py."""

from __future__ import annotations

import numpy as np

from .plots import HALF, WIDE, new_figure, styled, thin
from .units import scaled_axis


@styled
def estimate_figure(result):
    """The estimate with its 2-sigma band, and the friction estimate, of a TemperatureEstimate against time."""
    fig, axes = new_figure(WIDE, HALF * 0.75, nrows=1, ncols=2)
    (a, b) = axes[0]
    t, T, s2 = result.time, result.temperature, 2.0 * np.sqrt(result.variance)
    a.fill_between(*thin(t, T - s2), np.interp(thin(t, T - s2)[0], t, T + s2), color="#d62728", alpha=0.2,
                   lw=0, label="2 sigma")
    a.plot(*thin(t, T), color="#d62728", label="estimate")
    a.set_xlabel("time [s]")
    a.set_ylabel("temperature [°C]")
    a.set_title("contact temperature estimate")
    k = scaled_axis(b, "y", result.friction, "friction estimate", "N")
    b.plot(*thin(t, result.friction * k), color="#1f77b4")
    b.set_xlabel("time [s]")
    b.set_title("friction estimate")
    return fig


__all__ = ["estimate_figure"]
