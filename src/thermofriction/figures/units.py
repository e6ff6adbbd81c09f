"""Axis units chosen from the data: every figure draws SI values scaled to a prefix (m, mm, µm, nm; N, mN;
N m, mN m; ...) that makes its tick labels plain numbers between ~1 and 1000, with the unit in the axis label
and never matplotlib's offset or multiplier text ("1e6" above the axis)."""

from __future__ import annotations

import numpy as np

#: the prefixes each SI unit is drawn in, largest first: (factor of the SI unit, name)
PREFIXES = {
    "m": ((1.0, "m"), (1e-3, "mm"), (1e-6, "µm"), (1e-9, "nm")),
    "m/s": ((1.0, "m/s"), (1e-3, "mm/s"), (1e-6, "µm/s"), (1e-9, "nm/s")),
    "rad": ((1.0, "rad"), (1e-3, "mrad"), (1e-6, "µrad"), (1e-9, "nrad")),
    "rad/s": ((1.0, "rad/s"), (1e-3, "mrad/s"), (1e-6, "µrad/s")),
    "N": ((1.0, "N"), (1e-3, "mN"), (1e-6, "µN")),
    "N m": ((1.0, "N m"), (1e-3, "mN m"), (1e-6, "µN m")),
    "V": ((1.0, "V"), (1e-3, "mV")),
    "J": ((1.0, "J"), (1e-3, "mJ"), (1e-6, "µJ")),
    "N/m": ((1e6, "N/µm"), (1e3, "N/mm"), (1.0, "N/m")),
    "N s/m": ((1e6, "N s/µm"), (1e3, "N s/mm"), (1.0, "N s/m")),
    "N m/rad": ((1e3, "N m/mrad"), (1.0, "N m/rad")),
}


def unit_scale(values, unit):
    """(multiplier, unit name) that draws ``values`` [``unit``, SI] with the largest magnitude between 1 and
    1000 of the chosen prefix (the smallest prefix for smaller data, the unit itself for larger or for data
    all zero). Units without prefixes here (°C, %) are returned as they are, multiplier 1."""
    choices = PREFIXES.get(unit)
    v = np.asarray(values, float)
    v = np.abs(v[np.isfinite(v)])
    if not choices or v.size == 0 or not v.max() > 0:
        return 1.0, unit
    top = float(v.max())
    for factor, name in choices:
        if top >= factor * 0.9995:  # 999.6 µm reads as 1 mm after rounding: the larger unit
            return 1.0 / factor, name
    factor, name = choices[-1]
    return 1.0 / factor, name


def scaled_axis(ax, axis, values, quantity, unit):
    """Labels ``ax``'s x or y ``axis`` "quantity [prefixed unit]" chosen from ``values`` (SI) and returns the
    multiplier to draw them with; the axis shows plain numbers (no offset text)."""
    k, name = unit_scale(values, unit)
    getattr(ax, f"set_{axis}label")(f"{quantity} [{name}]" if name else quantity)
    plain(ax, axis)
    return k


def scaled_ticks(ax, axis, values, quantity, unit):
    """As scaled_axis, with the data left in SI: the tick labels are scaled instead (for panels drawn by many
    calls, e.g. error bars and laws). Returns the multiplier the labels use."""
    from matplotlib.ticker import FuncFormatter
    k, name = unit_scale(values, unit)
    getattr(ax, f"set_{axis}label")(f"{quantity} [{name}]" if name else quantity)
    if k != 1.0:
        getattr(ax, f"{axis}axis").set_major_formatter(FuncFormatter(lambda v, _: f"{v * k:.6g}"))
    else:
        plain(ax, axis)
    return k


def plain(ax, axis="both"):
    """No offset or multiplier text on ``ax``'s axis (a linear axis; log axes have neither)."""
    for a in ((ax.xaxis, ax.yaxis) if axis == "both" else (getattr(ax, f"{axis}axis"),)):
        f = a.get_major_formatter()
        if hasattr(f, "set_useOffset"):
            f.set_useOffset(False)
            f.set_scientific(False)


__all__ = ["PREFIXES", "unit_scale", "scaled_axis", "scaled_ticks", "plain"]
