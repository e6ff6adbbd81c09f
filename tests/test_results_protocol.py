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


@pytest.mark.parametrize("make", [_simulation, _fit, _validation, _heating, _loop])
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
