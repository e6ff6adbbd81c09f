"""The force report's sections over load (docs/force-data.md#loads), where the runs span two loads or more: the
friction-velocity map per load (each model's steady sliding at that load: a model without laws of load draws the
same curve at every load, which is what load-blind looks like), the laws of temperature and load over the load with
their 95 % bands and the per-condition estimates the laws went through, and a table of the laws."""

from __future__ import annotations

import html
import math

import numpy as np

from ..figures.load_plots import MAX_LOAD_PANELS, laws_over_load, velocity_map_per_load
from ..identification.load_kinds import equation, form_of, law_value
from ..measurements import steady_state_curve
from ..measurements.command import implied_friction
from ..measurements.force_load import law_derivatives, model_at
from ..models.load_laws import load_laws
from .entries import _covariance
from .page import html_table, page_styled

#: two loads closer than this fraction of the larger are one load in the map
SAME_LOAD = 0.02


def distinct_loads(exps) -> list:
    """The runs' distinct loads, sorted (loads within SAME_LOAD of each other are one).

    Parameters
    ----------
    exps : list of ForceExperiment
        The runs.

    Returns
    -------
    list of float
    """
    out = []
    for L in sorted(float(e.load) for e in exps if getattr(e, "load", None) is not None):
        if not out or abs(L - out[-1]) > SAME_LOAD * max(abs(L), abs(out[-1])):
            out.append(L)
    return out


def _near(a, b) -> bool:
    return abs(a - b) <= SAME_LOAD * max(abs(a), abs(b))


def _curve(model, v, T, load):
    """A model's steady-sliding friction at (T, load) [its sensor offset included], or None where it cannot run."""
    try:
        m = model_at(model, T, load) if load_laws(model) else model
        return steady_state_curve(m, v, T) + model.plant.sensor_offset
    except Exception:  # noqa: BLE001 - a model that cannot run here: no curve, the rest of the page stays
        return None


@page_styled
def fig_map_per_load(figs, entries, exps, unit, vunit, what) -> str:
    """The friction-velocity map, one panel per load (at most MAX_LOAD_PANELS, spread over the loads)."""
    loads = distinct_loads(exps)
    if len(loads) > MAX_LOAD_PANELS:
        loads = [loads[i] for i in np.linspace(0, len(loads) - 1, MAX_LOAD_PANELS).round().astype(int)]
    top = max(float(np.max(np.abs(e.drive_velocity))) for e in exps)
    v = np.concatenate([-np.geomspace(top, top * 1e-3, 30), np.geomspace(top * 1e-3, top, 30)])
    panels = []
    for L in loads:
        at = [e for e in exps if getattr(e, "load", None) is not None and _near(float(e.load), L)]
        points = []
        for e in at:
            ve, Fe = implied_friction(entries[0].model, e)
            stride = max(len(e.time) // 800, 1)
            points.append((float(e.temperature), ve[::stride], Fe[::stride]))
        curves = []
        for i, entry in enumerate(entries):
            for T in sorted({float(e.temperature) for e in at}):
                F = _curve(entry.model, v, T, L)
                if F is not None:
                    curves.append((i, T, v, F))
        held = " (held out)" if all(getattr(e, "role", "fit") == "validate" for e in at) else ""
        panels.append({"load": L, "title": f"load {L:.3g} {unit}{held}", "points": points, "curves": curves})
    fig = velocity_map_per_load(panels, [e.label for e in entries], f"velocity [{vunit}]", f"friction {what} [{unit}]")
    return figs.render(fig, "velocity-map-load", f"The friction-velocity map at each load: measured points (dots, "
                       f"coloured by temperature) and each model's steady sliding {what} at that load and at the "
                       f"runs' temperatures (line styles: the models, in the legend's order; sensor offset "
                       f"included). A model without laws of load draws the same curve at every load.")


def _band(law, fit, name, T, loads):
    """(value, lower, upper) of a law over ``loads`` at T, its 95 % band from the fit's covariance (none where the
    fit does not give it)."""
    value = np.array([law_value(law, T, L) for L in loads])
    C = _covariance(fit or {}, [f"{name}.{c}" for c in law.coefficient_names()])
    if C is None:
        return value, value, value
    sd = np.array([math.sqrt(max(float(g @ C @ g), 0.0)) for g in (law_derivatives(law, T, L) for L in loads)])
    return value, value - 1.96 * sd, value + 1.96 * sd


@page_styled
def fig_laws_over_load(figs, entry, exps, unit) -> str:
    """One model's laws over the load at each fit temperature, with their bands and per-condition estimates."""
    loads = distinct_loads(exps)
    grid = np.linspace(0.0 if loads[0] >= 0 else loads[0] * 1.1, loads[-1] * 1.1, 60)
    fit = entry.fit or {}
    conditions = ((fit.get("details") or {}).get("load") or {}).get("conditions") or []
    temps = sorted({round(float(e.temperature), 3) for e in exps if getattr(e, "role", "fit") == "fit"})
    held = sorted({float(e.load) for e in exps if getattr(e, "role", "fit") == "validate"})
    laws = []
    for name, law in load_laws(entry.model).items():
        lines = [(T, grid, *_band(law, fit, name, T, grid)) for T in temps]
        points = [(c["temperature"], c["load"], c["values"][name], 1.96 * c["stderr"][name])
                  for c in conditions if name in c.get("values", {})]
        laws.append({"title": f"{name}: {form_of(law)}", "ylabel": f"{name} [{unit}]", "lines": lines,
                     "points": points})
    fig = laws_over_load(laws, f"|load| [{unit}]", held)
    return figs.render(fig, "load-laws", f"{entry.label}: the laws of temperature and load over the load at each fit "
                       f"temperature (lines) with their 95 % bands (the coefficients' covariance), the per-condition "
                       f"estimates with their 95 % intervals (circles), the held-out loads (dotted).")


def _law_rows(entries) -> list:
    rows = []
    for e in entries:
        for name, law in load_laws(e.model).items():
            T, L = law.range, law.load.range
            rows.append([e.label, name, form_of(law), equation(name, law),
                         "—" if T is None else f"{T[0]:.4g}–{T[1]:.4g}", "—" if L is None else f"{L[0]:.4g}–{L[1]:.4g}"])
    return rows


def load_sections(figs, entries, exps, unit, vunit, what) -> str:
    """The report's sections over load (module docstring); "" where the runs do not span two loads.

    Parameters
    ----------
    figs : Figures
        The page's figures.
    entries : list of Entry
        The models compared.
    exps : list of ForceExperiment
        The runs.
    unit, vunit : str
        The friction's and the velocity's unit.
    what : str
        "force" or "torque".

    Returns
    -------
    str
        HTML.
    """
    if len(distinct_loads(exps)) < 2:
        return ""
    parts = ["<section><h2>Friction–velocity map per load</h2>" + fig_map_per_load(figs, entries, exps, unit, vunit,
                                                                                    what) + "</section>"]
    rows = _law_rows(entries)
    if rows:
        laws = "".join(fig_laws_over_load(figs, e, exps, unit) for e in entries if load_laws(e.model))
        parts.append("<section><h2>Laws of temperature and load</h2>" + html_table(
            ["model", "parameter", "form", "law (T in °C, L the load)", "T range [°C]", f"|L| range [{unit}]"], rows)
            + laws + f"<p class='note'>{html.escape('L: the run load (' + unit + '), as the data files give it.')}</p>"
            + "</section>")
    return "".join(parts)


__all__ = ["load_sections", "distinct_loads"]
