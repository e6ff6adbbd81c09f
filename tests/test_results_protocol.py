"""One results protocol for every result (thermofriction.results.Result): to_dict/to_json, summary, report,
_repr_html_, to_dataframe and plot, on a small instance of each, checked against the result's own fields."""

from __future__ import annotations

import json

import numpy as np
import pytest
from matplotlib.figure import Figure

import thermofriction as tf
from thermofriction import control as C
from thermofriction.heating import simulate_heating
from thermofriction.results import Result


def _simulation():
    res = tf.simulate(tf.load_model("li2009-base"), 0.02, temperature=35.0)
    return res, "displacement", res.displacement


def _fit():
    data = tf.synthesize(tf.load_model("li2009-base"), [35.0], duration=0.05, seed=1)
    res = tf.identify(data, "base", starts=1)
    return res, "value", np.array([p.value for p in res.parameters.values()])


def _validation():
    data = tf.synthesize(tf.load_model("li2009-base"), [35.0, 38.0], duration=0.05, seed=2)
    res = tf.validate(tf.load_model("li2009-base"), data)
    return res, "max_error_pct", np.array([p.max_error_pct for p in res.predictions])


def _heating():
    res = simulate_heating(tf.load_model("li2009-self-heating"), 2.0, samples=50)
    return res, "temperature", res.temperature


def _loop():
    res = C.simulate_loop(tf.load_model("stage-model-i"), C.sine_reference(1e-3, 0.5, 0.2), temperature=30.0)
    return res, "error", res.error


def _plant():
    from thermofriction.identification import fit_plant, step_response
    t = np.linspace(0.0, 0.01, 400)
    u = np.where(t >= 1e-3, 10.0, 0.0)
    x = step_response(t, 0.3, 6000.0, 2e-6, 10.0, 1e-3)
    res = fit_plant(t, u, x)
    return res, "value", np.array([p.value for p in res.parameters.values()])


def _sweep():
    res = tf.sweep(tf.load_model("li2009-base"), {"amplitude": [10.0, 20.0]}, duration=0.04, temperature=35.0,
                   metrics=["final_displacement"], scheduler="sequential")
    return res, "final_displacement[m]", res["final_displacement"]


def _fleet():
    model = tf.load_model("li2009-base")
    data = [tf.synthesize(model, [35.0], duration=0.05, seed=k) for k in (1, 2)]
    res = tf.identify_fleet(data, "base", scheduler="sequential", starts=1)
    return res, "rmse", np.array([res.fits[n].rmse for n in res.names])


def _propagation():
    data = tf.synthesize(tf.load_model("li2009-base"), [35.0], duration=0.3, sample_rate=5000, seed=3)
    fit = tf.identify(data, "base", starts=1, parameters=["sigma0", "fc"])
    res = tf.propagate(fit, [35.0], draws=3, duration=0.04, scheduler="sequential")
    return res, "nominal_step", res.nominal_step


RESULTS = [_simulation, _fit, _validation, _heating, _loop, _plant, _sweep, _fleet, _propagation]


@pytest.mark.parametrize("make", RESULTS)
def test_every_result_follows_the_protocol(make):
    res, column, values = make()
    assert isinstance(res, Result)
    data = json.loads(res.to_json())
    assert data == json.loads(json.dumps(data))  # plain JSON
    frame = res.to_dataframe()
    assert np.allclose(frame[column].to_numpy(dtype=float), values, equal_nan=True)
    assert isinstance(res.plot(), Figure)
    page = res._repr_html_()
    assert page.startswith("<") and "</table>" in page
    assert isinstance(res.report(), str) and res.report() == str(res)


def test_results_json_holds_what_the_result_holds(tmp_path):
    res, _, values = _loop()
    res.to_json(tmp_path / "loop.json")
    data = json.loads((tmp_path / "loop.json").read_text())
    assert data["rms_error"] == pytest.approx(res.rms_error)
    assert np.allclose(data["samples"]["error"], values)


@pytest.mark.parametrize("make", RESULTS)
def test_one_summary_type_and_one_formatter(make):
    """summary() is a Summary (a plain-JSON mapping) everywhere, and the text report is the one formatter's
    rendering of the result's blocks."""
    from thermofriction.results import Summary, as_text
    res = make()[0]
    s = res.summary()
    assert isinstance(s, Summary) and json.loads(json.dumps(s)) == json.loads(json.dumps(dict(s)))
    assert res.report() == as_text(res._blocks())


def test_findings_are_values_and_warnings_at_the_edge():
    """A temperature outside a law's range: a Finding on the simulation's result, and the same warning (category
    and text) from simulate."""
    from thermofriction.errors import TemperatureRangeWarning
    from thermofriction.results import Finding
    with pytest.warns(TemperatureRangeWarning, match="outside the calibrated range") as caught:
        res = tf.simulate(tf.load_model("li2009-model-i"), 0.02, temperature=42.0)
    assert [(f.category, f.message) for f in res.findings] == [(w.category, str(w.message)) for w in caught
                                                                if w.category is TemperatureRangeWarning]
    assert all(isinstance(f, Finding) for f in res.findings)


def test_validation_keeps_its_findings_as_values_with_their_categories():
    """validate's warnings are its findings' texts; the findings keep the category; validate warns none of a
    prediction's (they are on the result), as before."""
    import warnings as W

    from thermofriction.errors import TemperatureRangeWarning
    model = tf.load_model("li2009-model-i")
    data = tf.synthesize(model, [29.0], duration=0.05, sample_rate=2000.0, noise=0.0, seed=1)
    with W.catch_warnings(record=True) as caught:
        W.simplefilter("always")
        res = tf.validate(model, data)
    assert res.warnings == [f.message for f in res.findings]
    assert [f.category for f in res.findings] == [TemperatureRangeWarning]
    assert "temperature 29 C is outside" in res.findings[0].message
    assert not [w for w in caught if w.category is TemperatureRangeWarning]


def test_collecting_is_per_thread():
    """Two threads inside their collecting blocks at once (a barrier) each get their own findings."""
    import threading

    from thermofriction.results import Finding, collecting, emit
    barrier, out = threading.Barrier(2), {}

    def task(i):
        with collecting() as found:
            barrier.wait(timeout=30)
            emit([Finding(UserWarning, f"task {i}")])
            barrier.wait(timeout=30)
        out[i] = [f.message for f in found]

    threads = [threading.Thread(target=task, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert out == {0: ["task 0"], 1: ["task 1"]}
