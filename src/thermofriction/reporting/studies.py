"""Report pages of the studies beyond the paper: self-heating over long runs and friction
compensation in closed loop."""

from __future__ import annotations

import html

import numpy as np

from .. import _args
from .._lazy import lazy
from .page import Figures, fmt_number, html_table, page_styled, subplots, write_page
from ..figures.plots import legend
from ..figures.units import scaled_axis

matplotlib = lazy("matplotlib")


@page_styled
def _check_arguments(name, items, what, path, figures_dir, title, command):
    """A study page's arguments: ``items`` a non-empty list of dicts, the paths and texts of their types."""
    if not isinstance(items, (list, tuple)) or not items or not all(isinstance(r, dict) for r in items):
        _args.refuse(name, what, items)
    _args.path(path, "path")
    _args.path(figures_dir, "figures_dir", none=True)
    _args.text(title, "title", none=True)
    _args.text(command, "command", none=True)


def heating_report(runs, path, *, figures_dir=None, title=None, command=None) -> str:
    """Writes an HTML report of long heated runs. Figures: temperature rise, step-size drift, and the error of
    the constant-temperature prediction; a table of the figures that matter.

    Parameters
    ----------
    runs : list of dict
        Each with ``label``, ``result`` (a HeatingResult, the prediction with self-heating), optionally
        ``reference`` (the full simulation on the same grid) and ``constant`` (the displacement [m] predicted
        at the start temperature, on the same grid).
    path : str or os.PathLike
        The HTML file written.
    figures_dir : str or os.PathLike, optional
        A folder where the figures are also written as SVG and PNG files.
    title : str, optional
        The page's title.
    command : str, optional
        The command line shown as how the report was made.

    Returns
    -------
    str
        The page's HTML, as written to ``path``.

    Raises
    ------
    InputError
        An argument of the wrong type, named; a path that cannot be written.
    """
    _check_arguments("runs", runs, "a non-empty list of dicts", path, figures_dir, title, command)
    figs = Figures(figures_dir)
    colors = matplotlib.rcParams["axes.prop_cycle"].by_key()["color"]
    parts = []
    fig, ax = subplots(figsize=(7, 3.4))
    for i, r in enumerate(runs):
        res = r["result"]
        ax.plot(res.time, res.temperature, color=colors[i % len(colors)], label=r["label"])
        if r.get("reference") is not None:
            ax.plot(r["reference"].time, r["reference"].temperature, ":", color="k", lw=1)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("interface temperature [°C]")
    ax.set_title("interface temperature")
    legend(ax)
    temp_fig = figs.render(fig, "heating_temperature", "Temperature of the friction interface (lines: two-time-scale "
                           "method; dotted: the full simulation through every cycle).")
    fig, ax = subplots(figsize=(7, 3.4))
    k = scaled_axis(ax, "y", np.concatenate([r["result"].step_size for r in runs]), "step per cycle", "m")
    for i, r in enumerate(runs):
        res = r["result"]
        ax.plot(res.time, res.step_size * k, color=colors[i % len(colors)], label=r["label"])
        if r.get("reference") is not None:
            ref = r["reference"]
            ax.plot(ref.time, ref.step_size * k, ":", color="k", lw=1)
    ax.set_xlabel("time [s]")
    ax.set_title("step per cycle as the interface heats")
    legend(ax)
    step_fig = figs.render(fig, "heating_step_size", "Step size drift as the interface heats (dotted: full simulation).")
    fig, ax = subplots(figsize=(7, 3.4))
    rows = []
    for i, r in enumerate(runs):
        res, ref, const = r["result"], r.get("reference"), r.get("constant")
        truth = ref if ref is not None else res
        if const is not None:
            err = (const - truth.displacement) / np.maximum(np.abs(truth.displacement), 1e-300) * 100
            ax.plot(truth.time[1:], err[1:], color=colors[i % len(colors)], label=r["label"])
        rows.append([r["label"], fmt_number(res.temperature[-1] - res.temperature[0], "{:.3g}"),
                     fmt_number(res.step_size[0] * 1e6, "{:.4g}"), fmt_number(res.step_size[-1] * 1e6, "{:.4g}"),
                     fmt_number(truth.displacement[-1] * 1e3, "{:.5g}"),
                     fmt_number(None if const is None else (const[-1] - truth.displacement[-1]) * 1e3, "{:+.4g}"),
                     fmt_number(None if ref is None else np.max(np.abs(res.temperature - ref.temperature)), "{:.2g}"),
                     fmt_number(None if ref is None else abs(res.displacement[-1] - ref.displacement[-1])
                          / abs(ref.displacement[-1]) * 100, "{:.2g}"),
                     fmt_number(res.stats.get("seconds"), "{:.3g}"),
                     fmt_number(None if ref is None else ref.stats.get("seconds"), "{:.3g}")])
    ax.set_xlabel("time [s]")
    ax.set_ylabel("constant-temperature error [%]")
    ax.set_yscale("symlog", linthresh=1.0)
    legend(ax)
    err_fig = figs.render(fig, "heating_constant_temperature_error", "Error of the displacement predicted at the "
                          "start temperature (no self-heating), relative to the prediction with self-heating.")
    parts.append("<section><h2>Summary</h2>" + html_table(
        ["run", "temperature rise [K]", "first step [µm]", "last step [µm]", "displacement [mm]",
         "constant-T error [mm]", "max |ΔT| vs full [K]", "displacement error vs full [%]",
         "two-time-scale [s]", "full [s]"], rows) + "</section>")
    parts.append("<section><h2>Temperature</h2>" + temp_fig + "</section>")
    parts.append("<section><h2>Step size</h2>" + step_fig + err_fig + "</section>")
    return write_page(path, title or "thermofriction — self-heating", ", ".join(r["label"] for r in runs), parts,
                       command)


@page_styled
def control_report(rows, path, *, figures_dir=None, title=None, command=None) -> str:
    """Writes an HTML report of ``thermofriction.control.compare_compensation``'s rows: the table of RMS
    and maximum tracking errors per reference, stage temperature and compensation, and for each
    reference the tracking error over time at the hottest temperature.

    Parameters
    ----------
    rows : list of dict
        ``compare_compensation``'s rows.
    path : str or os.PathLike
        The HTML file written.
    figures_dir : str or os.PathLike, optional
        A folder where the figures are also written as SVG and PNG files.
    title : str, optional
        The page's title.
    command : str, optional
        The command line shown as how the report was made.

    Returns
    -------
    str
        The page's HTML, as written to ``path``.

    Raises
    ------
    InputError
        An argument of the wrong type, named; a path that cannot be written.
    """
    _check_arguments("rows", rows, "a non-empty list of row dicts (compare_compensation)", path, figures_dir, title,
                     command)
    figs = Figures(figures_dir)
    table = [[r["reference"], fmt_number(r["temperature"], "{:.1f}"), r["compensation"], fmt_number(r["rms_error"] * 1e6, "{:.3g}"),
              fmt_number(r["max_error"] * 1e6, "{:.3g}")] for r in rows]
    parts = ["<section><h2>Tracking error</h2>" + html_table(
        ["reference", "stage T [°C]", "compensation", "RMS error [µm]", "max error [µm]"], table) +
        "<p style='font-size:13px;color:#4a5266'>Blind: the compensation's model is told the calibration "
        "temperature (30 °C); aware: the measured temperature.</p></section>"]
    hottest = max(r["temperature"] for r in rows)
    for i, name in enumerate(dict.fromkeys(r["reference"] for r in rows)):
        fig, ax = subplots(figsize=(7, 3.4))
        shown = [r["result"] for r in rows if r["reference"] == name and r["temperature"] == hottest]
        k = scaled_axis(ax, "y", np.concatenate([res.error for res in shown]), "tracking error", "m")
        for r in rows:
            if r["reference"] == name and r["temperature"] == hottest:
                ax.plot(r["result"].time, r["result"].error * k, label=r["compensation"], lw=1)
        ax.set_xlabel("time [s]")
        ax.set_title(f"tracking error at {hottest:g} °C, {name}")
        ax.set_yscale("symlog", linthresh=1e-7 * k)  # linear within 0.1 µm, where the errors cross zero
        legend(ax, fontsize=8)
        parts.append("<section><h2>" + html.escape(name) + "</h2>" + figs.render(
            fig, f"control_error_{i}", f"Tracking error at {hottest:g} °C, {name}: no compensation, and "
            f"feed-forward or observer compensation, temperature-blind or temperature-aware.") + "</section>")
    return write_page(path, title or "thermofriction — friction compensation", "closed-loop tracking", parts, command)



__all__ = ["heating_report", "control_report"]
