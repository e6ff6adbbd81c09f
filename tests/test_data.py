"""Datasets (SPEC 7): reading, writing, synthesising, and one clear error per malformed input."""

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.data import read_experiment_csv


@pytest.fixture(scope="module")
def small(model_i):
    return tf.synthesize(model_i, [31.0, 40.0], validate=[35.0], duration=0.3, sample_rate=2000, noise=20e-9,
                         quantization=1e-9, temperature_noise=0.05, seed=11)


def test_synthesize_save_load_round_trip(small, tmp_path):
    tf.save_dataset(small, tmp_path / "d")
    data = tf.load_dataset(tmp_path / "d")
    assert [e.role for e in data.experiments] == ["fit", "fit", "validate"]
    assert [e.temperature for e in data.fit] == [31.0, 40.0]
    for a, b in zip(small.experiments, data.experiments):
        np.testing.assert_allclose(b.time, a.time, rtol=1e-9)
        np.testing.assert_allclose(b.displacement, a.displacement, rtol=1e-9, atol=1e-18)
        np.testing.assert_allclose(b.temperature_signal, a.temperature_signal, rtol=1e-9)
        assert b.input == a.input == tf.load_model("li2009-model-i").input


def test_synthesis_is_reproducible_with_independent_streams(model_i):
    kw = dict(duration=0.2, sample_rate=2000, noise=20e-9, seed=5)
    a = tf.synthesize(model_i, [31.0, 40.0], **kw)
    b = tf.synthesize(model_i, [31.0, 40.0], **kw)
    c = tf.synthesize(model_i, [31.0, 40.0, 35.0], **kw)
    d = tf.synthesize(model_i, [31.0, 40.0], **{**kw, "seed": 6})
    for x, y in zip(a.experiments, b.experiments):
        np.testing.assert_array_equal(x.displacement, y.displacement)
    for x, y in zip(a.experiments, c.experiments):  # adding an experiment changes no other
        np.testing.assert_array_equal(x.displacement, y.displacement)
    assert not np.array_equal(a.experiments[0].displacement, d.experiments[0].displacement)


def test_sensor_noise_and_quantisation_are_what_was_asked(model_i):
    clean = tf.synthesize(model_i, [36.0], duration=1.0, noise=0.0, seed=1).experiments[0]
    noisy = tf.synthesize(model_i, [36.0], duration=1.0, noise=20e-9, seed=1).experiments[0]
    assert np.std(noisy.displacement - clean.displacement) == pytest.approx(20e-9, rel=0.03)
    q = tf.synthesize(model_i, [36.0], duration=0.2, noise=20e-9, quantization=5e-9, seed=1).experiments[0]
    np.testing.assert_allclose(q.displacement / 5e-9, np.round(q.displacement / 5e-9), atol=1e-6)


HEADER = "time[s],voltage[V],displacement[um]\n"
ROWS = "".join(f"{i * 1e-3:.6f},{i * 0.1:.3f},{i * 0.01:.4f}\n" for i in range(20))

BAD_CSV = [
    ("missing column", "time[s],voltage[V]\n" + "".join(f"{i},{i}\n" for i in range(20)), "line 1: missing column"),
    ("unknown unit", HEADER.replace("[um]", "[furlong]") + ROWS, "unknown unit 'furlong'"),
    ("unknown column", HEADER.replace("\n", ",force[N]\n") + ROWS.replace("\n", ",1\n"), "unknown column 'force'"),
    ("non-monotonic time", HEADER + ROWS.replace("0.005000", "0.003000"), "line 7: time must increase"),
    ("NaN", HEADER + ROWS.replace("0.0500\n", "nan\n", 1), "not finite"),
    ("not a number", HEADER + ROWS.replace("0.0300", "abc", 1), "line 5, column 'displacement[um]'"),
    ("empty file", "", "empty file"),
    ("wrong cell count", HEADER + ROWS.replace("0.0400\n", "0.0400,7\n", 1), "line 6: 4 values, expected 3"),
    ("irregular sampling", HEADER + ROWS.replace("0.008000", "0.008500"), "irregular sampling"),
    ("too short", HEADER + ROWS[:60], "at least 10 samples"),
]


@pytest.mark.parametrize("text,words", [c[1:] for c in BAD_CSV], ids=[c[0] for c in BAD_CSV])
def test_bad_experiment_files_name_file_line_and_column(text, words, tmp_path):
    path = tmp_path / "run.csv"
    path.write_text(text)
    with pytest.raises(tf.InputError) as e:
        read_experiment_csv(path)
    assert str(path) in str(e.value) and words in str(e.value)


def test_units_are_converted_to_si(tmp_path):
    path = tmp_path / "run.csv"
    path.write_text("time[ms],voltage[V],displacement[nm],temperature[C]\n" +
                    "".join(f"{i},{i},{10 * i},35\n" for i in range(12)))
    cols = read_experiment_csv(path)
    assert cols["time"][1] == pytest.approx(1e-3) and cols["displacement"][1] == pytest.approx(10e-9)


def manifest(tmp_path, text, csv=HEADER + ROWS):
    (tmp_path / "run.csv").write_text(csv)
    (tmp_path / "dataset.toml").write_text(text)
    return tmp_path


BAD_MANIFEST = [
    ("unknown key", '[[experiment]]\nfile = "run.csv"\ntemperature = 30.0\nrol = "fit"\n', "unknown key 'rol'"),
    ("escaping path", '[[experiment]]\nfile = "../run.csv"\ntemperature = 30.0\n', "inside the dataset folder"),
    ("absolute path", '[[experiment]]\nfile = "/etc/passwd"\ntemperature = 30.0\n', "inside the dataset folder"),
    ("TOML syntax", '[[experiment]\nfile = "run.csv"\n', "TOML syntax error"),
    ("missing temperature", '[[experiment]]\nfile = "run.csv"\n', "no temperature"),
    ("missing file", '[[experiment]]\nfile = "nope.csv"\ntemperature = 30.0\n', "nope.csv: no such file"),
    ("bad role", '[[experiment]]\nfile = "run.csv"\ntemperature = 30.0\nrole = "train"\n', "'role'"),
    ("no experiments", 'name = "x"\n', "no [[experiment]]"),
]


@pytest.mark.parametrize("text,words", [c[1:] for c in BAD_MANIFEST], ids=[c[0] for c in BAD_MANIFEST])
def test_bad_manifests_are_refused_with_a_clear_message(text, words, tmp_path):
    folder = manifest(tmp_path, text)
    with pytest.raises(tf.InputError) as e:
        tf.load_dataset(folder)
    assert words in str(e.value)


def test_missing_dataset_folder():
    with pytest.raises(tf.InputError, match="no such dataset folder"):
        tf.load_dataset("/nonexistent/dataset")
