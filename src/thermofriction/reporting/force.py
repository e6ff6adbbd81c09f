"""The report on force (torque) data (docs/force-data.md#report): a comparison of the friction models (AICc
differences among fits of the same data, errors on held-out experiments), measured against predicted force over
time, the friction-velocity map with the measured points and each model's steady-sliding curve, presliding
hysteresis loops where the motion reverses, errors per experiment and the identified parameters."""

from __future__ import annotations

import html
import math

import numpy as np

from ..errors import InputError
from ..fitting.shown import cells
from ..measurements import steady_state_curve
from ..measurements.command import implied_friction
from ..models import ModelI, ModelII
from ..plausible import SUSPICIOUS
from ..validation import validate
from .entries import akaike_scaled
from .load import distinct_loads, load_sections
from .page import Figures, fmt_number, html_table, page_html, page_styled, subplots
from ..figures.plots import legend
from ..figures.plots import thin as _thin
from ..figures.units import scaled_axis


def _colors(temps):
    """Temperature -> colour on the report's scale for temperatures (viridis, by value)."""
    import matplotlib
    lo, hi = min(temps), max(temps)
    cmap = matplotlib.colormaps["viridis"]
    return {T: cmap(0.05 + 0.8 * ((T - lo) / (hi - lo) if hi > lo else 0.5)) for T in temps}

#: At most this many experiments get their own panel of force over time, and this many reversals a loop.
MAX_PANELS = 4
MAX_LOOPS = 4


def _label(model) -> str:
    name = model.friction.description.title
    if isinstance(model.thermal, ModelI):
        return f"{name}, Model I"
    if isinstance(model.thermal, ModelII):
        return f"{name}, Model II"
    return name


def _units(exps):
    rotary = bool(exps[0].rotary)
    return ("N m", "rad/s", "rad", "torque") if rotary else ("N", "m/s", "m", "force")


@page_styled
def fig_force_time(figs, entries, unit, what):
    preds0 = entries[0].validation.predictions
    shown = sorted(preds0, key=lambda p: (p.role != "validate", p.temperature))[:MAX_PANELS]
    fig, axes = subplots(len(shown), 1, figsize=(8.5, 2.4 * len(shown) + 0.5), squeeze=False,
                             constrained_layout=True)
    for ax, p0 in zip(axes[:, 0], shown):
        stride = max(len(p0.time) // 400, 1)
        k = scaled_axis(ax, "y", p0.measured, what, unit)
        ax.plot(p0.time[::stride], p0.measured[::stride] * k, "o", ms=2.5, mfc="none", color="0.35", label="measured")
        for e in entries:
            p = next(q for q in e.validation.predictions if q.file == p0.file)
            ax.plot(*_thin(p.time, p.predicted * k), lw=1.1, label=e.label)
        ax.set_title(f"{p0.file}, {p0.temperature:.1f} °C" + (" (held out)" if p0.role == "validate" else ""),
                     fontsize=9)
    axes[-1, 0].set_xlabel("time [s]")
    legend(fig, fontsize=8, frameon=False, loc="outside lower center", ncol=len(entries) + 1)
    return figs.render(fig, "force-time", f"Measured (markers) and predicted (lines) friction {what} over time, "
                       f"the model's sensor offset included; held-out experiments first.")


@page_styled
def fig_velocity_map(figs, entries, exps, unit, vunit, what):
    fig, ax = subplots(figsize=(6.5, 4.2))
    temps = sorted({e.temperature for e in exps})
    col = _colors(temps)
    top = max(float(np.max(np.abs(e.drive_velocity))) for e in exps)
    measured = [implied_friction(entries[0].model, e) for e in exps]  # a drive's command: less the first model's J a
    kv = scaled_axis(ax, "x", [top], "velocity", vunit)
    kf = scaled_axis(ax, "y", np.concatenate([F for _, F in measured]), f"friction {what}", unit)
    for k, (e, (v_e, F_e)) in enumerate(zip(exps, measured)):
        stride = max(len(e.time) // 1500, 1)
        ax.plot(v_e[::stride] * kv, F_e[::stride] * kf, ".", ms=2, alpha=0.35, color=col[e.temperature],
                label="measured" if k == 0 else None)
    v = _map_velocities(exps, top)
    T_mid = float(np.median(temps))
    for k, e in enumerate(entries):
        try:
            F = steady_state_curve(e.model, v, T_mid) + e.model.plant.sensor_offset
        except Exception:  # noqa: BLE001 - a model that cannot run at this temperature: no curve, the rest stays
            continue
        ax.plot(v * kv, F * kf, "-", lw=1.4, label=f"{e.label}, steady sliding at {T_mid:.1f} °C")
    ax.set_title(f"friction–velocity map at {T_mid:.1f} °C")
    legend(ax, fontsize=7, frameon=False, loc="lower right")
    return figs.render(fig, "velocity-map", f"The friction-velocity map: measured points (dots, coloured by "
                       f"temperature, {min(temps):.1f}–{max(temps):.1f} °C) and each model's steady-sliding "
                       f"{what} (simulated at constant velocity; sensor offset included).")


def _map_velocities(exps, top):
    """The velocities a map's model curves are drawn at: the directions the data slide in only (one-way runs drew
    a negative branch the data never saw)."""
    v_all = np.concatenate([e.drive_velocity for e in exps])
    branches = [np.geomspace(top * 1e-3, top, 40)] if np.any(v_all > 1e-3 * top) else []
    if np.any(v_all < -1e-3 * top):
        branches.insert(0, -np.geomspace(top, top * 1e-3, 40))
    return np.concatenate(branches or [np.geomspace(top * 1e-3, top, 40)])


def reversals(position, n, excursion=0.05):
    """Up to ``n`` real reversals of a motion: turning points of ``position`` between which it travels at least
    ``excursion`` of its range both ways (a zigzag filter), with enough samples either side. Velocity sign flips
    would also pick the noise of a velocity at rest (1e-17 deg/s flips) and a quantised velocity's dither."""
    x = np.asarray(position, float)
    threshold = excursion * float(np.ptp(x)) if x.size else 0.0
    if threshold <= 0:
        return []
    turns, direction, extreme = [], 0, 0  # extreme: the farthest point since the last turn
    for i in range(1, len(x)):
        if direction == 0:  # until the motion has left its start by the threshold
            direction = 1 if x[i] - x[0] >= threshold else -1 if x[0] - x[i] >= threshold else 0
            extreme = i
        elif direction * (x[i] - x[extreme]) > 0:
            extreme = i
        elif direction * (x[extreme] - x[i]) >= threshold:
            turns.append(extreme)
            direction, extreme = -direction, i
    return [int(i) for i in turns if 5 <= i < len(x) - 5][:n]


@page_styled
def fig_loops(figs, entries, unit, xunit, what):
    """Force against position after each reversal: the presliding hysteresis, measured and predicted."""
    loops = []
    for p in entries[0].validation.predictions:
        for i in reversals(p.position, MAX_LOOPS - len(loops)):
            loops.append((p.file, i))
        if len(loops) >= MAX_LOOPS:
            break
    if not loops:
        return ""
    fig, axes = subplots(1, len(loops), figsize=(3.2 * len(loops), 3.2), squeeze=False, constrained_layout=True)
    for ax, (file, i) in zip(axes[0], loops):
        p0 = next(q for q in entries[0].validation.predictions if q.file == file)
        swing = abs(float(np.median(p0.measured[max(i - 20, 0):i])) - float(np.median(p0.measured[i + 1:i + 40])))
        # the window: from a little before the reversal to where the force has swung to its new level
        j = i
        while j < len(p0.measured) - 1 and abs(p0.measured[j] - p0.measured[i]) < 0.95 * swing and j - i < 400:
            j += 1
        a, b = max(i - (j - i) // 2 - 2, 0), min(j + (j - i) // 2 + 2, len(p0.time))
        x = p0.position[a:b] - p0.position[i]
        kx = scaled_axis(ax, "x", x, "position from the reversal", xunit)
        kf = scaled_axis(ax, "y", p0.measured[a:b], f"friction {what}", unit)
        ax.plot(x * kx, p0.measured[a:b] * kf, "o", ms=3, mfc="none", color="0.35", label="measured")
        for e in entries:
            p = next(q for q in e.validation.predictions if q.file == file)
            ax.plot(x * kx, p.predicted[a:b] * kf, "-", lw=1.2, label=e.label)
        ax.set_title(f"{file}\nt = {p0.time[i]:.3g} s", fontsize=8)
    for ax in axes[0][1:]:  # the y label once, unless a panel's unit differs
        if ax.get_ylabel() == axes[0][0].get_ylabel():
            ax.set_ylabel("")
    legend(axes[0][0], fontsize=7, frameon=False)
    return figs.render(fig, "presliding", f"Presliding: the {what} against the position around reversals of the "
                       f"motion, measured (markers) and predicted (lines); the loop's slope at the reversal is the "
                       f"bristle stiffness.")


@page_styled
def fig_hysteresis(figs, entries, unit, xunit, what):
    """The friction against the measured position over whole runs, measured and predicted by each model; held-out
    experiments first, at most MAX_PANELS."""
    preds0 = entries[0].validation.predictions
    shown = sorted(preds0, key=lambda p: (p.role != "validate", p.temperature))[:MAX_PANELS]
    cols = min(len(shown), 2)
    rows = -(-len(shown) // cols)
    fig, axes = subplots(rows, cols, figsize=(4.3 * cols, 3.3 * rows + 0.4), squeeze=False, constrained_layout=True)
    for ax, p0 in zip(axes.flat, shown):
        kx = scaled_axis(ax, "x", p0.position, "position", xunit)
        kf = scaled_axis(ax, "y", p0.measured, f"friction {what}", unit)
        stride = max(len(p0.time) // 1500, 1)
        ax.plot(p0.position[::stride] * kx, p0.measured[::stride] * kf, "o", ms=2, mfc="none", mew=0.6, color="0.45",
                label="measured")
        for e in entries:
            p = next(q for q in e.validation.predictions if q.file == p0.file)
            step = max(len(p.time) // 20_000, 1)
            ax.plot(p.position[::step] * kx, p.predicted[::step] * kf, "-", lw=1.1, label=e.label)
        ax.set_title(f"{p0.file}, {p0.temperature:.1f} °C" + (" (held out)" if p0.role == "validate" else ""),
                     fontsize=9)
    for ax in axes.flat[len(shown):]:
        ax.set_visible(False)
    legend(fig, fontsize=8, frameon=False, loc="outside lower center", ncol=len(entries) + 1)
    return figs.render(fig, "hysteresis", f"The friction {what} against the measured position over each run: "
                       f"measured (markers) and predicted by each model (lines), the sensor offset included; "
                       f"held-out experiments first.")


def _akaike(entries):
    return akaike_scaled(entries)[0]


def render_force(entries, data, *, figures_dir=None, command=None, title=None, truth=None, bands=None) -> str:
    """The page for force data (``truth`` and ``bands`` are displacement studies' and not shown here): the
    friction-velocity map, hysteresis and presliding loops, the models compared on the held-out experiments.

    Parameters
    ----------
    entries : list of Entry
        The models compared, each with its label and, when known, its fit and validation.
    data : Dataset
        The measurements; at least one experiment with role "validate".
    figures_dir : str or os.PathLike, optional
        A folder where the figures are also written as SVG and PNG files.
    command : str, optional
        The command line shown as how the report was made.
    title : str, optional
        The page's title.
    truth : dict, optional
        Taken for the same call as ``render``; not shown.
    bands : PropagationResult, optional
        Taken for the same call as ``render``; not shown.

    Returns
    -------
    str
        The page's HTML.

    Raises
    ------
    InputError
        A dataset without a held-out ("validate") experiment.
    ComputationError
        A model's predictions failed.
    """

    exps = list(getattr(data, "experiments", data))
    if not any(getattr(e, "role", "fit") == "validate" for e in exps):
        raise InputError("the dataset has no experiment with role 'validate': a report compares predictions on "
                         "experiments the models were not identified on")
    unit, vunit, xunit, what = _units(exps)
    for e in entries:
        if e.validation is None:  # as it was fitted (its fit record)
            e.validation = validate(e.model, data)
        # the default labels name the thermal model only (and the command line adds the file's stem to tell
        # them apart): here the friction model is what differs
        if e.label.startswith(("no thermal model", "Model I", "base")):
            e.label = _label(e.model)
    seen = {}
    for e in entries:  # one label per entry
        seen[e.label] = seen.get(e.label, 0) + 1
        if seen[e.label] > 1:
            e.label = f"{e.label} ({seen[e.label]})"
    figs = Figures(figures_dir)
    parts = []
    held = {e.label: e.validation.summary().get("validate", {}).get("rmse", math.inf) for e in entries}
    best = min(entries, key=lambda e: held[e.label])
    held_pct = 100 * best.validation.summary().get("validate", {}).get("nrmse", math.nan)
    cards = [("best on held-out experiments", best.label,
              f"RMSE {held[best.label]:.3g} {unit} ({held_pct:.2g} % of the range)"),
             ("experiments", f"{len(exps)}", f"{sum(getattr(e, 'role', 'fit') == 'validate' for e in exps)} held out"),
             ("temperatures", f"{min(e.temperature for e in exps):.1f}–{max(e.temperature for e in exps):.1f} °C", ""),
             ("units", "rotary" if unit == "N m" else "linear", f"{xunit}, {vunit}, {unit}")]
    parts.append('<div class="cards">' + "".join(
        f'<div class="card"><div class="k">{html.escape(k)}</div><div class="v">{html.escape(v)}</div>'
        f'<div class="s">{html.escape(s)}</div></div>' for k, v, s in cards) + "</div>")
    warns = []
    for e in entries:
        f = e.fit or {}
        warns += [f"{e.label}: {w}" for w in f.get("warnings", [])]
        if f.get("success") is False:
            warns.append(f"{e.label}: the fit did not converge: {f.get('message', '')}")
        warns += [f"{e.label}: {x.file} could not be predicted: {x.reason}" for x in e.validation.failures]
        warns += [f"{e.label}: {w}" for w in e.validation.warnings]
    warns.sort(key=lambda w: SUSPICIOUS not in w)  # a unit 1000x off first: it explains the rest
    if warns:
        parts.append("<section><h2>Warnings</h2>" + "".join(f'<div class="warn">{html.escape(w)}</div>'
                                                           for w in dict.fromkeys(warns)) + "</section>")
    parts.append(_comparison_section(entries, unit, what))
    parts.append(f"<section><h2>Measured and predicted {what}</h2>" + fig_force_time(figs, entries, unit, what)
                 + "</section>")
    parts.append("<section><h2>Friction–velocity map</h2>" + fig_velocity_map(figs, entries, exps, unit, vunit, what)
                 + "</section>")
    parts.append(load_sections(figs, entries, exps, unit, vunit, what))  # runs at several loads (reporting/load.py)
    parts.append("<section><h2>Hysteresis</h2>" + fig_hysteresis(figs, entries, unit, xunit, what) + "</section>")
    loops = fig_loops(figs, entries, unit, xunit, what)
    if loops:
        parts.append("<section><h2>Presliding hysteresis</h2>" + loops + "</section>")
    loads = len(distinct_loads(exps)) > 1  # a load column where the runs span loads
    err_rows = [[e.label, m["file"], fmt_number(m["temperature"], "{:.4g}"),
                 *([fmt_number(m.get("load"), "{:.4g}")] if loads else []), m["role"], fmt_number(m["rmse"], "{:.4g}"),
                 fmt_number(100 * m["nrmse"]), fmt_number(m["max_error"]), fmt_number(m["bias"], "{:+.3g}")]
                for e in entries for m in e.validation.experiments]
    parts.append("<section><h2>Errors per experiment</h2>" + html_table(
        ["model", "file", "T [°C]", *([f"load [{unit}]"] if loads else []), "role", f"RMSE [{unit}]", "RMSE [% of range]", f"max |error| [{unit}]",
         f"mean error [{unit}]"], err_rows) + f"<p class='note'>{html.escape(_range_note(what))}</p></section>")
    parameters = _parameters_section(entries, unit)
    if parameters:
        parts.append(parameters)
    return page_html(title or f"thermofriction report — {getattr(data, 'name', None) or 'force data'}",
                     f"{', '.join(e.label for e in entries)} on {len(exps)} {what} experiments", parts,
                     command=command, data=data)


def _comparison_section(entries, unit, what) -> str:
    """The friction models compared: AICc among fits of the same data, and errors on held-out experiments."""
    rows = []
    aic = _akaike(entries)
    c = max([a[2] for a in aic if a] or [1.0])
    basis = (f"The residuals are correlated (the most general fit's integrated autocorrelation time c = {c:.3g}): "
             f"ΔAICc is divided by c (as QAIC does), and the models are best compared by their held-out RMSE. "
             if c > 1.5 else "")
    for e, a in zip(entries, aic):
        s = e.validation.summary()
        f = e.fit or {}
        k = sum(1 for p in (f.get("parameters") or {}).values() if p.get("vary"))
        rows.append([e.label, fmt_number(k if f else None, "{:.0f}"), fmt_number(a[0] if a else None, "{:.1f}"),
                     fmt_number(a[1] if a else None, "{:.3f}"), fmt_number(s.get("fit", {}).get("rmse"), "{:.4g}"),
                     fmt_number(s.get("validate", {}).get("rmse"), "{:.4g}"),
                     fmt_number(100 * s.get("validate", {}).get("nrmse", math.nan)),
                     fmt_number(e.model.plant.sensor_offset, "{:.4g}"), e.validation.scoring])
    return ("<section><h2>Friction models compared</h2>" + html_table(
        ["model", "fitted parameters", "ΔAICc", "Akaike weight", f"RMSE, fit [{unit}]", f"RMSE, held out [{unit}]",
         "RMSE, held out [% of range]", f"sensor offset [{unit}]", "scored with"], rows, text=(8,), wrap=(8,)) +
        "<p style='font-size:13px;color:#4a5266'>" + basis + "ΔAICc is each fit's AICc minus the lowest among fits of the same "
        "data (from the identification results beside each model file), the Akaike weight exp(−ΔAICc/2) normalised "
        "to one. The held-out RMSE compares the models on experiments none was fitted to, each model scored as it was "
        "fitted (its fit record: \"scored with\"; a model without one by the defaults, shared offset and the "
        "dataset's motion): with the offset per experiment, each experiment's own offset is removed (on held-out "
        "experiments it is estimated on them), so the errors are of the friction's shape; with a shared offset, "
        "the one fitted on the fit experiments is used as it is. " + html.escape(_range_note(what)) +
        " Over the held-out experiments: the root mean square of theirs.</p></section>")


def _range_note(what) -> str:
    """What the force tables' relative error is, said where it is shown."""
    return (f"RMSE [% of range] = 100 · RMSE / (max F_meas − min F_meas): the RMSE against the range the measured "
            f"{what} spans (a {what} that changes sign has no level to divide by). Max |error| is the largest single "
            f"error, in the data's unit: on a {what} that reverses it is at a reversal, where a small timing "
            f"difference shows as a large error.")


def _parameters_section(entries, unit) -> str:
    """Each fit's parameters with their intervals, the sensor offset among them."""
    param_rows = []
    for e in entries:
        f = e.fit or {}
        for name, p in (f.get("parameters") or {}).items():
            param_rows.append([e.label, name, *cells(p), p.get("unit", "")])  # (fitting/shown.py)
        o = f.get("sensor_offset")
        if o:
            param_rows.append([e.label, "sensor offset" + ("" if o.get("fitted") else " (held)"),
                               *cells({**o, "vary": bool(o.get("fitted"))}), o.get("unit", unit)])
        param_rows += _drive_rows(e.label, (f.get("details") or {}).get("plant"))
    if not param_rows:
        return ""
    return ("<section><h2>Identified parameters</h2>" + html_table(
        ["model", "parameter", "value", "std. error", "95 % interval", "unit"], param_rows) + "</section>")


def _drive_rows(label, plant) -> list:
    """A drive's inertia J and delay (command data: details["plant"]), the delay's note (how it was taken, the
    range searched) in its name's cell."""
    if not plant:
        return []
    rows = []
    for name, p, scale, unit in (("inertia J", plant["inertia"], 1.0, plant["inertia"].get("unit", "")),
                                 (f"delay ({plant['delay'].get('note', '')})", plant["delay"], 1e3, "ms")):
        ci = p.get("ci95") or [math.nan, math.nan]
        rows.append([label, name, fmt_number(p.get("estimate", p.get("value")) * scale, "{:.6g}"),
                     fmt_number((p.get("stderr") or math.nan) * scale, "{:.3g}"),
                     f"[{fmt_number(ci[0] * scale, '{:.5g}')}, {fmt_number(ci[1] * scale, '{:.5g}')}]", unit])
    return rows


__all__ = ["render_force", "reversals"]
