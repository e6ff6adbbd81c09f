"""Issue 44 item 5, figures and messages: figures at their own size (not stretched to the page), one legend entry
per label, the paper's laws only beside the paper's models, an error relative to signed data that means something,
and a fitted law's range that holds at its own fit temperatures."""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.identification.laws import fit_law, segmented_fit
from thermofriction.figures import fit_plots, plots
from thermofriction.reporting.page import Figures, page_html

from lookalike import lookalike_dataset

JOINT = """name = "a joint"
[plant]
type = "prescribed"
motion = "rotary"
sensor_offset = 0.02
[friction]
model = "lugre"
sigma0 = 100.0
sigma1 = 0.5
fc = 0.38
fs = 0.47
vs = 0.08
sigma2 = 0.1
[thermal]
model = "none"
"""


def _svg_width_pt(html_text):
    return float(re.search(r'<svg[^>]*\swidth="([0-9.]+)pt"', html_text).group(1))


def test_a_figure_is_shown_at_its_own_size_and_a_single_panel_is_not_page_wide():
    """The page's style no longer stretches every figure to the card's width: an SVG keeps its own width (72 pt
    per inch of the figure) and is only shrunk where the page is narrower. A one-model displacement figure has
    one panel and is sized for one panel (plus its legend), not the 11 in of three."""
    css = page_html("t", "s", [])
    assert "figure svg{width:100%" not in css and "figure svg{max-width:100%" in css
    one = plots.panels_width(1)
    assert one < 0.7 * plots.WIDE and plots.panels_width(3) == plots.WIDE
    data = tf.synthesize(tf.load_model("li2009-base"), [30.0], validate=[35.0], duration=0.2, sample_rate=2000.0,
                         seed=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        v = tf.validate(tf.load_model("li2009-base"), data)
    fig = plots.displacement_figure([("base", v)])
    assert fig.get_figwidth() == pytest.approx(one)
    # rendered: the SVG's width is about the figure's (bbox "tight" trims the margins, a legend's edge may pass it)
    width = _svg_width_pt(Figures().render(fig, "d", "caption"))
    assert 0.8 * 72 * one < width < 1.1 * 72 * one < 0.75 * 72 * plots.WIDE


def test_a_legend_has_one_entry_per_label():
    """Two runs at one nominal temperature (24.0001 and 23.9998 C, both "24.0 °C") gave the temperature key two
    identical entries, and two validations drawn into one panel (``v2.plot(ax=...)``) repeated "held-out
    temperature"; the one legend helper keeps the first of each label."""
    styles = plots.temperature_styles([(24.0001, "fit"), (23.9998, "fit"), (45.0, "fit"), (30.0, "validate")])
    fig, _ = plots.new_figure(5, 3)
    plots.temperature_key(fig, styles)
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels == ["24.0 °C", "45.0 °C", "30.0 °C, held out"]

    data = tf.synthesize(tf.load_model("li2009-base"), [30.0], validate=[35.0], duration=0.2, sample_rate=2000.0,
                         seed=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        v1 = tf.validate(tf.load_model("li2009-base"), data)
        v2 = tf.validate(tf.load_model("li2009-model-i"), data)
    fig = v1.plot(label="one")
    v2.plot(ax=fig.axes[0], label="two")
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert len(labels) == len(set(labels)) and {"one", "two", "held-out temperature"} <= set(labels)


def _laws_model(name=None, initial=None):
    model = tf.load_model("li2009-model-i")
    import dataclasses
    return dataclasses.replace(model, name=name, provenance={"initial_model": initial} if initial else None)


def test_the_papers_laws_only_beside_the_papers_models():
    """The paper's Eqs. (9)-(11) describe its actuator: drawn for the preset and for a fit started from a li2009
    preset (the demo's), not for a model fitted to a user's own actuator from its own start."""
    assert fit_plots.from_the_paper(_laws_model("li2009-model-i"))
    assert fit_plots.from_the_paper(_laws_model("model-i fit to li2009-synthetic", "li2009-base"))
    assert not fit_plots.from_the_paper(_laws_model("model-i fit to my-stage", "my-plant.toml"))
    assert not fit_plots.from_the_paper(_laws_model("model-i fit to my-stage", None))

    def drawn(model):
        fig = fit_plots.laws_figure({}, model)
        return any("paper" in line.get_label() for ax in fig.axes for line in ax.lines)
    assert drawn(_laws_model("li2009-model-i"))
    assert not drawn(_laws_model("model-i fit to my-stage", "my-plant.toml"))


def test_force_tables_give_the_rmse_against_the_measured_range_not_max_error_percent(tmp_path):
    """On signed torque (a joint reversing: the torque crosses zero) the largest error sits at a reversal; the
    tables now give the RMSE as a percentage of the range the measured torque spans, and the largest error in
    N m. Both checked against NumPy on the prediction's own arrays: 100 sqrt(mean e^2) / ptp(T_meas) and
    max |e|, e = predicted − measured. The look-alike's torque comes from an independent SciPy solver."""
    folder, _ = lookalike_dataset(tmp_path / "data", offsets=(0.02, 0.02, 0.02), temperatures=(25.0, 25.0, 25.0))
    (tmp_path / "joint.toml").write_text(JOINT)
    data = tf.load_dataset(folder)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        v = tf.validate(tf.load_model(tmp_path / "joint.toml"), data)
    head = [c[0] for c in v._COLUMNS]
    assert "RMSE [% of range]" in head and "max |error| [N m]" in head and "max error [%]" not in head
    for p, row in zip(v.predictions, v.rows()):
        e = p.predicted - p.measured
        assert np.min(p.measured) < 0 < np.max(p.measured)  # signed data
        pct = 100 * math.sqrt(float(np.mean(e ** 2))) / float(np.ptp(p.measured))
        # the cells hold 3 significant digits: within half a unit of the last one (5e-3 relative at most)
        assert float(row[head.index("RMSE [% of range]")]) == pytest.approx(pct, rel=5e-3)
        assert float(row[head.index("max |error| [N m]")]) == pytest.approx(float(np.max(np.abs(e))), rel=5e-3)
    s = v.summary()["validate"]
    assert s["nrmse"] == pytest.approx(v.predictions[-1].nrmse)
    assert "RMSE [% of range] = 100 RMSE / (max F_meas - min F_meas)" in v.measurement.caption


def test_a_fitted_laws_range_holds_at_its_nominal_fit_temperatures():
    """Runs nominally at 24, 34 and 45 C whose records average 24.0001, 34.0002 and 44.9995 C: the laws fitted
    through them (fit_law's and the segmented law's) hold at 24 and 45 C, and no more than 0.1 C beyond. (The range
    written is what was fitted; a law holds within RANGE_TOLERANCE of it.)"""
    T = np.array([24.0001, 29.0, 34.0002, 39.0, 44.9995])
    values = 1.0 + 0.01 * T
    law, _ = fit_law(T, values, kinds=("linear",))
    _, pwl, _ = segmented_fit(T, values)
    for rng_law in (law, pwl):
        assert rng_law.in_range(24.0) and rng_law.in_range(45.0)
        lo, hi = rng_law.range
        assert (lo, hi) == (24.0001, 44.9995)
        assert not rng_law.in_range(23.8) and not rng_law.in_range(45.2)
