"""A wrong-but-valid unit is caught (unit_scale.py, docs/your-data.md#units): µm values under a [mm] or [m] header,
mN values under [N]. The data are written by the package's own writers (synthesize + save_dataset, write_force_csv)
and their header then rewritten, as a user's mistake would; the expected factor is known exactly (1e3, 1e6), so a
warning must name it, the header and the unit that explains it, and a correct file must raise none."""

from __future__ import annotations

import json
import math
import shutil
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.identification import front
from thermofriction.data.force import write_force_csv
from thermofriction.unit_scale import SUGGEST_WITHIN, TRUST_RATIO, suggestion, unit_warnings

sys.path.insert(0, str(Path(__file__).resolve().parent))
from conftest import run_cli  # noqa: E402

MODEL = "li2009-base"


@pytest.fixture(scope="module")
def actuator(tmp_path_factory):
    """One synthetic actuator dataset (a fit run and a held-out one), written in µm, and a function that copies it
    with the displacement header declaring another unit (the values unchanged: µm numbers)."""
    root = tmp_path_factory.mktemp("units")
    data = tf.synthesize(tf.load_model(MODEL), [32.0], validate=[38.0], duration=0.4, sample_rate=5000.0)
    tf.save_dataset(data, root / "um")

    def labelled(unit):
        folder = root / unit
        if not folder.exists():
            shutil.copytree(root / "um", folder)
            for f in folder.glob("*.csv"):
                text = f.read_text()
                assert "displacement[um]" in text.splitlines()[0]  # what the writer wrote
                f.write_text(text.replace("displacement[um]", f"displacement[{unit}]", 1))
        return folder

    return labelled


def _load(folder):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        data = tf.load_dataset(folder)
    return data, [str(w.message) for w in caught if issubclass(w.category, tf.UnitWarning)]


def _validate(model, data):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = tf.validate(model, data)
    return res, [str(w.message) for w in caught if issubclass(w.category, tf.UnitWarning)]


def test_correct_data_raise_no_unit_warning(actuator):
    data, loading = _load(actuator("um"))
    res, raised = _validate(tf.load_model(MODEL), data)
    assert loading == [] and raised == []
    assert not any("suspicious unit" in w for w in res.warnings)


@pytest.mark.parametrize("unit, factor", [("mm", "~1,000×"), ("m", "~1,000,000×")])
def test_micrometres_under_a_larger_unit_are_named_with_the_unit_that_explains_them(actuator, unit, factor):
    """The values are µm numbers read as mm (1e3 too large) or m (1e6): exact factors, whatever the model."""
    data, _ = _load(actuator(unit))
    res, raised = _validate(tf.load_model(MODEL), data)
    assert len(raised) == 1 and res.warnings[0] == raised[0]  # one for both files (one header), and first
    w = raised[0]
    assert w.startswith("suspicious unit: T32C.csv, T38C-validate.csv: the values under column "
                        f"displacement[{unit}] are {factor} what the model produces")
    assert "are they in µm (header displacement[um])?" in w
    assert res.summary()["validate"]["max_error_pct"] > 90  # what the warning explains


def test_a_displacement_of_metres_beyond_any_actuator_travel_is_warned_at_loading(actuator):
    _, loading = _load(actuator("m"))
    assert len(loading) == 2 and all("column displacement[m]: the displacement spans" in w for w in loading)
    _, loading = _load(actuator("mm"))  # 3-4 mm: an actuator's travel; the model judges it (above)
    assert loading == []


class _Stop(Exception):
    pass


def _stop(*args, **kwargs):
    raise _Stop


def test_identify_warns_before_the_fit_from_the_initial_model(actuator, monkeypatch):
    """The warning comes from the initial model, before the fit, which is replaced here by a stop (a fit on values
    1000x off takes seconds per simulation); the result carrying it is tested on force data."""
    data, _ = _load(actuator("mm"))
    monkeypatch.setattr(front, "_fit", _stop)
    with pytest.warns(tf.UnitWarning, match=r"displacement\[mm\] are ~1,000× what the initial model produces"):
        with pytest.raises(_Stop):
            tf.identify(data, "base", init=MODEL, starts=1)
    monkeypatch.undo()
    ok, _ = _load(actuator("um"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fit = tf.identify(ok, "base", init=MODEL, starts=1, max_evaluations=3)
    assert not [w for w in caught if issubclass(w.category, tf.UnitWarning)]
    assert not any("suspicious unit" in w for w in fit.warnings)


def test_cli_validate_prints_the_warning_once_and_exits_0(actuator):
    """A warning, not an error: the numbers are valid and the model may be another plant's (exit 0)."""
    r = run_cli("validate", MODEL, actuator("mm"))
    assert r.returncode == 0, r.stderr
    lines = [x for x in r.stderr.splitlines() if "suspicious unit" in x]
    assert len(lines) == 1 and lines[0].startswith("thermofriction: warning: suspicious unit: ")
    assert "displacement[mm]" in lines[0] and "are they in µm" in lines[0]
    assert "Traceback" not in r.stderr


# -- force data -----------------------------------------------------------------------------------------------------

STAGE = tf.Model(tf.PrescribedMotion(), tf.LuGre(sigma0=3000.0, sigma1=0.3, fc=0.9, fs=1.4, vs=0.3, sigma2=0.35))


def _force_dataset(folder, scale, column):
    """A stage's friction under a 2 mm sine, simulated and written by write_force_csv: ``scale`` times the values
    in newtons, under the header ``column``."""
    t = np.linspace(0.0, 2.0, 801)
    x = 2e-3 * np.sin(2 * math.pi * t)
    res = tf.simulate(STAGE, t_eval=t, temperature=35.0, input=tf.Sine(amplitude=2e-3, frequency=1.0))
    F = np.asarray(res.friction_force) + np.random.default_rng(0).normal(0.0, 0.01, t.size)
    folder.mkdir()
    write_force_csv(folder / "run1.csv", t, x, F * scale, column=column)
    (folder / "dataset.toml").write_text('[[experiment]]\nfile = "run1.csv"\ntemperature = 35.0\n')
    return tf.load_dataset(folder)


def test_millinewtons_under_a_newton_header_are_caught(tmp_path):
    ok = _force_dataset(tmp_path / "ok", 1.0, None)
    res, raised = _validate(STAGE, ok)
    assert raised == [] and not res.warnings
    wrong = _force_dataset(tmp_path / "mN", 1e3, "friction_force[N]")  # mN numbers, declared N
    res, raised = _validate(STAGE, wrong)
    assert len(raised) == 1 and res.warnings == raised
    assert raised[0].startswith("suspicious unit: run1.csv: the values under column friction_force[N] are ~1,000× "
                                "what the model produces")
    assert "are they in mN (header friction_force[mN])?" in raised[0]
    with pytest.warns(tf.UnitWarning, match=r"friction_force\[N\] are ~1,000× what the initial model") as caught:
        fit = tf.identify(wrong, "base", init=STAGE, starts=1, max_evaluations=3)
    assert [w.filename for w in caught if issubclass(w.category, tf.UnitWarning)] == [__file__]  # the user's line
    assert fit.warnings[0].startswith("suspicious unit: run1.csv") and "are they in mN" in fit.warnings[0]
    assert fit.to_dict()["warnings"][0] == fit.warnings[0]  # in the results JSON too


def test_cli_identify_prints_the_warning_and_exits_0(tmp_path):
    _force_dataset(tmp_path / "mN", 1e3, "friction_force[N]")
    STAGE.save(tmp_path / "stage.toml")
    r = run_cli("identify", tmp_path / "mN", "--method", "base", "--init", tmp_path / "stage.toml", "--starts", "1",
                "--max-evaluations", "3", "-o", tmp_path / "fit.toml", "--json", tmp_path / "fit.json")
    assert r.returncode == 0, r.stderr
    lines = [x for x in r.stderr.splitlines() if "suspicious unit" in x]
    assert len(lines) == 1 and lines[0].startswith("thermofriction: warning: suspicious unit: run1.csv: the values "
                                                   "under column friction_force[N] are ~1,000×")
    assert "are they in mN" in r.stdout  # the report's [[Warnings]]
    assert json.loads((tmp_path / "fit.json").read_text())["warnings"][0].startswith("suspicious unit: run1.csv")


# -- the rule -------------------------------------------------------------------------------------------------------

class _Exp:
    file = "run.csv"
    voltage = np.zeros(2)
    headers = {"displacement": ("column displacement[mm]", "mm")}


@pytest.mark.parametrize("decades, warned, unit", [
    (0.0, False, None), (2.4, False, None), (-2.4, False, None),  # within a start's error: never
    (2.6, True, "µm"), (3.0, True, "µm"), (3.4, True, "µm"), (-3.0, True, "m"),
    (4.5, True, None),  # far from any power of 1000: warned, no unit suggested
    (6.0, True, "nm")])
def test_the_rule_warns_beyond_2_5_decades_and_suggests_a_unit_within_half_a_decade_of_a_power_of_1000(
        decades, warned, unit):
    assert TRUST_RATIO == pytest.approx(10 ** 2.5) and SUGGEST_WITHIN == 0.5
    predicted = np.array([0.0, 1e-6])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tf.UnitWarning)
        out = unit_warnings([(_Exp(), predicted * 10 ** decades, predicted)])
    assert bool(out) == warned
    assert suggestion("mm", 10 ** decades) == unit
    if warned:
        assert (f"are they in {unit}" in out[0]) == (unit is not None)
        assert ("no unit explains" in out[0]) == (unit is None)


def test_a_model_that_does_not_move_is_no_evidence():
    """A zero predicted (or measured) span gives no ratio: nothing is said."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", tf.UnitWarning)
        assert unit_warnings([(_Exp(), np.array([0.0, 1e-3]), np.zeros(2))]) == []


def test_the_reports_first_warning_is_the_suspicious_unit():
    """docs/your-data.md, step 5: the unit explains every error after it, so it is said before the fit's."""
    from types import SimpleNamespace

    from thermofriction.reporting.displacement import _warnings
    fit = {"fit_quality": {"adequate": False}, "warnings": ["the fit is not adequate: RMSE 1000 times the noise"]}
    validation = SimpleNamespace(failures=[], warnings=["T20C.csv: temperature 20 C is outside the calibrated range",
                                                        "suspicious unit: T20C.csv: the values under column ..."])
    warns = _warnings([SimpleNamespace(label="Model I", fit=fit, validation=validation)])
    assert warns[0] == "Model I: suspicious unit: T20C.csv: the values under column ..."
    assert warns[1].startswith("Model I: the fit is not adequate") and len(warns) == 3


def test_a_matlab_variable_is_named_by_its_name_and_suffix(actuator, tmp_path):
    from thermofriction.data.matlab import save_mat
    e = tf.load_dataset(actuator("um")).experiments[0]
    save_mat(tmp_path / "run.mat", {"time": e.time, "voltage": e.voltage, "displacement_mm": e.displacement * 1e6})
    (tmp_path / "dataset.toml").write_text('[[experiment]]\nfile = "run.mat"\ntemperature = 32.0\n')
    _, raised = _validate(tf.load_model(MODEL), tf.load_dataset(tmp_path))
    assert len(raised) == 1 and "run.mat: the values under variable 'displacement_mm' are ~1,000×" in raised[0]
    assert "are they in µm (declare um: the variable's suffix, or the manifest's units table)?" in raised[0]
