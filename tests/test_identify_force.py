"""Identification, validation and report on force (torque) data (docs/force-data.md).

The data are made by the independent reference implementation (tests/reference, SciPy's solve_ivp), not by the
C core: a joint (rad, N m) or a stage (mm, mN) under a sine motion, sampled with jitter (each sample moved by up
to 30 % of the interval), with white noise of 1 % of the force's range and a sensor offset. Truths are away
from every preset and from the code's defaults (the rotary joint: sigma0 = 3000 N m/rad, sigma1 = 0.3 N m s/rad,
fc = 0.9 N m, fs = 1.4 N m, vs = 0.3 rad/s, sigma2 = 0.35 N m s/rad; the stage: sigma0 = 2e5 N/m, sigma1 = 20
N s/m, fc = 3 N, fs = 4 N, vs = 5 mm/s, sigma2 = 100 N s/m). Fits start from values read off the data
(identification/force.py: force_start), not from the truth.

Tolerance: each fitted parameter, and the offset, within twice the half-width of its own 95 % interval (about
four standard errors) of the truth: an honest interval passes, a biased fit or a falsely tight interval fails.
The fits must also be adequate (residuals at the noise estimated from the data).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from force_truths import make_dataset  # noqa: E402

import thermofriction as tf  # noqa: E402
from thermofriction.models import PrescribedMotion  # noqa: E402
from thermofriction.models.laws import Linear  # noqa: E402
from thermofriction.models.thermal import ModelI, ModelII  # noqa: E402

from conftest import run_cli  # noqa: E402

JOINT = PrescribedMotion(motion="rotary")
STAGE = PrescribedMotion()
ROT = dict(sigma0=3000.0, sigma1=0.3, fc=0.9, fs=1.4, vs=0.3, sigma2=0.35)
TRUTHS = {
    "lugre": lambda: tf.LuGre(**ROT),
    "elastoplastic": lambda: tf.ElastoPlastic(**ROT, z_ba=0.3 * 0.9 / 3000.0),
    "dahl": lambda: tf.Dahl(sigma0=3000.0, fc=0.9),
    "stribeck": lambda: tf.Stribeck(fc=0.9, fs=1.4, vs=0.3, sigma2=0.35),
    "coulomb": lambda: tf.Coulomb(fc=0.9, sigma2=0.35),
    "gms": lambda: tf.GMS(k=(1500.0, 1000.0, 500.0), w=(0.25, 0.35, 0.4), C=20.0, fc=0.9, fs=1.4, vs=0.3,
                          sigma2=0.35),
}
OFFSET = 0.05  # [N m]
DATA = dict(n=1500, duration=2.0)


def check_recovered(fit, truth_values, names=None):
    for name, p in fit.parameters.items():
        if not p.vary or (names and name not in names):
            continue
        half = 0.5 * (p.ci95[1] - p.ci95[0])
        assert math.isfinite(half), (name, p)
        assert abs(p.value - truth_values[name]) <= 2 * half, (name, p.value, truth_values[name], p.ci95)


def check_offset(fit, truth):
    o = fit.sensor_offset
    half = 0.5 * (o["ci95"][1] - o["ci95"][0])
    assert o["fitted"] and abs(o["value"] - truth) <= 2 * half, o
    assert fit.model.plant.sensor_offset == o["value"]


@pytest.mark.parametrize("kind", list(TRUTHS))
def test_each_friction_model_is_recovered_from_joint_torque(kind, tmp_path):
    truth = tf.Model(JOINT, TRUTHS[kind]())
    folder, _ = make_dataset(tmp_path, truth, offset=OFFSET, **DATA)
    data = tf.load_dataset(folder)
    init = None
    if kind == "gms":  # the element structure (k, w) is held: start C and the levels off the truth
        init = tf.Model(JOINT, tf.GMS(k=(1500.0, 1000.0, 500.0), w=(0.25, 0.35, 0.4), C=40.0, fc=1.0, fs=1.5,
                                      vs=0.2, sigma2=0.3))
    fit = tf.identify(data, "base", init=init, friction=kind)
    assert fit.model.friction.model == kind
    assert fit.adequate, fit.fit_quality
    assert fit.unit == "N m"
    check_recovered(fit, truth.friction.values())
    check_offset(fit, OFFSET)
    units = {n: p.unit for n, p in fit.parameters.items()}
    assert units.get("fc") == "N m"
    if "sigma0" in units:
        assert units["sigma0"] == "N m/rad"
    if "vs" in units:
        assert units["vs"] == "rad/s"


def test_linear_stage_in_mm_and_mN_without_a_velocity_column(tmp_path):
    """A load-cell stage: positions in mm, force in mN, no velocity column (the position's gradient drives)."""
    p = dict(sigma0=2e5, sigma1=20.0, fc=3.0, fs=4.0, vs=5e-3, sigma2=100.0)
    truth = tf.Model(STAGE, tf.LuGre(**p))
    folder, _ = make_dataset(tmp_path, truth, amplitude=5e-3, offset=-0.4, units=("mm", "mm/s", "mN"),
                             velocity=False, **DATA)
    fit = tf.identify(tf.load_dataset(folder), "base")
    assert fit.adequate, fit.fit_quality
    assert fit.unit == "N" and fit.parameters["sigma0"].unit == "N/m"
    check_recovered(fit, p)
    check_offset(fit, -0.4)


def test_plant_only_file_through_the_command_line(tmp_path):
    """A model file with only [plant] type = "prescribed" (rotary) and [friction] model = "lugre": identify,
    validate and report from the command line; the results carry N m and the offset."""
    truth = tf.Model(JOINT, tf.LuGre(**ROT))
    folder, sd = make_dataset(tmp_path / "data", truth, validate=(35.0,), offset=OFFSET, **DATA)
    (tmp_path / "joint.toml").write_text('[plant]\ntype = "prescribed"\nmotion = "rotary"\n\n[friction]\n'
                                         'model = "lugre"\n')
    r = run_cli("identify", folder, "--method", "base", "--init", tmp_path / "joint.toml", "-o",
                tmp_path / "fitted.toml", "--json", tmp_path / "fitted.json")
    assert r.returncode == 0, r.stderr
    assert "sensor offset" in r.stdout and "N m/rad" in r.stdout
    fitted = tf.load_model(tmp_path / "fitted.toml")
    assert fitted.plant.rotary and abs(fitted.plant.sensor_offset - OFFSET) < 5 * sd / math.sqrt(DATA["n"])
    res = json.loads((tmp_path / "fitted.json").read_text())
    assert res["unit"] == "N m" and res["sensor_offset"]["fitted"] is True
    assert res["parameters"]["sigma0"]["unit"] == "N m/rad"
    assert [e["file"] for e in res["experiments"]] == ["run0-T35C.csv"]
    assert res["experiments"][0]["rmse"] < 1.5 * sd
    r = run_cli("validate", tmp_path / "fitted.toml", folder, "--json", tmp_path / "v.json")
    assert r.returncode == 0, r.stderr
    v = json.loads((tmp_path / "v.json").read_text())
    assert v["unit"] == "N m" and v["sensor_offset"] == fitted.plant.sensor_offset
    assert all(e["rmse"] < 1.5 * sd for e in v["experiments"]), v["experiments"]
    r = run_cli("report", tmp_path / "fitted.toml", folder, "-o", tmp_path / "r.html")
    assert r.returncode == 0, r.stderr
    page = (tmp_path / "r.html").read_text()
    for section in ("Friction models compared", "Measured and predicted torque", "Friction–velocity map",
                    "Presliding hysteresis", "sensor offset"):
        assert section in page


def test_held_out_data_keep_the_fitted_offset(tmp_path):
    """The offset is fitted once, on the fit experiments; a held-out run whose sensor was re-zeroed (offset
    +0.3 N m more) shows that difference as its mean error, instead of having it fitted away. (A Stribeck
    map: the offset's treatment does not depend on the friction model, and its fits are cheap.)"""
    truth = tf.Model(JOINT, TRUTHS["stribeck"]())
    folder, sd = make_dataset(tmp_path, truth, validate=(35.0,), offset=OFFSET, validate_offset=OFFSET + 0.3, **DATA)
    data = tf.load_dataset(folder)
    fit = tf.identify(data, "base", friction="stribeck")
    v = tf.validate(fit.model, data)
    held = [p for p in v.predictions if p.role == "validate"][0]
    fitted = [p for p in v.predictions if p.role == "fit"][0]
    assert abs(held.bias + 0.3) < 0.1 * 0.3, held.bias
    assert abs(fitted.bias) < 3 * sd / math.sqrt(len(fitted.time))
    assert held.rmse > 0.3 > 2 * fitted.rmse


def test_no_offset_holds_the_models_offset(tmp_path):
    """--no-offset: the offset is the initial model's, not fitted, and takes no degree of freedom (a Stribeck
    map, as above)."""
    truth = tf.Model(JOINT, TRUTHS["stribeck"]())
    folder, _ = make_dataset(tmp_path, truth, offset=OFFSET, **DATA)
    data = tf.load_dataset(folder)
    start = tf.Model(PrescribedMotion(motion="rotary", sensor_offset=OFFSET),
                     tf.Stribeck(fc=1.1, fs=1.6, vs=0.2, sigma2=0.3))
    held = tf.identify(data, "base", init=start, offset=False)
    assert held.sensor_offset["fitted"] is False and held.model.plant.sensor_offset == OFFSET
    fitted = tf.identify(data, "base", init=start)
    assert held.statistics["dof"] == fitted.statistics["dof"] + 1
    check_recovered(held, truth.friction.values())
    with pytest.raises(tf.InputError, match="applies to force data"):
        tf.identify(tf.synthesize(tf.load_model("li2009-base"), [35.0], duration=0.1), "base", offset=False)


def test_model_i_from_torque_at_several_temperatures(tmp_path):
    """Model I on force data as on displacements: fc and fs follow linear laws of temperature (truth:
    fc = 1.25 - 0.01 T, fs = 1.9 - 0.012 T N m); fitted per temperature, laws through the estimates, a joint
    refinement; the held-out temperature is predicted at the noise. The laws are checked by their values at the
    fit temperatures, within twice the half-width of their 95 % intervals there (FitResult.law_interval): on three
    temperatures the estimates may choose an exponential fs law by AICc, whose coefficients are not the linear
    truth's (they did once the motion's velocity was linear between samples)."""
    laws = {"fc": Linear(a=-0.01, b=1.25), "fs": Linear(a=-0.012, b=1.9)}
    base = {k: v for k, v in ROT.items() if k not in laws}
    truth = tf.Model(JOINT, tf.LuGre(**base, fc=None, fs=None), ModelI(laws))
    folder, sd = make_dataset(tmp_path, truth, temperatures=(30.0, 35.0, 40.0), validate=(37.5,), offset=OFFSET, **DATA)
    data = tf.load_dataset(folder)
    start = tf.Model(JOINT, tf.LuGre(**base, fc=None, fs=None),
                     ModelI({"fc": Linear(a=-0.005, b=1.1), "fs": Linear(a=-0.02, b=2.1)}))
    fit = tf.identify(data, "model-i", init=start)
    assert fit.adequate, fit.fit_quality
    for name, law in laws.items():
        value, lo, hi = fit.law_interval(name, [30.0, 35.0, 40.0])
        half = 0.5 * (hi - lo)
        assert np.all(half > 0) and np.all(np.abs(value - law([30.0, 35.0, 40.0])) <= 2 * half), (name, value, half)
    check_offset(fit, OFFSET)
    v = tf.validate(fit.model, data)
    assert all(p.rmse < 1.3 * sd for p in v.predictions), [p.rmse for p in v.predictions]


def test_model_ii_from_torque_at_several_temperatures(tmp_path):
    """Model II: a thermal friction term dF(T) scaling the base model (truth dF falls linearly, 0 at 30 C to
    -0.2 N m at 40 C); the direct procedure recovers it."""
    from thermofriction.models.laws import PWL
    truth = tf.Model(JOINT, tf.LuGre(**ROT), ModelII(PWL([30.0, 40.0], [0.0, -0.2])))
    folder, sd = make_dataset(tmp_path, truth, temperatures=(30.0, 35.0, 40.0), validate=(37.5,), offset=OFFSET,
                              **DATA)
    data = tf.load_dataset(folder)
    fit = tf.identify(data, "model-ii", init=tf.Model(JOINT, tf.LuGre(**ROT), ModelII(PWL([30.0, 40.0], [0.0, 0.0]))))
    dF = fit.model.thermal.dF
    assert abs(float(dF(40.0)) - (-0.2)) < 0.1 * 0.2, dF
    check_offset(fit, OFFSET)
    v = tf.validate(fit.model, data)
    assert all(p.rmse < 1.3 * sd for p in v.predictions), [p.rmse for p in v.predictions]


def test_friction_models_compared_by_aicc_and_held_out_error(tmp_path):
    """compare_friction_models: on LuGre data LuGre wins on AICc and on the held-out error."""
    from thermofriction.identification.compare import compare_friction_models
    truth = tf.Model(JOINT, tf.LuGre(**ROT))
    folder, sd = make_dataset(tmp_path, truth, validate=(35.0,), offset=OFFSET, **DATA)
    out = compare_friction_models(tf.load_dataset(folder), ("coulomb", "stribeck", "lugre"))
    assert out["lugre"]["delta_aicc"] == 0.0
    assert out["coulomb"]["delta_aicc"] > 10 and out["stribeck"]["delta_aicc"] > 10
    assert out["lugre"]["heldout_rmse"] < min(out["coulomb"]["heldout_rmse"], out["stribeck"]["heldout_rmse"])
    assert out["lugre"]["heldout_rmse"] < 1.3 * sd


LINEAR = {  # a stage in mm and mN: fc = 3 N, fs = 4 N, vs = 5 mm/s, sigma2 = 100 N s/m, sigma0 = 2e5 N/m
    "stribeck": (lambda: tf.Stribeck(fc=3.0, fs=4.0, vs=5e-3, sigma2=100.0), True),
    "coulomb": (lambda: tf.Coulomb(fc=3.0, sigma2=100.0), True),
    "dahl": (lambda: tf.Dahl(sigma0=2e5, fc=3.0), False),
}


@pytest.mark.parametrize("kind", list(LINEAR))
def test_cheap_friction_models_in_linear_units(kind, tmp_path):
    """The static maps and Dahl on a linear stage (mm, mm/s, mN), with and without a velocity column."""
    make, velocity = LINEAR[kind]
    truth = tf.Model(STAGE, make())
    folder, _ = make_dataset(tmp_path, truth, amplitude=5e-3, offset=0.2, units=("mm", "mm/s", "mN"),
                             velocity=velocity, **DATA)
    fit = tf.identify(tf.load_dataset(folder), "base", friction=kind)
    assert fit.adequate, fit.fit_quality
    assert fit.unit == "N" and fit.parameters["fc"].unit == "N"
    check_recovered(fit, truth.friction.values())
    check_offset(fit, 0.2)
