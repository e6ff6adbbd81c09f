"""The figure of an uncertainty propagation (tf.propagate): the predicted displacement at each new
temperature with its bands, and the mean step per cycle against temperature with its band.

    fig = bands_figure(bands)              # a matplotlib Figure
    save_bands_figure(bands, "bands.svg")  # or .png; written atomically

Kept apart from the report module, which may embed it (``fig.savefig`` to SVG)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._io import atomic_write
from ..errors import InputError
from ..figures.plots import legend
from ..figures.units import scaled_axis


def bands_figure(result):
    """The bands drawn around the fitted model's prediction (their width is nanometres on
    micrometres of motion). Left: per temperature, the parameters' band minus the fitted model's
    displacement, over time (the band with the measurement noise is given in words). Right: the mean
    step per cycle's band minus the fitted model's step against temperature, each point labelled
    with the fitted model's step [um]."""
    import matplotlib
    from matplotlib.figure import Figure  # no pyplot: the caller's backend (a notebook's) is left alone

    temps = np.asarray(result.temperatures, float)
    cmap = matplotlib.colormaps["plasma"]
    span = float(np.ptp(temps)) or 1.0
    colors = [cmap(0.1 + 0.75 * (T - temps.min()) / span) for T in temps]
    fig = Figure(figsize=(10, 3.8))
    ax, bx = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.6, 1]})
    t = result.time
    level = f"{100 * result.level:g} %"
    k = scaled_axis(ax, "y", np.concatenate([np.ravel(result.lower - result.nominal),
                                             np.ravel(result.upper - result.nominal)]),
                    "displacement − fitted model's", "m")
    for j, T in enumerate(temps):
        c, nom = colors[j], result.nominal[j]
        ax.fill_between(t, (result.lower[j] - nom) * k, (result.upper[j] - nom) * k, color=c, alpha=0.45,
                        linewidth=0.6, edgecolor=c, label=f"{T:g} °C")
    ax.axhline(0, color="#1d2433", linewidth=0.8)
    ax.set_xlabel("time [s]")
    ax.set_title(f"{level} band of the prediction from the parameters' uncertainty", fontsize=9)
    if result.noise:  # far wider than the parameters' band as a rule: said, not drawn
        extra = float(np.max(result.prediction_upper - result.nominal)) * 1e9
        ax.text(0.01, 0.02, f"a new measurement adds the {result.noise * 1e9:.3g} nm sensor noise: "
                f"up to ±{extra:.3g} nm (prediction_lower/upper)", transform=ax.transAxes, fontsize=7,
                color="#4a5266")
    legend(ax, fontsize=8, frameon=False, ncol=min(len(temps), 4))
    ok = np.isfinite(result.nominal_step)
    if ok.any():
        order = np.argsort(temps)
        T, nom = temps[order], result.nominal_step[order]
        lo, hi = result.step_lower[order] - nom, result.step_upper[order] - nom
        ks = scaled_axis(bx, "y", np.concatenate([lo, hi]), "step per cycle − fitted model's", "m")
        lo, hi = lo * ks, hi * ks
        bx.fill_between(T, lo, hi, color="#f0a500", alpha=0.35, linewidth=0, label=f"{level} band")
        bx.plot(T, lo, T, hi, color="#f0a500", linewidth=0.8)
        bx.plot(T, np.zeros_like(T), "o-", color="#1d2433", markersize=4, linewidth=0.8, label="fitted model")
        for x, step in zip(T, nom):
            bx.annotate(f"{step * 1e6:.4g} µm", (x, 0), textcoords="offset points", xytext=(0, 6), ha="center",
                        fontsize=7, color="#4a5266")
        legend(bx, fontsize=8, frameon=False, loc="lower right")
    else:
        bx.text(0.5, 0.5, "no periodic input: no steps per cycle", ha="center", va="center",
                transform=bx.transAxes)
    bx.set_xlabel("temperature [°C]")
    bx.set_title(f"mean step per cycle, {result.draws - len(result.failures)} of {result.draws} draws", fontsize=9)
    for a in (ax, bx):
        a.grid(alpha=0.3)
        a.spines["top"].set_visible(False)
        a.spines["right"].set_visible(False)
    fig.tight_layout()
    return fig


def save_bands_figure(result, path):
    """Writes :func:`bands_figure` as SVG (or PNG when the name ends .png), atomically."""
    fig = bands_figure(result)
    fmt = "png" if str(path).lower().endswith(".png") else "svg"
    with atomic_write(Path(path), "wb") as fh:
        fig.savefig(fh, format=fmt, dpi=150, bbox_inches="tight")
    return path


def sweep_figure(result, metric=None, x=None):
    """A sweep's ``metric`` (default the first with a finite value) against the coordinate ``x`` (default the grid's first), one line
    per combination of the other coordinates (the first eight), failed points left out."""
    from matplotlib.figure import Figure  # no pyplot: the caller's backend (a notebook's) is left alone

    # default: the first metric with a finite value (a run shorter than a cycle has no mean step)
    finite = [m for m in result.metrics if np.isfinite(np.asarray(result[m], float)[result.ok]).any()]
    metric = metric or (finite or list(result.metrics))[0]
    x = x or result.coordinates[0]
    if metric not in result.metrics or x not in result.coordinates:
        raise InputError(f"plot: metric one of {', '.join(result.metrics)}, x one of {', '.join(result.coordinates)}")
    others = [c for c in result.coordinates if c != x]
    keys = [tuple(float(result[c][i]) for c in others) for i in range(len(result))]
    fig = Figure(figsize=(6.5, 3.8), layout="constrained")
    ax = fig.subplots()
    ok = result.ok
    for key in list(dict.fromkeys(keys))[:8]:
        rows = np.array([i for i, k in enumerate(keys) if k == key and ok[i]], int)
        label = ", ".join(f"{c} {v:g}" for c, v in zip(others, key)) or None
        ax.plot(result[x][rows], result[metric][rows], "o-", markersize=3, linewidth=0.9, label=label)
    ax.set_xlabel(result.header(x))
    ax.set_ylabel(result.header(metric))
    if metric not in finite:  # an empty axis says why
        ax.text(0.5, 0.5, f"no finite value of {metric} at any point", transform=ax.transAxes, ha="center",
                va="center", color="#8a4b00")
    if others:
        legend(ax, fontsize=8, frameon=False)
    ax.grid(alpha=0.3)
    return fig


def fleet_figure(result):
    """Each fitted parameter across a fleet, relative to its median (one column per parameter, one point per
    dataset), the outliers named."""
    from matplotlib.figure import Figure  # no pyplot: the caller's backend (a notebook's) is left alone

    s = result.summary()
    params, rows = result.parameter_table()
    fig = Figure(figsize=(max(4.0, 1.2 * len(params) + 2), 3.8))
    ax = fig.subplots()
    for j, p in enumerate(params):
        med = s["parameters"][p]["median"] or 1.0
        names = [n for n in rows if p in rows[n]]
        ax.plot(np.full(len(names), j), [rows[n][p] / med for n in names], "o", color="#1d2433", markersize=4)
        for o in s["parameters"][p]["outliers"]:
            ax.annotate(o["dataset"], (j, o["value"] / med), textcoords="offset points", xytext=(6, 0), fontsize=7)
    ax.set_xticks(range(len(params)), params)
    ax.set_ylabel("value / fleet median")
    ax.set_title(f"{s['identified']} of {s['datasets']} datasets identified ({result.method})", fontsize=9)
    ax.grid(alpha=0.3)
    return fig


__all__ = ["bands_figure", "save_bands_figure", "sweep_figure", "fleet_figure"]
