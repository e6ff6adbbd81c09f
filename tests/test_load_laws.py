"""Laws of temperature and load (models/load_laws.py), a run's load in force data, and the refusals where the load
is not an input yet (the FMU, identify; the simulator's and the real-time API's load: tests/test_load_core.py). Values are checked against the formulas written out here (analytic), derivatives against
central differences of the value taken here."""

from __future__ import annotations

import tomllib
import warnings

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.cli import main
from thermofriction.data.force import force_experiment
from thermofriction.measurements.force_load import run_load
from thermofriction.models import (Const, Exp, LoadLaw, LoadRangeWarning, LoadTerm, Linear, LuGre, Model, ModelI,
                                   PrescribedMotion, model_from_dict)

MODEL = """
[plant]
type = "prescribed"
motion = "rotary"

[friction]
model = "lugre"
sigma0 = 100.0
sigma1 = 0.5
sigma2 = 0.1
vs = 0.08

[thermal]
model = "I"
fc = { law = "linear", a = -0.003, b = 0.4, range = [20.0, 50.0], load = { law = "affine", k = 0.02, interaction = 1e-4, range = [5.0, 25.0] } }
fs = { law = "exp", a = 0.6, b = -0.004, load = { law = "affine", k = 0.012, combine = "sum", saturation = 40.0 } }
"""


def model():
    return model_from_dict(tomllib.loads(MODEL))


@pytest.mark.parametrize("T, L", [(20.0, 5.0), (35.0, -15.0), (50.0, 25.0)])
@pytest.mark.filterwarnings("error")
def test_values_are_the_written_formulas(T, L):
    """Analytic: product-affine with interaction, sum-affine with saturation, proportional."""
    m = model()
    fc = (0.4 - 0.003 * T) * (1 + 0.02 * abs(L)) + 1e-4 * T * abs(L)
    fs = 0.6 * np.exp(-0.004 * T) + 0.012 * 40.0 * np.tanh(abs(L) / 40.0)
    assert m.laws["fc"].value(T, L) == pytest.approx(fc, rel=1e-12)
    assert m.laws["fs"].value(T, L) == pytest.approx(fs, rel=1e-12)
    mu = LoadLaw(Linear(a=-1e-3, b=0.1), LoadTerm("proportional"))
    assert mu.value(T, L) == pytest.approx((0.1 - 1e-3 * T) * abs(L), rel=1e-12)
    p = m.parameters_at(T, L)
    assert p["fc"] == pytest.approx(fc) and p["fs"] == pytest.approx(fs)


def test_coefficient_derivatives_match_central_differences():
    """The law's derivatives (the chain rule of a joint fit) against differences of its value taken here."""
    for law in model().laws.values():
        c = np.array(law.coefficients())
        for T, L in [(22.0, 7.0), (47.0, 30.0)]:
            d = law.coefficient_derivatives(T, L)
            for k in range(c.size):
                h = 1e-6 * max(abs(c[k]), 1e-3)
                up, down = c.copy(), c.copy()
                up[k] += h
                down[k] -= h
                fd = (law.with_coefficients(up).value(T, L, warn=False) -
                      law.with_coefficients(down).value(T, L, warn=False)) / (2 * h)
                assert d[k] == pytest.approx(fd, rel=1e-6, abs=1e-9 * abs(law.value(T, L, warn=False)))


def test_round_trip_through_toml_and_names():
    m = model()
    again = model_from_dict(tomllib.loads(m.to_toml()))
    assert again.to_dict() == m.to_dict()
    assert m.laws["fc"].coefficient_names() == ["a", "b", "load.k", "load.interaction"]
    assert m.laws["fs"].coefficient_names() == ["a", "b", "load.k"]


def test_a_load_outside_the_range_warns_inside_does_not():
    law = model().laws["fc"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        law.value(30.0, 25.0)
        law.value(30.0, -25.0)  # the range is of the load's magnitude (a torque of either sign)
    with pytest.warns(LoadRangeWarning, match=r"load 40 outside the range of \|load\| 5\.\.25"):
        law.value(30.0, 40.0)


@pytest.mark.parametrize("table, match", [
    ({"law": "proportional", "combine": "sum"}, "combine = \"product\""),
    ({"law": "affine"}, "'k' is required"),
    ({"law": "proportional", "k": 1.0}, "'k' is not a coefficient"),
    ({"law": "affine", "k": 1.0, "saturation": 0.0}, "'saturation' must be positive"),
    ({"law": "affine", "k": 1.0, "slope": 2.0}, "slope"),
    ({"law": "cubic"}, "one of proportional, affine"),
    ({"law": "proportional", "range": [-5.0, 5.0]}, "magnitude"),
])
def test_bad_load_tables_are_named(table, match):
    d = tomllib.loads(MODEL)
    d["thermal"]["fc"]["load"] = table
    with pytest.raises(tf.InputError, match=r"\[thermal\] fc load: .*" + match.replace("(", r"\(")):
        model_from_dict(d)


def test_the_load_is_refused_where_it_is_not_an_input_yet(tmp_path):
    """The simulator asks for the load, naming the law (the FMU takes it as an input: tests/test_load_deploy.py)."""
    m = model()
    with pytest.raises(tf.InputError, match=r"\[thermal\] fc: a law of the load .* give the run's load"):
        tf.simulate(m, 0.1, temperature=30.0)
    with pytest.raises(tf.InputError, match="needs the load"):
        m.parameters_at(30.0)


def _columns(load):
    t = np.linspace(0.0, 4.0, 401)
    x = 0.5 * np.sin(2 * np.pi * 0.5 * t)
    F = 0.3 * np.tanh(np.gradient(x, t) / 0.01)
    cols = {"time": t, "position": x, "force": F, "rotary": True,
            "headers": {"time": "time[s]", "position": "position[rad]", "force": "friction_torque[N*m]"}}
    if load is not None:
        cols["load_torque"] = load
    return cols


def _read(cols, load=None, T=30.0):
    return force_experiment("f.csv", "f.csv", temperature=T, role="fit", description="",
                            from_zero=lambda t, i: (t, i), columns=cols, load=load)


def test_a_run_carries_its_load_from_a_column_or_the_manifest():
    n = 401
    assert _read(_columns(np.full(n, 12.0) + 1e-3 * np.sin(np.arange(n)))).load == pytest.approx(12.0, abs=1e-4)
    assert _read(_columns(None), load=7.5).load == 7.5
    assert _read(_columns(None)).load is None
    ramp = _read(_columns(np.linspace(5.0, 25.0, n)))  # read (a simulation is driven by it), refused by a force fit
    assert ramp.load == pytest.approx(15.0) and isinstance(ramp.load_input(), tf.Sampled)
    with pytest.raises(tf.InputError, match=r"f\.csv: the load column varies over the run"):
        run_load(ramp)
    with pytest.raises(tf.InputError, match=r"f\.csv: both a load_torque column and the manifest's 'load'"):
        _read(_columns(np.full(n, 3.0)), load=3.0)


def test_dataset_manifest_load_key_and_csv_column(tmp_path):
    """A dataset folder: the manifest's ``load`` on one run, a normal_force[N] column on another (linear motion),
    and a bad ``load`` named with its entry."""
    t = np.linspace(0.0, 4.0, 401)
    x = 1e-3 * np.sin(2 * np.pi * 0.5 * t)
    F = 2.0 * np.tanh(np.gradient(x, t) / 1e-4)
    for name, extra in (("a.csv", None), ("b.csv", np.full(t.size, 40.0))):
        head = "time[s],position[m],friction_force[N]" + (",normal_force[N]" if extra is not None else "")
        cols = [t, x, F] + ([extra] if extra is not None else [])
        np.savetxt(tmp_path / name, np.column_stack(cols), delimiter=",", header=head, comments="")
    (tmp_path / "dataset.toml").write_text('[[experiment]]\nfile = "a.csv"\ntemperature = 30.0\nload = 20.0\n\n'
                                           '[[experiment]]\nfile = "b.csv"\ntemperature = 30.0\n')
    ds = tf.load_dataset(tmp_path)
    assert [e.load for e in ds.experiments] == [20.0, 40.0]
    (tmp_path / "dataset.toml").write_text('[[experiment]]\nfile = "a.csv"\ntemperature = 30.0\nload = "heavy"\n')
    with pytest.raises(tf.InputError, match=r"\[\[experiment\]\] 1.*'load' must be a number"):
        tf.load_dataset(tmp_path)


def test_identify_takes_a_law_of_load_by_model_i_only():
    """identify fits laws of load (identification/load_identify.py, tests/test_load_identify.py) by Model I; another
    method, or a law kind asked for with them, is refused naming what applies."""
    m = model()
    exps = [_read(_columns(None), load=10.0, T=T) for T in (25.0, 45.0)]
    data = tf.Dataset(name="d", experiments=exps)
    with pytest.raises(tf.InputError, match="method 'model-i'"):
        tf.identify(data, method="model-ii", init=m)
    with pytest.raises(tf.InputError, match="laws: a law of load keeps the temperature kind"):
        tf.identify(data, method="model-i", init=m, laws={"fc": "exp"})


def test_a_constant_or_exp_base_law_keeps_its_kind():
    law = LoadLaw(Exp(a=1.0, b=-0.01), LoadTerm("affine", k=0.1))
    assert law.kind == "exp" and law.to_dict()["load"] == {"law": "affine", "k": 0.1, "combine": "product"}
    assert LoadLaw(Const(value=2.0), LoadTerm("proportional")).value(10.0, -3.0) == pytest.approx(6.0)
    m = Model(PrescribedMotion(motion="rotary"), LuGre(sigma0=100.0, sigma1=0.5, sigma2=0.1, vs=0.08, fc=None,
                                                       fs=0.5), ModelI({"fc": law}))
    assert m.laws["fc"] is law


def test_save_dataset_keeps_each_run_s_load(tmp_path):
    """A round trip through save_dataset and load_dataset keeps the load (the manifest's key)."""
    exps = [_read(_columns(None), load=L, T=T) for L, T in ((5.0, 25.0), (12.5, 40.0))]
    for k, e in enumerate(exps):
        e.file = f"r{k}.csv"
    tf.save_dataset(tf.Dataset(name="d", experiments=exps), tmp_path / "ds")
    assert [e.load for e in tf.load_dataset(tmp_path / "ds").experiments] == [5.0, 12.5]


def test_the_command_line_refuses_to_simulate_a_law_of_load(tmp_path, capsys):
    """Exit status 2 and one line naming the law, no traceback."""
    path = tmp_path / "m.toml"
    model().save(path)
    status = main(["simulate", str(path), "--temperature", "30", "--duration", "0.01", "--input",
                   "sine:amplitude=0.1,frequency=1", "-o", str(tmp_path / "o.csv")])
    err = capsys.readouterr().err
    assert status == 2 and "[thermal] fc: a law of the load" in err and "Traceback" not in err
    assert not (tmp_path / "o.csv").exists()
