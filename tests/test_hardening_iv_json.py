"""Hardening IV (issue 41): an edited fit JSON (the results that `identify --json` writes, read by `propagate`), a
damaged propagation result (`report --bands`) and the model file's ripple table. Each bad input is one message
naming the file and the key, exit status 2, before any work, and no output file."""

import json

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.cli import main
from thermofriction.cli.fits import load_fit
from thermofriction.scale.propagate import check_drawable, draw_parameters

PROPAGATE = ["--temperatures", "30", "--draws", "3", "--duration", "0.05", "--scheduler", "sequential", "-q"]


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """A base fit of sigma0 and fc (both well determined) at 30 C: its dataset, model file and results JSON."""
    folder = tmp_path_factory.mktemp("fit")
    data = tf.synthesize(tf.load_model("li2009-model-i"), [30.0], duration=0.5, sample_rate=2000, seed=1)
    tf.save_dataset(data, folder / "data")
    assert main(["identify", str(folder / "data"), "--method", "base", "--parameters", "sigma0,fc", "--starts", "1",
                 "-q", "-o", str(folder / "fit.toml"), "--json", str(folder / "fit.json")]) == 0
    return folder


def _one_error(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("thermofriction: error: "), err
    return err[0]


# -- the fit JSON, edited ------------------------------------------------------------------------

def _sigma0(d, key, value):
    d["parameters"]["sigma0"][key] = value


def _with_sigma1(d, matrix):
    """A third fitted parameter at the model's own value (a valid edit) and a 3 x 3 correlation ``matrix``."""
    d["parameters"]["sigma1"] = {"value": d["model"]["friction"]["sigma1"], "stderr": 1e-3, "ci95": None,
                                 "unit": "N s/m", "vary": True}
    d["correlation"] = {"names": ["sigma0", "fc", "sigma1"], "matrix": matrix}


#: (edit of the parsed JSON, or raw JSON text with @@ where the value goes, the words the message must hold)
EDITS = {
    "iterations 1e400": (lambda d: d.__setitem__("iterations", "@@"), "1e400", "iterations"),
    "iterations 2.5": (lambda d: d.__setitem__("iterations", 2.5), None, "iterations"),
    "iterations -3": (lambda d: d.__setitem__("iterations", -3), None, "iterations"),
    "iterations text": (lambda d: d.__setitem__("iterations", "five"), None, "iterations"),
    "n_points 1e400": (lambda d: d.__setitem__("n_points", "@@"), "1e400", "n_points"),
    "starts null": (lambda d: d.__setitem__("starts", None), None, "starts"),
    "jacobian_evaluations list": (lambda d: d.__setitem__("jacobian_evaluations", [1]), None, "jacobian_evaluations"),
    "value 1e400": (lambda d: _sigma0(d, "value", "@@"), "1e400", "'sigma0': value"),
    "value NaN": (lambda d: _sigma0(d, "value", "@@"), "NaN", "'sigma0': value"),
    "value nan string": (lambda d: _sigma0(d, "value", "nan"), None, "'sigma0': value"),
    "value 400 digits": (lambda d: _sigma0(d, "value", "@@"), "9" * 400, "'sigma0': value"),
    "value as text": (lambda d: _sigma0(d, "value", "1944055.48"), None, "'sigma0': value"),
    "value negative": (lambda d: _sigma0(d, "value", -d["parameters"]["sigma0"]["value"]), None, "'sigma0': value"),
    "value 0": (lambda d: _sigma0(d, "value", 0), None, "'sigma0': value"),
    "stderr negative": (lambda d: _sigma0(d, "stderr", -3e4), None, "'sigma0': stderr"),
    "stderr 1e300": (lambda d: _sigma0(d, "stderr", 1e300), None, "'sigma0'"),
    "stderr infinite": (lambda d: _sigma0(d, "stderr", "inf"), None, "'sigma0'"),
    "stderr missing": (lambda d: d["parameters"]["sigma0"].pop("stderr"), None, "'sigma0'"),
    "ci95 reversed": (lambda d: _sigma0(d, "ci95", d["parameters"]["sigma0"]["ci95"][::-1]), None, "ci95"),
    "vary 'no'": (lambda d: _sigma0(d, "vary", "no"), None, "'sigma0': vary"),
    "unit a list": (lambda d: _sigma0(d, "unit", [1]), None, "'sigma0': unit"),
    "at_bound 7": (lambda d: _sigma0(d, "at_bound", 7), None, "'sigma0': at_bound"),
    "unknown parameter": (lambda d: d["parameters"].__setitem__("bogus", d["parameters"].pop("fc")), None,
                          "'bogus'"),
    "correlation not PSD": (lambda d: _with_sigma1(d, [[1, 0.9, 0.9], [0.9, 1, -0.9], [0.9, -0.9, 1]]), None,
                            "'correlation' is not positive semi-definite"),
    "correlation above 1": (lambda d: d["correlation"].__setitem__("matrix", [[1, 1.5], [1.5, 1]]), None,
                            "'correlation' must lie in [-1, 1]"),
    "correlation asymmetric": (lambda d: d["correlation"].__setitem__("matrix", [[1, 0.5], [-0.5, 1]]), None,
                               "'correlation' is not symmetric"),
    "correlation diagonal 2": (lambda d: d["correlation"].__setitem__("matrix", [[2, 0], [0, 1]]), None,
                               "'correlation' must have 1 on its diagonal"),
    "correlation 3 x 3": (lambda d: d["correlation"].__setitem__("matrix", [[1, 0, 0]] * 3), None, "2 x 2"),
    "correlation ragged": (lambda d: d["correlation"].__setitem__("matrix", [[1, 0], [0]]), None, "2 x 2"),
    "correlation Infinity": (lambda d: d["correlation"]["matrix"][0].__setitem__(1, "@@"), "Infinity",
                             "correlation"),
    "noise negative": (lambda d: d["fit_quality"].__setitem__("noise", -1.0), None, "fit_quality: noise"),
    "noise inf": (lambda d: d["fit_quality"].__setitem__("noise", "inf"), None, "fit_quality: noise"),
    "fit_quality a list": (lambda d: d.__setitem__("fit_quality", [1]), None, "fit_quality"),
    "warnings a string": (lambda d: d.__setitem__("warnings", "abc"), None, "warnings"),
    "method a number": (lambda d: d.__setitem__("method", 5), None, "method"),
    "success 'no'": (lambda d: d.__setitem__("success", "no"), None, "success"),
    "measurement unknown": (lambda d: d.__setitem__("measurement", "bogus"), None, "measurement"),
    "parameters missing": (lambda d: d.pop("parameters"), None, "'parameters'"),
    "model a number": (lambda d: d.__setitem__("model", 3), None, "'model'"),
}


def _edited(fit, edit, raw):
    d = json.loads(fit.read_text())
    edit(d)
    text = json.dumps(d)
    return text.replace('"@@"', raw) if raw is not None else text


@pytest.mark.parametrize("case", EDITS)
def test_an_edited_fit_json_is_refused_naming_the_file_and_the_key(case, fitted, tmp_path, capsys):
    edit, raw, words = EDITS[case]
    path = tmp_path / "fit.json"
    path.write_text(_edited(fitted / "fit.json", edit, raw))
    out = tmp_path / "bands.json"
    assert main(["propagate", str(path), *PROPAGATE, "-o", str(out)]) == 2
    err = _one_error(capsys)
    assert str(path) in err and words in err, err
    assert not out.exists()


@pytest.mark.parametrize("how", ["empty", "truncated", "not UTF-8", "a list"])
def test_a_truncated_or_foreign_fit_json_is_one_message(how, fitted, tmp_path, capsys):
    whole = (fitted / "fit.json").read_bytes()
    path = tmp_path / "fit.json"
    path.write_bytes({"empty": b"", "truncated": whole[:len(whole) // 2], "not UTF-8": b"\x00\xff\xfe",
                      "a list": b"[1, 2]"}[how])
    assert main(["propagate", str(path), *PROPAGATE, "-o", str(tmp_path / "b.json")]) == 2
    assert str(path) in _one_error(capsys) and not (tmp_path / "b.json").exists()


def test_the_fit_json_as_written_and_a_valid_third_parameter_still_propagate(fitted, tmp_path, capsys):
    """The checks refuse edits, not fits: the file as identify wrote it propagates, and so does a positive
    definite correlation over a third parameter at the model's value (the same edit as the refused one above)."""
    assert main(["propagate", str(fitted / "fit.json"), *PROPAGATE, "-o", str(tmp_path / "b.json")]) == 0
    path = tmp_path / "fit3.json"
    path.write_text(_edited(fitted / "fit.json", lambda d: _with_sigma1(d, [[1, 0.5, 0.2], [0.5, 1, -0.3],
                                                                             [0.2, -0.3, 1]]), None))
    fit = load_fit(path)
    check_drawable(fit)
    names, draws = draw_parameters(fit, 4000, 1)
    assert names == ["sigma0", "fc", "sigma1"] and np.all(np.isfinite(draws))
    # the draws carry the correlation written (log-space draws: their logs' correlation, to sampling error)
    assert abs(np.corrcoef(np.log(draws[:, 1]), np.log(draws[:, 2]))[0, 1] + 0.3) < 0.05
    capsys.readouterr()


def test_a_correlation_negative_to_rounding_is_taken_as_semi_definite(fitted):
    """A singular correlation (two parameters correlated +1) that rounding left with an eigenvalue of -1e-12 is
    drawn from (the draws' square root clips it to 0; docs/cli.md#propagate), not refused."""
    fit = load_fit(fitted / "fit.json")
    fit.correlation = np.array([[1.0, 1.0 + 1e-12], [1.0 + 1e-12, 1.0]])
    assert np.linalg.eigvalsh(fit.correlation)[0] < 0
    check_drawable(fit)
    names, draws = draw_parameters(fit, 200, 0)
    assert np.all(np.isfinite(draws))
    z = np.log(draws)  # both drawn log-normally: their logs' standardised values are equal (correlation 1)
    z = (z - z.mean(axis=0)) / z.std(axis=0)
    assert np.allclose(z[:, 0], z[:, 1], atol=1e-4)


def test_the_api_refuses_a_negative_standard_error_before_any_simulation(fitted, monkeypatch):
    def no_simulation(*args, **kwargs):
        raise AssertionError("simulated before the fit's uncertainty was checked")

    monkeypatch.setattr("thermofriction.simulation.simulate", no_simulation)
    fit = load_fit(fitted / "fit.json")
    fit.parameters["sigma0"].stderr = -1.0
    with pytest.raises(tf.InputError, match="'sigma0': its standard error must be 0 or more"):
        tf.propagate(fit, [30.0], draws=3, duration=0.05, scheduler="sequential")


# -- report --bands: the propagation result's axes ------------------------------------------------

@pytest.mark.parametrize("time", [[], [0.0, 0.02, 0.01], [0.0, "nan", 0.02]])
def test_report_bands_refuses_a_bad_time_axis_before_its_work(time, fitted, tmp_path, capsys):
    bands = tmp_path / "bands.json"
    assert main(["propagate", str(fitted / "fit.json"), *PROPAGATE, "-o", str(bands)]) == 0
    d = json.loads(bands.read_text())
    d["time"] = time
    for key in ("nominal", "median", "lower", "upper", "prediction_lower", "prediction_upper"):
        d[key] = [[0.0] * len(time)]
    bands.write_text(json.dumps(d))
    page = tmp_path / "r.html"
    assert main(["report", str(fitted / "fit.toml"), str(fitted / "data"), "--bands", str(bands),
                 "-o", str(page)]) == 2
    err = _one_error(capsys)
    assert str(bands) in err and "'time'" in err and not page.exists()


# -- the ripple table ------------------------------------------------------------------------------

def _model_file(tmp_path, fitted, lines):
    text = (fitted / "fit.toml").read_text().replace("[friction]\n", "[friction]\n" + lines + "\n", 1)
    path = tmp_path / "ripple.toml"
    path.write_text(text)
    return path


def test_an_absent_ripple_amplitude_is_zero_as_documented(fitted, tmp_path):
    absent = tf.load_model(_model_file(tmp_path, fitted, "ripple = { period = 1e-3, cos = [0.1] }"))
    zero = tf.load_model(_model_file(tmp_path, fitted, "ripple = { period = 1e-3, cos = [0.1], sin = [0.0] }"))
    assert absent.friction.ripple_cos1 == 0.1 and absent.friction.ripple_sin1 is None
    a, b = (tf.simulate(m, 0.01, temperature=30, sample_rate=2000) for m in (absent, zero))
    assert np.array_equal(a.displacement, b.displacement)
    plain = tf.simulate(tf.load_model(fitted / "fit.toml"), 0.01, temperature=30, sample_rate=2000)
    assert np.max(np.abs(a.displacement - plain.displacement)) > 1e-3 * np.max(np.abs(plain.displacement))


#: (the [friction] lines, the words the message must hold)
BAD_RIPPLES = {
    "period 0": ("ripple = { period = 0.0, cos = [0.1] }", "'ripple.period' must be positive"),
    "period negative": ("ripple = { period = -1e-3, cos = [0.1] }", "'ripple.period' must be positive"),
    "period nan": ("ripple = { period = nan, cos = [0.1] }", "'ripple.period' must be finite"),
    "period inf": ("ripple = { period = inf }", "'ripple.period' must be finite"),
    "period a string": ('ripple = { period = "1e-3", cos = [0.1] }', "'ripple.period' must be a number"),
    "period missing": ("ripple = { cos = [0.1] }", "needs its 'period'"),
    "cos a string": ('ripple = { period = 1e-3, cos = "0.1" }', "'ripple.cos' must be an array"),
    "cos a number": ("ripple = { period = 1e-3, cos = 0.1 }", "'ripple.cos' must be an array"),
    "cos empty": ("ripple = { period = 1e-3, cos = [] }", "'ripple.cos' must be an array"),
    "sin holds a string": ('ripple = { period = 1e-3, sin = ["a"] }', "'ripple.sin[0]' must be a number"),
    "sin holds -inf": ("ripple = { period = 1e-3, sin = [-inf] }", "'ripple.sin[0]' must be finite"),
    "4 harmonics": ("ripple = { period = 1e-3, cos = [0.1, 0.1, 0.1, 0.1] }", "at most 3 harmonics"),
    "unknown key": ("ripple = { period = 1e-3, tan = [0.1] }", "unknown keys ['tan']"),
    "not a table": ('ripple = "yes"', "'ripple' must be a table"),
    "table and flat key": ("ripple = { period = 1e-3, cos = [0.1] }\nripple_cos1 = 0.2",
                           "'ripple_cos1' is given both"),
    "amplitude without period": ("ripple_sin2 = 0.1", "need the ripple's period"),
}


@pytest.mark.parametrize("case", BAD_RIPPLES)
def test_a_bad_ripple_table_is_one_message_naming_file_and_key(case, fitted, tmp_path, capsys):
    lines, words = BAD_RIPPLES[case]
    path = _model_file(tmp_path, fitted, lines)
    out = tmp_path / "sim.csv"
    assert main(["simulate", str(path), "--duration", "0.005", "-o", str(out)]) == 2
    err = _one_error(capsys)
    assert str(path) in err and words in err, err
    assert not out.exists()


def test_ripple_arrays_of_different_lengths_are_harmonics_absent_as_zero(fitted, tmp_path):
    m = tf.load_model(_model_file(tmp_path, fitted, "ripple = { period = 1e-3, cos = [0.1], sin = [0.0, 0.0, 0.02] }"))
    assert (m.friction.ripple_cos1, m.friction.ripple_sin3, m.friction.ripple_cos3) == (0.1, 0.02, None)


def test_fitting_a_ripple_amplitude_without_a_period_is_a_usage_error_before_the_fit(fitted, tmp_path, capsys):
    out = tmp_path / "x.toml"
    assert main(["identify", str(fitted / "data"), "--method", "base", "--init", str(fitted / "fit.toml"),
                 "--parameters", "sigma0,fc,ripple_cos1", "-q", "-o", str(out)]) == 2
    err = _one_error(capsys)
    assert str(fitted / "fit.toml") in err and "ripple_cos1" in err and "ripple's period" in err
    assert not out.exists()
    data = tf.load_dataset(fitted / "data")
    for method in ("base", "model-i"):  # the API too, for each method that takes friction parameters
        with pytest.raises(tf.InputError, match="the initial model: ripple amplitudes \\(ripple_sin2\\)"):
            tf.identify(data, method, init=tf.load_model("li2009-model-i"), parameters=["sigma0", "ripple_sin2"])
