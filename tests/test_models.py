"""Model files (docs/formats.md#model-files): exact round trips, every law kind, and clear errors for bad files."""

import math

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

import thermofriction as tf
from thermofriction.models import law_from_dict, model_from_dict


@pytest.mark.parametrize("preset", tf.PRESETS)
def test_presets_round_trip_exactly(preset, tmp_path):
    model = tf.load_model(preset)
    path = tmp_path / "m.toml"
    model.save(path)
    again = tf.load_model(path)
    assert again == model
    assert again.to_toml() == model.to_toml()


LAWS = [
    {"law": "const", "value": 2.5},
    {"law": "linear", "a": -0.138, "b": 6.445, "range": [30.0, 41.5]},
    {"law": "exp", "a": 115072.0, "b": -0.136},
    {"law": "poly", "c": [1.0, -0.02, 3e-4]},
    {"law": "pwl", "T": [30.0, 38.4, 41.5], "values": [0.0, -0.145, -0.4775]},
    {"law": "table", "T": [30.0, 33.0, 36.0, 41.5], "values": [1.0, 0.9, 0.5, 0.45]},
]


@pytest.mark.parametrize("d", LAWS, ids=[d["law"] for d in LAWS])
def test_every_law_kind_round_trips_through_a_model_file(d, tmp_path):
    plant = tf.StickSlipPlant(mass=0.05, end_effector_mass=0.05, damping=1.0, stiffness=2e6, transducer_ratio=0.2)
    law = law_from_dict(d, "test")
    model = tf.Model(plant, tf.LuGre(sigma0=1e6, sigma1=None, fc=0.5), tf.ModelI({"sigma1": law}),
                     tf.Sawtooth(30, 5, rise=0.999))
    model.save(tmp_path / "m.toml")
    again = tf.load_model(tmp_path / "m.toml")
    assert again == model
    T = np.linspace(25, 45, 41)
    np.testing.assert_array_equal(again.laws["sigma1"](T), law(T))


def test_laws_match_their_formulas__analytic_and_scipy():
    T = np.linspace(20.0, 50.0, 301)
    np.testing.assert_allclose(law_from_dict(LAWS[1], "t")(T), -0.138 * T + 6.445, rtol=1e-15)
    np.testing.assert_allclose(law_from_dict(LAWS[2], "t")(T), 115072.0 * np.exp(-0.136 * T), rtol=1e-14)
    np.testing.assert_allclose(law_from_dict(LAWS[3], "t")(T), 1.0 - 0.02 * T + 3e-4 * T ** 2, rtol=1e-14)
    inside = T[(T >= 30) & (T <= 41.5)]
    np.testing.assert_allclose(law_from_dict(LAWS[4], "t")(inside), np.interp(inside, [30, 38.4, 41.5],
                                                                               [0.0, -0.145, -0.4775]), atol=1e-15)
    table = law_from_dict(LAWS[5], "t")
    ref = PchipInterpolator(LAWS[5]["T"], LAWS[5]["values"])
    np.testing.assert_allclose(table(inside), ref(inside), rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(table.slope(inside), ref.derivative()(inside), rtol=1e-10, atol=1e-13)


def test_modal_and_physical_forms_convert_both_ways():
    modal = tf.StickSlipPlant(mass=0.05, end_effector_mass=0.02, damping_ratio=0.2488, natural_frequency=6685.5,
                              gain=0.096e-6)
    c, k, T_em = modal.physical()
    assert k == pytest.approx(0.05 * 6685.5 ** 2) and c == pytest.approx(2 * 0.2488 * 6685.5 * 0.05)
    assert T_em == pytest.approx(0.096e-6 * k)
    phys = tf.StickSlipPlant(mass=0.05, end_effector_mass=0.02, damping=c, stiffness=k, transducer_ratio=T_em)
    np.testing.assert_allclose(phys.modal_parameters(), (0.2488, 6685.5, 0.096e-6), rtol=1e-14)
    a = tf.simulate(tf.Model(modal, tf.LuGre(1e6, 2.0, 0.5), input=tf.Sawtooth(30, 5, rise=0.999)), 0.3)
    b = tf.simulate(tf.Model(phys, tf.LuGre(1e6, 2.0, 0.5), input=tf.Sawtooth(30, 5, rise=0.999)), 0.3)
    np.testing.assert_allclose(a.displacement, b.displacement, rtol=0, atol=1e-6 * np.ptp(a.displacement))


GOOD = """
[plant]
type = "stick-slip"
xi = 0.2488
wn = 6685.5
K = 0.096e-6
m = 0.05
m_e = 0.05

[friction]
model = "lugre"
sigma2 = 0.0

[thermal]
model = "I"
sigma0 = { law = "exp", a = 1.15072e8, b = -0.136 }
sigma1 = { law = "linear", a = -0.138, b = 6.445 }
fc = { law = "exp", a = 106.04, b = -0.159 }
"""

BAD = [
    ("unknown key", GOOD.replace("sigma2 = 0.0", "sigma3 = 0.0"), "sigma3"),
    ("negative mass", GOOD.replace("m = 0.05", "m = -0.05"), "'m' must be positive"),
    ("number and law", GOOD.replace("sigma2 = 0.0", "sigma2 = 0.0\nfc = 0.5"), "both as a number"),
    ("TOML syntax", GOOD.replace("xi = 0.2488", "xi = = 0.2488"), "line 4"),
    ("unknown law", GOOD.replace('law = "exp", a = 106.04', 'law = "expo", a = 106.04'), "expo"),
    ("law key", GOOD.replace('a = -0.138, b = 6.445', 'a = -0.138, c = 6.445'), "'c'"),
    ("missing section", GOOD.split("[friction]")[0], "[friction]"),
    ("both plant forms", GOOD.replace("m_e = 0.05", "m_e = 0.05\nk = 1.0"), "either"),
    ("unknown section", GOOD + "\n[extra]\na = 1\n", "extra"),
    ("string for number", GOOD.replace("wn = 6685.5", 'wn = "fast"'), "'wn'"),
    ("fs below fc", GOOD.replace("sigma2 = 0.0", "sigma2 = 0.0\nfs = 0.1").replace(
        'fc = { law = "exp", a = 106.04, b = -0.159 }', "").replace('model = "lugre"', 'model = "lugre"\nfc = 0.5'),
     "'fs'"),
    ("unknown thermal model", GOOD.replace('model = "I"', 'model = "III"'), "III"),
    ("unknown friction model", GOOD.replace('"lugre"', '"bristle"'), "bristle"),
    ("GMS without element arrays", GOOD.replace('"lugre"', '"gms"'), "'k'"),
    ("unknown plant type", GOOD.replace('"stick-slip"', '"flexure"'), "flexure"),
]


@pytest.mark.parametrize("text,match", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_model_files_name_the_file_and_the_problem(text, match, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(tf.InputError) as e:
        tf.load_model(path)
    assert str(path) in str(e.value)
    assert match in str(e.value)


def test_good_model_text_loads(tmp_path):
    (tmp_path / "good.toml").write_text(GOOD)
    model = tf.load_model(tmp_path / "good.toml")
    assert set(model.laws) == {"sigma0", "sigma1", "fc"}
    assert model.parameters_at(35.0)["fc"] == pytest.approx(106.04 * math.exp(-0.159 * 35.0))


def test_save_is_atomic_and_leaves_no_temporary_file(tmp_path, monkeypatch):
    model = tf.load_model("li2009-model-ii")
    target = tmp_path / "m.toml"
    target.write_text("old")

    def boom(self):
        raise RuntimeError("disk full")
    monkeypatch.setattr(tf.Model, "to_toml", boom)
    with pytest.raises(RuntimeError):
        model.save(target)
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["m.toml"]


def test_model_from_dict_is_data_only():
    d = {"plant": {"type": "stick-slip", "m": 0.05, "m_e": 0.05, "c": 1.0, "k": 1e6, "T_em": 0.1},
         "friction": {"model": "lugre", "sigma0": 1e6, "sigma1": 1.0, "fc": 0.5}}
    model = model_from_dict(d)
    assert model.thermal is None and model.friction.fs is None
    assert model.parameters_at(20.0)["fs"] == 0.5


LIBRARY = {
    "coulomb-mass": tf.Model(tf.MassPlant(2.0), tf.Coulomb(fc=1.0, sigma2=0.1, v_smooth=1e-5), input=tf.Sine(3.0, 1.0)),
    "stribeck-prescribed": tf.Model(tf.PrescribedMotion(), tf.Stribeck(fc=1.0, fs=1.4, vs=2e-3, delta=1.5),
                                    input=tf.Sine(1e-3, 0.5)),
    "dahl-stick-slip": tf.Model(tf.load_model("li2009-base").plant, tf.Dahl(sigma0=2e6, fc=0.9),
                                input=tf.Sawtooth(30, 5, rise=0.999)),
    "elastoplastic-spring": tf.Model(tf.MassPlant(1.0, 2.0, 0.1),
                                     tf.ElastoPlastic(sigma0=1e5, sigma1=300.0, fc=1.0, z_ba=5e-6, fs=1.5, vs=1e-3,
                                                      sigma2=0.4, vd=1e-3)),
    "gms-model-i": tf.Model(tf.PrescribedMotion(), tf.GMS(k=(1e5, 3e5), w=(0.25, 0.75), C=None, fc=1.0),
                            tf.ModelI({"C": tf.Linear(-1.0, 100.0)}), input=tf.Sine(2e-5, 1.0)),
    "gms-model-ii": tf.Model(tf.MassPlant(1.0, 2.0, 0.1), tf.GMS(k=(1e5, 3e5, 1e6), w=(0.2, 0.3, 0.5), C=50.0, fc=1.0),
                             tf.ModelII(tf.Linear(-0.01, 0.3))),
}


@pytest.mark.parametrize("name", list(LIBRARY))
def test_every_friction_model_and_plant_round_trips_through_its_file(name, tmp_path):
    model = LIBRARY[name]
    model.save(tmp_path / "m.toml")
    again = tf.load_model(tmp_path / "m.toml")
    assert again == model and again.to_toml() == model.to_toml()
    res = tf.simulate(again, 0.05, temperature=35.0 if again.thermal else None, sample_rate=2000)
    assert np.all(np.isfinite(res.friction_force)) and res.states.shape[1] == model.friction.nstate


@pytest.mark.parametrize("text, match", [
    ('[plant]\ntype = "mass"\nm = 1.0\nv_0 = 0.1\n[friction]\nmodel = "coulomb"\nfc = 1.0\n', "'k_s'"),
    ('[plant]\ntype = "prescribed"\nm = 1.0\n[friction]\nmodel = "dahl"\nsigma0 = 1e5\nfc = 1.0\n', "'m'"),
    ('[plant]\ntype = "mass"\nm = 1.0\n[friction]\nmodel = "gms"\nk = [1e5, 2e5]\nw = [0.5, 0.4]\nC = 10.0\nfc = 1.0\n',
     "sum to one"),
    ('[plant]\ntype = "mass"\nm = 1.0\n[friction]\nmodel = "gms"\nk = [1e5, -2e5]\nw = [0.5, 0.5]\nC = 10.0\nfc = 1.0\n',
     r"'k\[1\]' must be positive"),
    ('[plant]\ntype = "mass"\nm = 1.0\n[friction]\nmodel = "gms"\nk = [1e5]\nw = [1.0]\nC = 10.0\nfc = 1.0\n'
     'sigma1 = 2.0\n', "'sigma1'"),
    ('[plant]\ntype = "mass"\nm = 1.0\n[friction]\nmodel = "elastoplastic"\nsigma0 = 1e5\nsigma1 = 300.0\nfc = 1.0\n'
     'z_ba = 2e-5\n', "z_ba"),
    ('[plant]\ntype = "mass"\nm = 1.0\n[friction]\nmodel = "stribeck"\nfc = 1.0\nfs = 0.5\nvs = 1e-3\n', "'fs'"),
    ('[plant]\ntype = "mass"\nm = 1.0\n[friction]\nmodel = "dahl"\nsigma0 = 1e5\nfc = 1.0\n[thermal]\nmodel = "I"\n'
     'sigma1 = { law = "const", value = 1.0 }\n', "'sigma1' is not a parameter of dahl"),
])
def test_library_model_files_are_checked_and_errors_name_the_key(text, match, tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(tf.InputError, match=match) as e:
        tf.load_model(path)
    assert str(path) in str(e.value)
