"""Validation metrics (docs/formats.md#validation-metrics) and the HTML report, the latter opened in a real browser."""

import json
import re
import types
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf
from conftest import synthetic_experiments
from thermofriction.reporting import Entry, report
from thermofriction.validation import step_sizes, validate


def dataset(model, fit, held_out, **kw):
    exps = synthetic_experiments(model, list(fit) + list(held_out), **kw)
    for e in exps:
        e.role = "validate" if e.temperature in held_out else "fit"
    return types.SimpleNamespace(experiments=exps, fit=[e for e in exps if e.role == "fit"], name="synthetic")


def test_metrics_of_the_true_model_on_noise_free_data_are_zero__definition(model_i):
    data = dataset(model_i, [31.0, 40.0], [35.0], duration=0.6)
    res = validate(model_i, data)
    for m in res.experiments:
        # what is left is the solver's error (data at rtol 1e-10, prediction at 1e-8)
        assert m["max_error_pct"] < 1e-3 and m["nrmse"] < 1e-5 and abs(m["final_error_pct"]) < 1e-3
    assert {m["role"] for m in res.experiments} == {"fit", "validate"}


def test_metrics_follow_their_definitions_for_a_known_error__analytic(model_i):
    """A measurement equal to the prediction plus a known error e(t) = a (t - t0) after t0 (the
    first 1 % of the run, where the zero is matched, is untouched): max error a (t_end - t0) /
    range, RMSE (about the mean offset, as identification measures it) the standard deviation of e,
    final error e(t_end) / net displacement, and every whole period after t0 gains a * period."""
    exp = synthetic_experiments(model_i, [36.0], duration=0.6)[0]
    pred = exp.displacement - exp.displacement[0]
    a, t0 = 1e-7, 0.01
    e = a * np.clip(exp.time - t0, 0, None)
    exp.displacement = exp.displacement - e
    m = validate(model_i, [exp]).experiments[0]
    meas = pred - e
    # to the solver's accuracy (data at rtol 1e-10, prediction at 1e-8: ~1e-5 of the metrics)
    assert m["max_error_pct"] == pytest.approx(100 * e[-1] / np.ptp(meas), rel=1e-4)
    assert m["rmse_offset_removed"] == pytest.approx(np.std(e), rel=1e-4)
    assert m["final_error_pct"] == pytest.approx(100 * e[-1] / meas[-1], rel=1e-4)
    assert m["step_error"] == pytest.approx(a * (3 * 0.2 - t0) / 3, rel=1e-4)  # mean over the 3 periods


def test_step_sizes_of_a_ramp():
    t = np.linspace(0, 1, 1001)
    np.testing.assert_allclose(step_sizes(t, 3 * t, 0.2), np.full(5, 0.6))


def test_validation_json_has_the_spec9_keys(model_i, tmp_path):
    data = dataset(model_i, [32.0], [38.0], duration=0.4)
    validate(model_i, data).to_json(tmp_path / "m.json")
    d = json.loads((tmp_path / "m.json").read_text())
    assert set(d["experiments"][0]) >= {"file", "temperature", "role", "max_error_pct", "rmse_offset_removed",
                                        "nrmse", "final_error_pct", "fit_quality"}


def test_temperatures_outside_a_laws_range_are_reported(model_i):
    data = dataset(model_i, [], [28.0], duration=0.2)
    res = validate(model_i, data)
    assert res.warnings and "28" in res.warnings[0]


def test_a_report_needs_held_out_experiments(model_i, tmp_path):
    data = dataset(model_i, [32.0, 38.0], [], duration=0.2)
    with pytest.raises(tf.InputError, match="validate"):
        report([model_i], data, tmp_path / "r.html")
    assert not (tmp_path / "r.html").exists()


@pytest.fixture(scope="module")
def written_report(tmp_path_factory, model_i):
    folder = tmp_path_factory.mktemp("report")
    data = dataset(model_i, [30.8, 33.9, 36.5, 38.4, 41.5], [35.0, 40.0], duration=1.0, noise=20e-9, seed=4)
    fit1 = tf.identify(data, "model-i", init=model_i, starts=1)
    fit2 = tf.identify(data, "model-ii", init=tf.load_model("li2009-base"), procedure="both", starts=1)
    base = tf.load_model("li2009-base")
    report([fit1, fit2, base], data, folder / "report.html", figures_dir=folder / "figures")
    return folder


def test_report_is_self_contained_with_every_figure(written_report):
    text = (written_report / "report.html").read_text()
    assert "<script" not in text
    assert not re.search(r"""(src|href)\s*=\s*["']?https?:|url\(\s*["']?https?:|@import""", text)
    for fig in ("displacement", "steps", "model-i-parameters", "model-ii", "residuals"):
        assert f'id="fig-{fig}"' in text, fig
        assert (written_report / "figures" / f"{fig}.svg").exists()
        assert (written_report / "figures" / f"{fig}.png").stat().st_size > 1000
    for heading in ("Model comparison", "Errors per experiment", "Identified parameters", "data SHA-256"):
        assert heading in text


@pytest.mark.skipif(__import__("browser").CHROMIUM is None, reason="Chromium is not installed")
def test_report_in_a_real_browser_has_no_console_errors_and_every_figure_shows(written_report):
    from browser import Browser
    b = Browser()
    try:
        sizes, errors = b.open((written_report / "report.html").as_uri(),
                               "JSON.stringify([...document.querySelectorAll('figure svg')].map("
                               "s => [s.getBoundingClientRect().width, s.getBoundingClientRect().height]))",
                               screenshot=written_report / "report.png")
    finally:
        b.close()
    sizes = json.loads(sizes)
    assert errors == []
    assert len(sizes) >= 5 and all(w > 100 and h > 100 for w, h in sizes), sizes
    shot = Path(written_report / "report.png")
    assert shot.stat().st_size > 50_000
    keep = Path(__file__).resolve().parents[1] / "build" / "report-screenshot.png"
    keep.parent.mkdir(exist_ok=True)
    keep.write_bytes(shot.read_bytes())


def test_a_fit_that_did_not_converge_says_so_in_the_report(model_i, tmp_path):
    """Never silently: an entry whose fit did not converge (success False in its JSON) is named,
    with the optimiser's message, in the report's warnings; a converged one is not."""
    from thermofriction.reporting import Entry

    data = dataset(model_i, [32.0, 38.0], [35.0], duration=0.2)
    fits = [Entry("stalled", model_i, {"success": False, "message": "maximum evaluations reached"}),
            Entry("fine", model_i, {"success": True, "message": "converged"})]
    text = report(fits, data, tmp_path / "r.html")
    assert "stalled: the fit did not converge: maximum evaluations reached" in text
    assert "fine: the fit did not converge" not in text
    assert (tmp_path / "r.html").read_text() == text
