"""The HTML report and the figures behind it (figures/plots.py, shared with the results' .plot()):
size, the error-against-temperature figure, fit and held-out temperatures told apart, AICc
differences and weights, every metric defined, the laws at a reference temperature, and the page
as Chromium renders it (legible legends, figures at the card's width)."""

import dataclasses
import html
import json
import math
import re
import types
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.demo import FIT_TEMPERATURES, HELD_OUT
from thermofriction.models import Exp, ModelI
from thermofriction.reporting import Entry, report
from thermofriction.figures import plots
from thermofriction.reporting.captions import DEFINITIONS


def _truth():
    """The paper's Model I with its laws moved away from the preset (the data are not the preset's)."""
    m = tf.load_model("li2009-model-i")
    laws = dict(m.laws)
    laws["sigma0"] = Exp(laws["sigma0"].a * 1.08, laws["sigma0"].b * 0.97, range=laws["sigma0"].range)
    laws["fc"] = Exp(laws["fc"].a * 0.93, laws["fc"].b, range=laws["fc"].range)
    return dataclasses.replace(m, thermal=ModelI(laws), name="perturbed truth")


@pytest.fixture(scope="module")
def demo_like(tmp_path_factory):
    """The demo's dataset shape (8 fit and 2 held-out temperatures, 2 s at 10 kHz, 20 nm noise, 5 nm
    quantisation) from a truth away from the presets; Model I and the model without thermal effects
    identified on it (one start each), Model II as the preset; the report written with its figures."""
    folder = tmp_path_factory.mktemp("report")
    data = tf.synthesize(_truth(), FIT_TEMPERATURES, validate=HELD_OUT, duration=2.0, sample_rate=10_000.0,
                         noise=20e-9, quantization=5e-9, seed=19, name="demo-like")
    start = tf.load_model("li2009-base")
    fit1 = tf.identify(data, "model-i", init=start, starts=1)
    base = tf.identify(data, "base", init=start, starts=1)
    entries = [Entry("Model I", fit1.model, fit1.to_dict()),
               Entry("Model II (preset)", tf.load_model("li2009-model-ii")),
               Entry("no thermal model", base.model, base.to_dict())]
    text = report(entries, data, folder / "report.html", figures_dir=folder / "figures")
    one = report([Entry("Model I", fit1.model, fit1.to_dict())], data, folder / "one.html")
    return types.SimpleNamespace(folder=folder, data=data, fit=fit1, base=base, entries=entries, text=text, one=one)


def test_the_demo_like_report_is_under_1_MB_and_self_contained(demo_like):
    size = (demo_like.folder / "report.html").stat().st_size
    assert size < 1_000_000, size
    assert "<script" not in demo_like.text
    for fig in ("error-vs-temperature", "steps", "displacement", "residuals", "model-i-parameters"):
        assert f'id="fig-{fig}"' in demo_like.text, fig
        assert (demo_like.folder / "figures" / f"{fig}.png").stat().st_size > 1000


def _lines(ax):
    return [ln for ln in ax.get_lines() if len(ln.get_xdata())]


def test_error_against_temperature_marks_fit_and_held_out_and_shows_the_papers_range(demo_like):
    """Each model: filled circles exactly at its fit temperatures with its max errors, open diamonds
    exactly at the held-out ones; the 7-8 % band; pale bands at the held-out temperatures."""
    pairs = [(e.label, e.validation) for e in demo_like.entries]
    fig = plots.error_figure(pairs)
    ax = fig.axes[0]
    for label, v in pairs:
        fit = sorted((p.temperature, p.max_error_pct) for p in v.predictions if p.role == "fit")
        held = sorted((p.temperature, p.max_error_pct) for p in v.predictions if p.role == "validate")
        colour = next(ln.get_color() for ln in _lines(ax) if ln.get_label() == label)
        mine = [ln for ln in _lines(ax) if ln.get_color() == colour]
        filled = [ln for ln in mine if ln.get_marker() == "o"]
        open_ = [ln for ln in mine if ln.get_marker() == "D"]
        assert len(filled) == 1 and len(open_) == 1
        np.testing.assert_allclose(np.column_stack([filled[0].get_xdata(), filled[0].get_ydata()]), fit)
        np.testing.assert_allclose(np.column_stack([open_[0].get_xdata(), open_[0].get_ydata()]), held)
        assert open_[0].get_markerfacecolor() in ("white", (1.0, 1.0, 1.0, 1.0))
    spans = [p for p in ax.patches if p.get_label() == "Li et al. (2009): 7–8 %"]
    assert len(spans) == 1
    ys = spans[0].get_path().transformed(spans[0].get_patch_transform()).vertices[:, 1]
    assert (min(ys), max(ys)) == pytest.approx(plots.PAPER_ERROR_PCT)
    def centre(p):
        x = p.get_path().transformed(p.get_patch_transform()).vertices[:, 0]
        return round(0.5 * float(x.min() + x.max()), 6)
    band_centres = sorted({centre(p)
                           for p in ax.patches if p.get_facecolor()[:3] == pytest.approx(
                               tuple(int(plots.HELD_OUT_BAND[i:i + 2], 16) / 255 for i in (1, 3, 5)))})
    assert band_centres == pytest.approx(sorted(HELD_OUT))
    assert ax.get_yscale() == "log"  # Model I at ~1 %, no thermal model at tens of %: decades apart


def test_held_out_traces_have_their_own_colours_and_dashes_in_every_trajectory_figure(demo_like):
    pairs = [(e.label, e.validation) for e in demo_like.entries]
    for fig in (plots.displacement_figure(pairs), plots.residual_figure(pairs)):
        for ax in fig.axes:
            solid = {ln.get_color() if isinstance(ln.get_color(), str) else tuple(ln.get_color())
                     for ln in _lines(ax) if ln.get_linestyle() == "-"}
            dashed = {ln.get_color() for ln in _lines(ax) if ln.get_linestyle() == "--"}
            assert dashed == set(plots.HELD_OUT_COLOURS[:len(HELD_OUT)])
            assert not dashed & solid
        labels = [t.get_text() for t in fig.legends[0].get_texts()]
        assert [f"{T:.1f} °C, held out" for T in HELD_OUT] == [x for x in labels if "held out" in x]


def test_residuals_are_the_windowed_rms_of_predicted_minus_measured__definition(demo_like):
    """Each line is sqrt(mean((x_sim - x_meas)^2)) over 50 equal windows (reshape: an independent
    computation), and the dotted line the median noise estimated from the data."""
    v = demo_like.entries[0].validation
    fig = plots.residual_figure([("Model I", v)])
    ax = fig.axes[0]
    lines = [ln for ln in _lines(ax) if ln.get_linestyle() in ("-", "--") and len(ln.get_xdata()) == 50]
    assert len(lines) == len(v.predictions)
    p = sorted(v.predictions, key=lambda p: (p.role == "validate", p.temperature))[0]
    n = len(p.time) // 50 * 50
    expected = np.sqrt(np.mean(((p.predicted - p.measured)[:n].reshape(50, -1)) ** 2, axis=1)) * 1e9
    np.testing.assert_allclose(lines[0].get_ydata(), expected, rtol=0.02)  # windows differ by one sample
    noise = np.median([p.fit_quality["noise"] for p in v.predictions]) * 1e9
    dotted = [ln for ln in ax.get_lines() if ln.get_linestyle() == ":"]
    assert dotted and dotted[0].get_ydata()[0] == pytest.approx(noise)
    # Model I fits at the noise: its residual lines lie within 15 % of the noise line
    assert all(np.median(ln.get_ydata()) == pytest.approx(noise, rel=0.15) for ln in lines)


def test_aicc_is_shown_as_differences_and_akaike_weights__definition(model_i, tmp_path):
    """ΔAICc = AICc - min over fits of the same data; weight = exp(-ΔAICc/2) / sum; a weight below
    1e-3 is written as such, never 0.000; no absolute AICc is shown."""
    same = {"n_points": 1000, "experiments": [{"file": "a.csv"}, {"file": "b.csv"}], "success": True}
    aiccs = [-5671423.7, -5671420.1, -5671300.0]
    from conftest import synthetic_experiments
    data = synthetic_experiments(model_i, [32.0, 35.0], duration=0.2)
    data[1].role = "validate"
    entries = [Entry(f"m{i}", model_i, dict(same, aicc=a)) for i, a in enumerate(aiccs)]
    text = report(entries, data, tmp_path / "r.html")
    w = np.exp(-0.5 * (np.array(aiccs) - min(aiccs)))
    w /= w.sum()
    table = text[text.index("<h2>Model comparison</h2>"):text.index("<h2>Errors per experiment</h2>")]
    rows = re.findall(r"<tr><td>m\d</td>.*?</tr>", table)
    cells = {r[8:10]: [html.unescape(c) for c in re.findall(r"<td[^>]*>([^<]*)</td>", r)] for r in rows}
    assert list(cells) == ["m0", "m1", "m2"]
    assert cells["m0"][-3:-1] == ["0 (best)", f"{w[0]:.3f}"]
    assert cells["m1"][-3:-1] == [f"{aiccs[1] - aiccs[0]:+,.1f}", f"{w[1]:.3f}"]
    assert cells["m2"][-3:-1] == ["+123.7", "< 0.001"]
    # in what the page says, not in its figures' drawing coordinates (an SVG path may hold "204.25671")
    prose = re.sub(r"<svg.*?</svg>", "", text, flags=re.S)
    assert "5,671" not in prose and "5671" not in prose


NOT_METRICS = {"model", "friction", "file", "T [°C]", "role", "identification time", "parameter", "value",
               "std. error", "std. error [N]", "95 % interval", "unit", "law", "T_ref [°C]", "value at T_ref",
               "change per °C", "at the range's ends", "inside the per-temperature 95 % intervals", "coefficient",
               "breakpoint T [°C]", "dF [N]", "λ", "note"}


def test_every_metric_in_a_table_is_defined_on_the_page(demo_like):
    heads = {html.unescape(h) for h in re.findall(r"<th[^>]*>([^<]*)</th>", demo_like.text)}
    defined = {html.unescape(d) for d in re.findall(r"<dt>([^<]*)</dt>", demo_like.text)}
    metrics = heads - NOT_METRICS
    assert metrics >= {"max error [%]", "RMSE [nm]", "NRMSE", "final error [%]", "step error [%]", "ΔAICc",
                       "Akaike weight"}
    assert metrics <= defined, metrics - defined
    assert defined <= set(DEFINITIONS)
    # the figure that shows max error says what it is
    caption = re.search(r'id="fig-error-vs-temperature".*?<figcaption>(.*?)</figcaption>', demo_like.text, re.S)
    assert "max|x_sim − x_meas|" in html.unescape(caption.group(1))


def test_laws_are_given_at_a_reference_temperature_with_the_delta_method_error__analytic(demo_like):
    """For an exponential law a exp(b T): the value at T_ref and its standard error from the
    coefficients' covariance, g = (exp(b T), a T exp(b T)), computed here by hand."""
    from thermofriction.reporting import law_at, reference_temperature
    fit = demo_like.fit.to_dict()
    law = demo_like.fit.model.laws["sigma0"]
    Tr = reference_temperature(law, 0.0)
    assert Tr == round(0.5 * (min(FIT_TEMPERATURES) + max(FIT_TEMPERATURES)))
    value, se = law_at(law, Tr, fit, "sigma0")
    names = fit["correlation"]["names"]
    i, j = names.index("sigma0.a"), names.index("sigma0.b")
    sa, sb = fit["parameters"]["sigma0.a"]["stderr"], fit["parameters"]["sigma0.b"]["stderr"]
    r = fit["correlation"]["matrix"][i][j]
    g = np.array([math.exp(law.b * Tr), law.a * Tr * math.exp(law.b * Tr)])
    C = np.array([[sa ** 2, r * sa * sb], [r * sa * sb, sb ** 2]])
    assert value == pytest.approx(law.a * math.exp(law.b * Tr), rel=1e-12)
    assert se == pytest.approx(math.sqrt(g @ C @ g), rel=1e-4)
    text = demo_like.text
    assert f"sigma0(T) = sigma0({Tr:g} °C) · exp(b · (T − {Tr:g} °C))" in html.unescape(text)
    assert "1/°C" in text and not re.search(r"1/C\b", text)


def test_a_law_outside_the_per_temperature_intervals_is_named(model_i, tmp_path):
    """An estimate whose 95 % interval excludes the law (here: at 36 C, far above it) is named in the
    law table and in a sentence; one that contains it is not."""
    from conftest import synthetic_experiments
    data = synthetic_experiments(model_i, [32.0, 36.0, 34.0], duration=0.2)
    data[2].role = "validate"
    fc = model_i.laws["fc"]

    def est(T, shift):
        v = fc(T) * (1 + shift)
        return {"temperature": T, "parameters": {"fc": {"value": v, "ci95": [v * 0.99, v * 1.01], "unit": "N"}}}
    fit = {"details": {"per_temperature": [est(32.0, 0.0), est(36.0, 0.2)]}, "parameters": {}}
    text = html.unescape(report([Entry("Model I", model_i, fit)], data, tmp_path / "r.html"))
    assert "no: outside at 36 °C" in text
    sentence = "The refined law of fc lies outside the per-temperature 95 % interval at 36 °C"
    assert sentence in re.sub("<[^>]+>", "", text)
    assert "outside at 32" not in text


def test_model_ii_breakpoints_are_listed_with_their_temperatures(demo_like):
    dF = tf.load_model("li2009-model-ii").thermal.dF
    text = demo_like.text
    assert "breakpoint T [°C]" in text
    for T, v in zip(dF.T, dF.values):
        assert re.search(rf"<tr><td>{T:.2f}</td><td>{v:.5g}</td>", text), (T, v)


def test_simulation_result_plot_draws_its_arrays():
    model = tf.load_model("li2009-model-i")
    res = tf.simulate(model, 0.4, temperature=([0, 0.4], [31, 39]), sample_rate=2000)
    fig = res.plot()
    # units from the data: µm of displacement, the friction's ~0.4 N flyback peaks in mN
    assert [ax.get_ylabel() for ax in fig.axes] == ["input [V]", "displacement [µm]", "friction force [mN]",
                                                     "temperature [°C]"]
    line = fig.axes[1].get_lines()[0]
    np.testing.assert_allclose(line.get_ydata(), res.displacement * 1e6)
    assert len(tf.simulate(model, 0.2, temperature=35.0).plot().axes) == 3  # a constant temperature: no panel
    with pytest.raises(ValueError, match="velocity"):
        res.plot(what=("nonsense",))


def test_fit_and_validation_plots_show_data_predictions_and_laws(demo_like):
    fit = demo_like.fit
    fig = fit.plot(demo_like.data)
    labels = [ax.get_ylabel() for ax in fig.axes if ax.get_visible()]
    assert labels[:2] == ["displacement [µm]", "RMS(predicted − measured) [nm]"]
    # units from the data: sigma0 ~1e6 N/m in N/µm, fc ~0.5 N in mN (the data stay in SI, the ticks are scaled)
    assert {"sigma0 [N/µm]", "sigma1 [N s/m]", "fc [mN]"} <= set(labels)
    law_ax = next(ax for ax in fig.axes if ax.get_ylabel() == "fc [mN]")
    # the per-temperature estimates: one error bar per fit temperature, at those temperatures
    bars = [c for c in law_ax.containers if c.__class__.__name__ == "ErrorbarContainer"]
    assert len(bars) == 1
    np.testing.assert_allclose(sorted(bars[0].lines[0].get_xdata()), FIT_TEMPERATURES)
    refined = next(ln for ln in law_ax.get_lines() if ln.get_label().startswith("refined law"))
    np.testing.assert_allclose(refined.get_ydata(), fit.model.laws["fc"](refined.get_xdata()))
    assert len(fit.plot().axes) == 3  # without data: the laws alone
    v = demo_like.entries[0].validation
    fig = v.plot(label="Model I")
    assert fig.axes[0].get_ylabel() == "max error [%]"
    assert len(v.plot(metric="step_error_pct").axes) == 1
    with pytest.raises(ValueError, match="max_error_pct"):
        v.plot(metric="rmse_nm")
    import matplotlib.pyplot as plt
    f, ax = plt.subplots()
    assert v.plot(ax=ax) is f  # into the user's own axes
    plt.close(f)


@pytest.mark.skipif(__import__("browser").CHROMIUM is None, reason="Chromium is not installed")
def test_report_in_chromium_is_legible_and_sized_by_its_panels(demo_like):
    """As rendered: every legend's text at 11 px or more, every figure at its own width (the SVG's, 4/3 px per pt:
    sized by its panels, issue 44) or its card's where that is narrower (half of it for the side-by-side pair),
    never stretched; and a one-model report's plots spanning most of their figure. (Until issue 44 every figure
    was stretched to at least 90 % of its card, a single panel blown up to the page's width.)"""
    from browser import Browser
    measure = ("JSON.stringify({legend: Math.min(...[...document.querySelectorAll('figure svg g[id^=legend] text')]"
               ".map(t => parseFloat(getComputedStyle(t).fontSize) * t.getScreenCTM().a)),"
               "figures: [...document.querySelectorAll('figure')].map(f => [f.id, f.querySelector('svg')"
               ".getBoundingClientRect().width, f.closest('section').clientWidth - 48,"
               " f.querySelector('svg').width.baseVal.value]),"
               "axes: [...document.querySelectorAll('figure svg')].map(s => { const r = s.getBoundingClientRect();"
               " const boxes = [...s.querySelectorAll('g[id^=axes_]')].map(g => g.getBoundingClientRect());"
               " return (Math.max(...boxes.map(b => b.right)) - Math.min(...boxes.map(b => b.left))) / r.width; }),"
               "errors: 0})")
    b = Browser()
    try:
        full, errors = b.open((demo_like.folder / "report.html").as_uri(), measure,
                              screenshot=demo_like.folder / "report.png")
        one, errors_one = b.open((demo_like.folder / "one.html").as_uri(), measure,
                                 screenshot=demo_like.folder / "one.png")
    finally:
        b.close()
    assert errors == [] and errors_one == []
    full, one = json.loads(full), json.loads(one)
    assert full["legend"] >= 11 and one["legend"] >= 11, (full["legend"], one["legend"])
    for name, width, card, natural in full["figures"] + one["figures"]:
        pair = name.startswith(("fig-error", "fig-steps"))
        room = (card - 24) / 2 if pair else card  # the pair's two columns and their 24 px gap
        assert abs(width - min(natural, room)) <= 1.5, (name, width, natural, card)
    assert max(w for n, w, c, _ in one["figures"] if n == "fig-displacement") < 0.75 * one["figures"][0][2]
    assert min(one["axes"]) > 0.6, one["axes"]  # the plots, not blank space, fill a one-model report
    keep = Path(__file__).resolve().parents[1] / "build"
    keep.mkdir(exist_ok=True)
    (keep / "report-screenshot.png").write_bytes((demo_like.folder / "report.png").read_bytes())


def test_truth_section_counts_covered_points_per_parameter_and_says_why_a_fit_cannot_be_compared():
    """A hand-made recovery (what FitResult.recovery returns): the section counts covered points per
    parameter, gives the largest error relative to the truth, and carries the reason verbatim."""
    from thermofriction.reporting import truth_section
    rows = [{"parameter": "fc", "temperature": T, "truth": 1.0, "value": v, "lower": v - 0.01, "upper": v + 0.01,
             "covered": abs(v - 1.0) <= 0.01} for T, v in ((30.0, 1.005), (35.0, 1.02), (40.0, 0.995))]
    page = truth_section({"Model I": {"summary": "2 of 3 covered", "rows": rows},
                          "Model II": {"summary": "not comparable with the truth: a reason", "rows": []}})
    assert "2 of 3" in page and ">2<" in page  # largest error 2 % of the truth
    assert "not comparable with the truth: a reason" in page
    assert page.count("<tr>") >= 1 + 3 + 1 + 1
