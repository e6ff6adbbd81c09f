"""Figures an engineer keeps (figures/units.py, friction_plots.py, plots.py): units chosen from the data with the
unit in the axis label and no offset text, titles on every figure and none overlapping another, the friction axis
cut (and saying so) where a sawtooth's flyback spikes would set it, the hysteresis views (friction against
displacement) drawing exactly the result's arrays, and the paper's 7-8 % band only where the errors are on its
scale. Each figure is drawn on an Agg canvas (as a saved PNG is) before its texts are read."""

import itertools
import warnings

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.errors import InputError
from thermofriction.reporting import Entry, report
from thermofriction.figures import plots
from thermofriction.figures.fit_plots import fit_figure, model_ii_figure
from thermofriction.figures.units import unit_scale


def _drawn(fig):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    FigureCanvasAgg(fig).draw()  # as a saved PNG is drawn
    return fig


def _offset_texts(fig):
    return [a.get_offset_text().get_text() for ax in fig.axes for a in (ax.xaxis, ax.yaxis)
            if a.get_offset_text().get_text()]


def _titles(fig):
    """Every non-empty title: the figure's and subfigures' suptitles and each visible axes' titles."""
    out = [t for f in [fig, *fig.subfigs] if (t := getattr(f, "_suptitle", None)) is not None and t.get_text()]
    for ax in fig.axes:
        if ax.get_visible():
            out += [t for t in (ax.title, ax._left_title, ax._right_title) if t.get_text()]
    return out


def _no_overlap(fig, gap=0.1):
    """The titles' texts, after checking that no two overlap and that two on one line are at least ``gap``
    inches apart (titles that touch read as one: the demo's "displacement vs temperature (Fig. 6)displacement
    vs dF (Fig. 7)", 0.04 in apart)."""
    renderer = fig.canvas.get_renderer()
    boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in _titles(fig)]
    for (a, ba), (b, bb) in itertools.combinations(boxes, 2):
        assert not ba.overlaps(bb), f"titles {a!r} and {b!r} overlap"
        if min(ba.y1, bb.y1) > max(ba.y0, bb.y0):  # on one line
            apart = max(bb.x0 - ba.x1, ba.x0 - bb.x1) / fig.dpi
            assert apart >= gap, f"titles {a!r} and {b!r} are {apart:.3f} in apart"
    return [a for a, _ in boxes]


@pytest.mark.parametrize("values, unit, expected", [
    ([0.0, 1.27], "m", (1.0, "m")), ([3e-6, -2.1e-5], "m", (1e6, "µm")), ([999.7e-6], "m", (1e3, "mm")),
    ([4e-8], "m", (1e9, "nm")), ([1e-12], "m", (1e9, "nm")), ([0.0, 0.0], "m", (1.0, "m")),
    ([0.403], "N", (1e3, "mN")), ([1.8e6], "N/m", (1e-6, "N/µm")), ([35.0], "°C", (1.0, "°C")),
    ([np.nan, 2e-3], "N m", (1e3, "mN m"))])
def test_units_are_chosen_so_the_largest_value_lies_between_1_and_1000__definition(values, unit, expected):
    k, name = unit_scale(values, unit)
    assert (k, name) == (pytest.approx(expected[0]), expected[1])


@pytest.fixture(scope="module")
def canudas():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the preset's parameters are not dissipative at high speed (documented)
        return tf.simulate(tf.load_model("canudas1995"), 20.0, sample_rate=500.0)


@pytest.fixture(scope="module")
def sawtooth():
    """The paper's stick-slip actuator at 35 C: 0.5 s of its 5 Hz sawtooth, two and a half flybacks."""
    return tf.simulate(tf.load_model("li2009-model-i"), 0.5, temperature=35.0)


def test_canudas_displacement_is_drawn_in_metres_without_offset_text_and_titled(canudas):
    """The mass travels 1.27 m: the axis says [m] with plain tick labels (it was "µm" with "1e6" above)."""
    fig = _drawn(canudas.plot())
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert labels == ["input [N]", "displacement [m]", "friction force [N]"]
    assert _offset_texts(fig) == []
    line = fig.axes[1].get_lines()[0]
    assert np.max(line.get_ydata()) == pytest.approx(np.max(canudas.displacement))
    assert _no_overlap(fig) == ["canudas1995"]  # no thermal model: no temperature in the title


def test_the_sawtooths_friction_axis_is_cut_to_its_percentiles_and_says_so(sawtooth):
    """The flyback's friction peaks (~0.4 N) dwarf the rest; the axis is cut to the 1-99 % percentiles (widened
    by a quarter of their span), the peaks are named on the panel, and the title names model and temperature."""
    fig = _drawn(sawtooth.plot())
    ax = fig.axes[2]
    assert ax.get_ylabel() == "friction force [mN]"
    F = sawtooth.friction_force * 1e3
    lo, hi = np.percentile(F, [1, 99])
    assert ax.get_ylim() == pytest.approx((lo - 0.25 * (hi - lo), hi + 0.25 * (hi - lo)))
    assert np.max(np.abs(F)) > 5 * max(abs(lo), abs(hi))  # the spikes are really cut
    notes = [t.get_text() for t in ax.texts]
    assert len(notes) == 1 and "percentiles" in notes[0] and f"{F.max():.3g}" in notes[0]
    assert fig.axes[1].get_ylabel() == "displacement [µm]" and _offset_texts(fig) == []
    assert _no_overlap(fig) == ["li2009-model-i at 35.0 °C"]


def test_a_smooth_friction_panel_is_not_cut(canudas):
    fig = _drawn(canudas.plot())
    ax = fig.axes[2]
    assert not ax.texts
    lo, hi = ax.get_ylim()
    assert lo <= canudas.friction_force.min() and hi >= canudas.friction_force.max()


def test_hysteresis_draws_the_results_friction_against_its_sliding_displacement(sawtooth, canudas):
    """Stick-slip: friction against x_e - x_p (where the friction acts), in µm and mN; a mass on a spring:
    against its displacement, in m and N. The line is the result's arrays themselves, every sample."""
    for res, x, kx, ky, xlabel, ylabel in (
            (sawtooth, sawtooth.relative_displacement, 1e6, 1e3, "x_e − x_p (sliding) [µm]", "friction force [mN]"),
            (canudas, canudas.displacement, 1.0, 1.0, "displacement [m]", "friction force [N]")):
        fig = _drawn(res.plot(what="hysteresis"))
        ax = fig.axes[0]
        assert (ax.get_xlabel(), ax.get_ylabel()) == (xlabel, ylabel)
        line = ax.get_lines()[0]
        np.testing.assert_array_equal(line.get_xdata(), x * kx)
        np.testing.assert_array_equal(line.get_ydata(), res.friction_force * ky)
        assert _offset_texts(fig) == [] and ax.get_title() == (
            "li2009-model-i at 35.0 °C" if res is sawtooth else "canudas1995")
    with pytest.raises(ValueError, match="hysteresis"):
        canudas.plot(what="nonsense")


@pytest.fixture(scope="module")
def small_dataset():
    """The paper's Model I, 0.4 s at four temperatures (one held out), 2 nm noise: the preset predicts its own
    data to the noise (max errors well below 1 %), the model without a thermal part misses them by tens of %."""
    return tf.synthesize(tf.load_model("li2009-model-i"), [31.0, 36.0, 41.0], validate=[33.5], duration=0.4,
                         noise=2e-9, seed=3)


def _band(ax):
    return [p for p in ax.patches if str(p.get_label()).startswith("Li et al.")]


def test_the_papers_band_is_left_out_where_the_errors_are_far_below_it(small_dataset):
    v = tf.validate(tf.load_model("li2009-model-i"), small_dataset)
    errors = [p.max_error_pct for p in v.predictions]
    assert max(errors) < 1.0
    ax = _drawn(v.plot()).axes[0]
    assert _band(ax) == []
    assert ax.get_ylim()[1] < 2.0  # the axis fits the errors
    assert ax.get_title() == "max error against temperature"
    assert len(_band(v.plot(paper=True).axes[0])) == 1  # asked for: drawn


def test_the_papers_band_is_drawn_where_the_errors_are_on_its_scale(small_dataset):
    base = tf.load_model("li2009-base")
    v = tf.validate(base, small_dataset)
    assert max(p.max_error_pct for p in v.predictions) > plots.PAPER_BAND_FROM_PCT
    ax = v.plot().axes[0]
    assert len(_band(ax)) == 1
    assert _band(v.plot(paper=False).axes[0]) == []


def test_hysteresis_needs_force_data(small_dataset):
    v = tf.validate(tf.load_model("li2009-model-i"), small_dataset, experiments=small_dataset.experiments[:1])
    with pytest.raises(InputError, match="force"):
        v.plot(what="hysteresis")


@pytest.fixture(scope="module")
def force_case(tmp_path_factory):
    """A stage's friction in mN under a ±0.5 mm sine, simulated by the C core (the data's generator here is
    not what is tested: the figures must draw the prediction's own arrays), two runs, one held out."""
    folder = tmp_path_factory.mktemp("force")
    stage = tf.Model(tf.PrescribedMotion(), tf.LuGre(sigma0=3e4, sigma1=0.5, fc=0.09, fs=0.14, vs=0.003,
                                                      sigma2=0.35), name="stage")
    for name, a in (("run0.csv", 0.5e-3), ("run1-validate.csv", 0.6e-3)):
        res = tf.simulate(stage, input=tf.Sine(amplitude=a, frequency=0.5), duration=2.0, sample_rate=500)
        np.savetxt(folder / name, np.column_stack([res.time, res.displacement, res.friction_force]),
                   delimiter=",", header="time[s],position[m],friction_force[N]", comments="", fmt="%.12g")
    (folder / "dataset.toml").write_text('[[experiment]]\nfile = "run0.csv"\ntemperature = 35.0\n\n'
                                         '[[experiment]]\nfile = "run1-validate.csv"\ntemperature = 35.0\n'
                                         'role = "validate"\n')
    data = tf.load_dataset(folder)
    return stage, data, tf.validate(stage, data), folder


def test_force_hysteresis_draws_measured_and_predicted_friction_against_the_measured_position(force_case):
    """One panel per experiment, held out first; in µm and mN (a ±0.6 mm motion, ~0.14 N friction)."""
    stage, data, v, _ = force_case
    fig = _drawn(v.plot(what="hysteresis"))
    order = sorted(v.predictions, key=lambda p: p.role != "validate")
    for ax, p in zip(fig.axes, order):
        assert (ax.get_xlabel(), ax.get_ylabel()) == ("position [µm]", "friction force [mN]")
        measured, predicted = ax.get_lines()[:2]
        np.testing.assert_array_equal(predicted.get_xdata(), p.position * 1e6)
        np.testing.assert_array_equal(predicted.get_ydata(), p.predicted * 1e3)
        np.testing.assert_array_equal(measured.get_ydata(), p.measured * 1e3)
    assert fig.axes[0].get_title().startswith("run1-validate.csv") and "held out" in fig.axes[0].get_title()
    assert _offset_texts(fig) == []
    assert "stage: friction force against position" in _no_overlap(fig)


def test_a_force_fits_figure_shows_friction_over_time_and_against_position_not_displacement(force_case):
    stage, data, v, _ = force_case
    fig = _drawn(fit_figure({"model": stage.to_dict(), "method": "base"}, v))
    labels = {ax.get_ylabel() for ax in fig.axes}
    assert labels == {"friction force [mN]"}
    assert {ax.get_xlabel() for ax in fig.axes} == {"time [s]", "position [µm]"}
    titles = _no_overlap(fig)
    assert titles[0].startswith("stage (base): run1-validate.csv")


def test_the_force_report_has_a_hysteresis_section(force_case, tmp_path):
    stage, data, _, _ = force_case
    text = report([Entry("LuGre", stage)], data, tmp_path / "r.html", figures_dir=tmp_path / "figs")
    assert '<h2>Hysteresis</h2><figure id="fig-hysteresis">' in text
    assert (tmp_path / "figs" / "hysteresis.png").stat().st_size > 1000


def test_model_ii_procedure_titles_do_not_overlap():
    """The paper's procedure's three panels side by side, on the demo's numbers (rounded), where their titles
    collided."""
    T = [30.8, 32.0, 33.9, 35.7, 37.0, 38.4, 40.0, 41.5]
    procedure = {"temperatures": T, "breakpoint": 36.58,
                 "displacement": [6.35e-6, 8.03e-6, 10.9e-6, 13.5e-6, 15.2e-6, 16.8e-6, 18.5e-6, 20.0e-6],
                 "displacement_law": {"T": [30.8, 36.58, 41.5], "values": [6.32e-6, 14.8e-6, 20.1e-6]},
                 "dF_grid": list(np.linspace(-0.396, 0.158, 8)),
                 "displacement_vs_dF": [13.2e-6, 11.5e-6, 9.96e-6, 8.64e-6, 7.52e-6, 6.60e-6, 5.87e-6, 5.33e-6],
                 "linear_fit": {"intercept": 6.89e-6, "slope": -1.42e-5, "r2": 0.9701},
                 "dF_law": {"T": [30.8, 36.58, 41.5], "values": [0.0397, -0.557, -0.928]}}
    direct = {"temperatures": T, "dF": [0.0, -0.13, -0.3, -0.42, -0.49, -0.55, -0.6, -0.64], "stderr": [0.01] * 8}
    fig = _drawn(model_ii_figure({"details": {"paper": procedure, "direct": direct}}, tf.load_model("li2009-model-ii"),
                                 held_out=[33.0, 39.2]))
    assert len(_no_overlap(fig)) == 3
    assert [ax.get_ylabel() for ax in fig.axes[:2]] == ["net displacement [µm]"] * 2
    assert _offset_texts(fig) == []
