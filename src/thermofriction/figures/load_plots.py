"""Figures over load (docs/force-data.md#loads): the friction-velocity map per load and the laws of temperature and
load over the load with their intervals. They draw what they are given (arrays computed by reporting/load.py), in
the colours of the temperatures."""

from __future__ import annotations

import numpy as np

from ..models.load_laws import LoadLaw

#: the most loads the map shows a panel for
MAX_LOAD_PANELS = 5


def temperature_colours(temps) -> dict:
    """Temperature -> colour (viridis by value, as the force report's)."""
    import matplotlib
    lo, hi = min(temps), max(temps)
    cmap = matplotlib.colormaps["viridis"]
    return {T: cmap(0.05 + 0.8 * ((T - lo) / (hi - lo) if hi > lo else 0.5)) for T in temps}


def _figure(n, width, height):
    from matplotlib.figure import Figure
    fig = Figure(figsize=(width * n + 0.6, height), layout="constrained")
    return fig, np.atleast_1d(fig.subplots(1, n, sharey=False, squeeze=False)[0])


def velocity_map_per_load(panels, labels, vlabel: str, flabel: str):
    """One panel per load: the measured friction against velocity (dots coloured by the runs' temperatures) and
    each model's steady-sliding curve at that load.

    Parameters
    ----------
    panels : list of dict
        Each: ``load`` (float), ``title`` (str), ``points`` [(temperature, velocity, friction)] and ``curves``
        [(label index, temperature, velocity, friction)], in the axes' units.
    labels : list of str
        The models' labels (the curves' index into it).
    vlabel, flabel : str
        The axes' labels.

    Returns
    -------
    matplotlib.figure.Figure
    """
    temps = sorted({p[0] for panel in panels for p in panel["points"]} | {c[1] for panel in panels
                                                                         for c in panel["curves"]})
    colour = temperature_colours(temps)
    styles = ["-", "--", ":", "-."]
    fig, axes = _figure(len(panels), 2.3, 3.2)
    for ax, panel in zip(axes, panels):
        for T, v, F in panel["points"]:
            ax.plot(v, F, ".", ms=1.5, alpha=0.3, color=colour[T])
        for i, T, v, F in panel["curves"]:
            ax.plot(v, F, styles[i % len(styles)], lw=1.3, color=colour[T],
                    label=f"{labels[i]}, {T:.4g} °C" if ax is axes[0] else None)
        ax.set_title(panel["title"], fontsize=9.5)
        ax.set_xlabel(vlabel)
    axes[0].set_ylabel(flabel)
    fig.legend(fontsize=9, frameon=False, loc="outside lower center", ncol=min(4, max(len(temps), 1)))
    return fig


def laws_over_load(laws, load_label: str, held_loads=()):
    """One panel per law: its value over the load at each temperature with the 95 % band, and the per-condition
    estimates with their 95 % intervals.

    Parameters
    ----------
    laws : list of dict
        Each: ``title`` (str), ``ylabel`` (str), ``lines`` [(temperature, loads, value, lower, upper)] and
        ``points`` [(temperature, load, value, half-width)].
    load_label : str
        The load axis's label.
    held_loads : sequence of float, default ()
        The held-out runs' loads, marked.

    Returns
    -------
    matplotlib.figure.Figure
    """
    temps = sorted({x[0] for law in laws for x in law["lines"]} | {x[0] for law in laws for x in law["points"]})
    colour = temperature_colours(temps)
    fig, axes = _figure(len(laws), 3.6, 3.2)
    for ax, law in zip(axes, laws):
        for T, L, v, lo, hi in law["lines"]:
            ax.fill_between(L, lo, hi, color=colour[T], alpha=0.2, lw=0)
            ax.plot(L, v, "-", lw=1.2, color=colour[T], label=f"{T:.4g} °C" if ax is axes[0] else None)
        for T, L, v, h in law["points"]:
            ax.errorbar([L], [v], yerr=[h], fmt="o", ms=3.5, mfc="white", color=colour[T], capsize=2)
        for L in held_loads:
            ax.axvline(L, color="0.5", lw=0.8, ls=":")
        ax.set_title(law["title"], fontsize=9)
        ax.set_xlabel(load_label)
        ax.set_ylabel(law["ylabel"])
    fig.legend(fontsize=9, frameon=False, loc="outside lower center", ncol=min(6, max(len(temps), 1)))
    return fig


def _covariance_of(fit, names):
    """The covariance of fitted coefficients ``names`` (zero rows for one held), from the fit's standard errors and
    correlation."""
    varying = [p.name for p in fit.parameters.varying]
    idx = [varying.index(n) if n in varying else None for n in names]
    se = np.array([0.0 if i is None else (fit.parameters[varying[i]].stderr or 0.0) for i in idx], float)
    C = np.zeros((len(names), len(names)))
    for a, i in enumerate(idx):
        for b, j in enumerate(idx):
            if i is not None and j is not None:
                C[a, b] = float(fit.correlation[i, j]) * se[a] * se[b]
    return np.nan_to_num(C)


def fit_laws_figure(fit, points: int = 60):
    """A fit's laws of temperature and load (``FitResult.plot`` where its details hold ``load``) over the load at
    each fit temperature, with 95 % bands by the delta method on the coefficients' covariance (the laws' own
    derivatives) and the per-condition estimates.

    Parameters
    ----------
    fit : FitResult
        The fit (``identify`` on runs at several loads).
    points : int, default 60
        The loads each line is drawn at.

    Returns
    -------
    matplotlib.figure.Figure
    """
    d = fit.details["load"]
    loads = [abs(x) for x in d["loads"]]
    grid = np.linspace(0.0, 1.1 * max(loads), points)
    conditions = d.get("conditions") or []
    temps = sorted({round(c["temperature"], 3) for c in conditions}) or sorted(
        {round(e["temperature"], 3) for e in fit.experiments})
    laws = []
    for name, law in fit.model.laws.items():
        if not isinstance(law, LoadLaw):
            continue
        C = _covariance_of(fit, [f"{name}.{c}" for c in law.coefficient_names()])
        lines = []
        for T in temps:
            v = np.array([law.value(T, L, warn=False) for L in grid])
            sd = np.sqrt([max(float(g @ C @ g), 0.0) for g in (law.coefficient_derivatives(T, L) for L in grid)])
            lines.append((T, grid, v, v - 1.96 * sd, v + 1.96 * sd))
        laws.append({"title": f"{name}: {law.load.kind}, {law.load.combine}", "ylabel": f"{name} [{fit.unit}]",
                     "lines": lines, "points": [(c["temperature"], c["load"], c["values"][name],
                                                 1.96 * c["stderr"][name]) for c in conditions]})
    return laws_over_load(laws, f"|load| [{fit.unit}]")


__all__ = ["velocity_map_per_load", "laws_over_load", "temperature_colours", "fit_laws_figure", "MAX_LOAD_PANELS"]
