"""Issue 40, item 4: advice is said only with a gain that holds out of sample (identification/advice.py). A held value
the score test calls contradicted is freed in a short refit, and that refit is scored on the dataset's held-out runs
(as the fit's generalisation is: validate, the fit's offset policy); a gain on the fit runs that does not hold there
is not advice, and without held-out runs the gain is said as measured on the fit runs, and that it is. Truths made by
the independent SciPy reference (tests/reference/) or by the package's own preset exactly as the demo makes its data
(the demo's false advice is the case); the held-out numbers said are checked against full refits scored by
tf.validate."""

import dataclasses
import re
import types

import numpy as np
import pytest

import thermofriction as tf
from stribeck_truths import reference_experiments, start_from, stribeck_truth
from thermofriction.demo import FIT_TEMPERATURES, HELD_OUT
from thermofriction.identification import advice
from thermofriction.measurements import amount

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning")

#: "freeing X lowers the held-out RMSE A nm -> B nm (fit runs C nm -> D nm; ..."
SAID = re.compile(r"freeing (.+?) lowers the (held-out) RMSE ([\d.e+-]+) nm -> ([\d.e+-]+) nm "
                  r"\(fit runs ([\d.e+-]+) nm -> ([\d.e+-]+) nm; a refit of \d+ evaluations")


def _held(res, name):
    return next(h for h in res.fit_quality["held"] if h["name"] == name)


def _with_held_out(fit, held):
    """A dataset of reference runs: ``fit`` fitted, ``held`` held out (role "validate")."""
    for e in held:
        e.role = "validate"
    return types.SimpleNamespace(experiments=fit + held, fit=fit, validate=held)


def _heldout_rmse(model, data):
    v = tf.validate(model, data, data.validate)
    return float(np.sqrt(np.mean([p.rmse ** 2 for p in v.predictions])))


def test_the_demo_model_ii_stribeck_advice_does_not_hold_out():
    """The demo's data (the paper's Model I preset, no Stribeck effect; made as thermofriction/demo.py makes them)
    fitted by Model II: fs held at fc was called contradicted, "fit a Stribeck effect", on a refit's gain on the fit
    runs (4.3 % of the misfit). On the held-out runs that refit gains 1.4 %, under half of it: no advice, not
    contradicted, and the header, the warnings and the JSON say the same."""
    truth = tf.load_model("li2009-model-i")
    data = tf.synthesize(truth, FIT_TEMPERATURES, validate=HELD_OUT, duration=2.0, sample_rate=10_000.0,
                         noise=20e-9, quantization=5e-9, temperature_noise=0.05, seed=2009)
    res = tf.identify(data, "model-ii", init=tf.load_model("li2009-base"))
    fs = _held(res, "fs")
    assert fs["refit_gain"] >= advice.MATERIAL  # the gain on the fit runs is there ...
    assert fs["refit_basis"] == advice.HELD_OUT and fs["refit_heldout_gain"] < advice.HOLDS * fs["refit_gain"]
    assert not fs["contradicted"] and not fs["refit_holds"]  # ... and does not hold out
    assert not any("fit a Stribeck effect" in w for w in res.warnings), res.warnings
    assert not any(h["contradicted"] for h in res.fit_quality["held"])
    assert "held value(s) contradicted" not in res.report().splitlines()[1]
    # the held-out RMSE before is the fit's own, as its generalisation scores it
    assert fs["heldout_rmse"] == pytest.approx(res.fit_quality["generalisation"]["heldout_rmse"], rel=1e-9)
    said = next(w for w in res.warnings if w.startswith("the fit is not adequate"))
    assert "freeing a Stribeck effect removes" in said and "does not hold out of sample" in said


@pytest.fixture(scope="module")
def heavy_held_out(model_i):
    """The paper's Model I actuator with an end-effector mass twice the start's (0.1 kg against 0.05), by the
    reference, with two runs held out between the fit temperatures."""
    truth = dataclasses.replace(model_i, plant=dataclasses.replace(model_i.plant, end_effector_mass=0.1))
    data = _with_held_out(reference_experiments(truth, (31.0, 36.0, 41.0), duration=0.3, seed=11),
                          reference_experiments(truth, (33.5, 38.5), duration=0.3, seed=111))
    return data, tf.identify(data, "model-i", init=model_i)


def test_a_wrong_mass_is_advised_with_held_out_numbers_a_full_refit_bears_out(heavy_held_out, model_i):
    """The 2x wrong held mass: contradicted, said with the held-out RMSE before and after; the before is the fit's
    own held-out RMSE (tf.validate), and a full fit with m_e free, scored by tf.validate on the held-out runs, does at
    least as well as the short refit said (1 % of the RMSE: the refit stops after 12 evaluations). A Stribeck
    effect, which the truth does not have, is not advised."""
    data, res = heavy_held_out
    m_e = _held(res, "m_e")
    assert m_e["contradicted"] and m_e["refit_basis"] == advice.HELD_OUT
    warning = next(w for w in res.warnings if w.startswith("m_e held at"))
    said = SAID.search(warning)
    assert said and said.group(1) == "m_e" and said.group(2) == "held-out", warning
    before, after = float(said.group(3)) * 1e-9, float(said.group(4)) * 1e-9
    assert before == pytest.approx(_heldout_rmse(res.model, data), rel=1e-3)
    assert after <= before * np.sqrt(1 - advice.MATERIAL)
    freed = tf.identify(data, "model-i", init=model_i, free=["m_e"])
    assert _heldout_rmse(freed.model, data) <= after * 1.01
    assert not _held(res, "fs")["contradicted"]
    assert not any("fit a Stribeck effect" in w for w in res.warnings)


def test_a_real_stribeck_effect_is_advised_with_held_out_numbers_a_full_refit_bears_out():
    """fs = 1.5 fc in the truth (reference), fitted by Model I as plain LuGre from a start 2-3x off, one run held
    out: fs held at fc is contradicted and said with its held-out gain; a full Model I fit with fs and its law,
    scored by tf.validate on the held-out run, does at least as well as the refit said."""
    truth = stribeck_truth()
    data = _with_held_out(reference_experiments(truth, seed=3), reference_experiments(truth, (35.5,), seed=103))
    res = tf.identify(data, "model-i", init=start_from(truth, {"sigma0": 2.5, "sigma1": 2.0, "fc": 0.45}))
    fs = _held(res, "fs")
    assert fs["contradicted"] and fs["refit_basis"] == advice.HELD_OUT, fs
    warning = next(w for w in res.warnings if w.startswith("fs held at fc (no Stribeck effect) is contradicted"))
    said = SAID.search(warning)
    assert said and said.group(1) == "a Stribeck effect" and said.group(2) == "held-out", warning
    before, after = float(said.group(3)) * 1e-9, float(said.group(4)) * 1e-9
    assert before == pytest.approx(_heldout_rmse(res.model, data), rel=1e-3)
    assert 1 - (after / before) ** 2 >= advice.HOLDS * fs["refit_gain"]
    full = tf.identify(data, "model-i", init=start_from(truth, {"sigma0": 1.3, "sigma1": 1.3, "fc": 0.8, "fs": 0.8}),
                       parameters=["sigma0", "sigma1", "fc", "fs"], laws={n: "linear" for n in truth.laws})
    assert _heldout_rmse(full.model, data) <= after * 1.01


def test_without_held_out_runs_the_advice_says_its_gain_is_in_sample(model_i):
    """No held-out runs: the 2x wrong mass (reference) is still advised, with the gain measured on the fit runs, and
    the text and the JSON say that no run was held out to check it (a blocked cross-validation was measured and
    dropped: advice.py). The in-sample numbers are the fit's (its RMSE) and the refit's."""
    truth = dataclasses.replace(model_i, plant=dataclasses.replace(model_i.plant, end_effector_mass=0.1))
    data = reference_experiments(truth, (31.0, 36.0, 41.0), duration=0.3, seed=11)
    res = tf.identify(data, "model-i", init=model_i)
    m_e = _held(res, "m_e")
    assert m_e["contradicted"] and m_e["refit_basis"] == advice.NO_RUN_HELD_OUT
    assert "refit_heldout_rmse" not in m_e and m_e["refit_gain"] >= advice.MATERIAL
    warning = next(w for w in res.warnings if w.startswith("m_e held at"))
    assert f"lowers the RMSE on the fit runs {amount(res.rmse, 'm').split()[0]} nm" in warning, warning
    assert advice.NO_RUN_HELD_OUT in warning, warning


@pytest.mark.parametrize("offset", ["shared", "per-experiment"])
def test_a_refit_is_scored_on_held_out_runs_as_the_fit_is__force_data(offset):
    """Force data (look-alike joint, tests/lookalike.py; its last run held out): a refit is scored on the held-out runs
    with its offset estimated on the fit runs as the fit's was (Measurement.complete), not the one of the model it
    started from. The refit that frees nothing, at the fit's own values from a model whose offset is 0.1 N m off,
    must score exactly the fit's held-out RMSE, which front.py's generalisation reports."""
    from lookalike import lookalike_experiments
    from thermofriction.fitting.parameters import get_value
    from thermofriction.measurements import measurement_of

    data, _ = lookalike_experiments(offsets=(0.02, -0.015, 0.03, 0.01))
    res = tf.identify(data, "base", starts=1, offset=offset)
    measurement = measurement_of(data, offset=offset)
    outside = advice.OutOfSample(res, data.fit, measurement, data, data.validate)
    before = outside.before()
    assert before == pytest.approx(res.fit_quality["generalisation"]["heldout_rmse"], rel=1e-9)
    theta = [get_value(res.model, p.name) for p in res.parameters.varying]
    off = dataclasses.replace(res.model, plant=dataclasses.replace(res.model.plant,
                                                                   sensor_offset=res.model.plant.sensor_offset + 0.1))
    assert outside.after(off, res.parameters, theta) == pytest.approx(before, rel=1e-6)
