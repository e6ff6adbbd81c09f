"""Datasets (docs/formats.md#datasets): reading, writing, synthesising, and one clear error per malformed input.

Oracles: the noise-free simulation of the same model (for the sensor effects), the values written
(for the round trip), and the file text itself (for the line and column an error must name)."""

import argparse
import dataclasses

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.cli.synth import add_synth_command
from thermofriction.data import Experiment, read_experiment_csv


@pytest.fixture(scope="module")
def small(model_i):
    return tf.synthesize(model_i, [31.0, 40.0], validate=[35.0], duration=0.3, sample_rate=2000, noise=20e-9,
                         quantization=1e-9, temperature_noise=0.05, record_stage=True, seed=11, name="small")


# -- synthesis ----------------------------------------------------------------------------------

def test_synthesize_save_load_round_trip(small, tmp_path):
    folder = tf.save_dataset(small, tmp_path / "d")
    assert small.path == folder and (folder / "dataset.toml").is_file()
    assert (folder / "T31C.csv").read_text().splitlines()[0] == \
        "time[s],voltage[V],displacement[um],temperature[C],stage_displacement[um]"
    data = tf.load_dataset(folder)
    assert data.name == "small" and data.description == small.description and data.path == folder
    assert [e.role for e in data.experiments] == ["fit", "fit", "validate"]
    assert [e.temperature for e in data.fit] == [31.0, 40.0] and [e.temperature for e in data.validate] == [35.0]
    assert data.temperatures == [31.0, 40.0, 35.0]
    for a, b in zip(small.experiments, data.experiments):
        assert (b.file, b.description, b.role) == (a.file, a.description, a.role)
        assert b.input == a.input == tf.load_model("li2009-model-i").input
        for name in ("time", "voltage", "displacement", "temperature_signal", "stage_displacement"):
            # ten significant digits in the file
            np.testing.assert_allclose(getattr(b, name), getattr(a, name), rtol=6e-10, atol=0, err_msg=name)
        assert b.sample_rate == pytest.approx(2000) and b.duration == pytest.approx(0.3)
    assert not list(folder.glob(".*.tmp"))  # atomic writes leave no temporary file


def test_synthesis_is_reproducible_with_independent_streams(model_i):
    kw = dict(duration=0.2, sample_rate=2000, noise=20e-9, seed=5)
    a = tf.synthesize(model_i, [31.0, 40.0], validate=[35.0], **kw)
    b = tf.synthesize(model_i, [31.0, 40.0], validate=[35.0], **kw)
    c = tf.synthesize(model_i, [31.0, 40.0, 33.0], validate=[35.0, 38.0], **kw)
    d = tf.synthesize(model_i, [31.0, 40.0], validate=[35.0], **{**kw, "seed": 6})
    for x, y in zip(a.experiments, b.experiments):
        np.testing.assert_array_equal(x.displacement, y.displacement)
    # adding an experiment of either role changes no other
    for x, y in zip(a.fit + a.validate, c.fit[:2] + c.validate[:1]):
        np.testing.assert_array_equal(x.displacement, y.displacement)
    assert not np.array_equal(a.experiments[0].displacement, d.experiments[0].displacement)
    # two runs at the same temperature: different noise, different files
    e = tf.synthesize(model_i, [31.0, 31.0], **kw)
    assert e.experiments[0].file != e.experiments[1].file
    assert not np.array_equal(e.experiments[0].displacement, e.experiments[1].displacement)


@pytest.fixture(scope="module")
def clean(model_i):
    return tf.synthesize(model_i, [36.0], duration=1.0, noise=0.0, seed=1).experiments[0]


def test_sensor_noise_is_what_was_asked(model_i, clean):
    noisy = tf.synthesize(model_i, [36.0], duration=1.0, noise=20e-9, record_stage=True, seed=1).experiments[0]
    assert np.std(noisy.displacement - clean.displacement) == pytest.approx(20e-9, rel=0.03)
    assert abs(np.mean(noisy.displacement - clean.displacement)) < 4 * 20e-9 / np.sqrt(clean.time.size)
    sim = tf.simulate(model_i, 1.0, temperature=36.0, sample_rate=10_000, controller=tf.StepSizeController(rtol=1e-10))
    assert np.std(noisy.stage_displacement - sim.stage_displacement) == pytest.approx(20e-9, rel=0.03)
    np.testing.assert_array_equal(noisy.voltage, sim.input)


def test_quantisation_to_multiples_of_q(model_i):
    q = 5e-9
    e = tf.synthesize(model_i, [36.0], duration=0.2, noise=20e-9, quantization=q, record_stage=True,
                      seed=1).experiments[0]
    for x in (e.displacement, e.stage_displacement):
        np.testing.assert_allclose(x / q, np.round(x / q), rtol=0, atol=1e-6)
    assert len(np.unique(np.round(np.diff(e.displacement) / q))) > 3


def test_drift_is_a_slow_line_with_a_random_sign(model_i, clean):
    drift = 1e-6
    data = tf.synthesize(model_i, [36.0] * 6, duration=1.0, noise=0.0, drift=drift, seed=1)
    slopes = [np.polyfit(e.time, e.displacement - clean.displacement, 1)[0] for e in data.experiments]
    np.testing.assert_allclose(np.abs(slopes), drift, rtol=1e-6)
    assert {np.sign(s) for s in slopes} == {-1.0, 1.0}   # 2^-5 chance per seed of one sign only; seed 1 has both
    assert "drift" in data.experiments[0].description


def test_temperature_record_and_its_noise(model_i):
    kw = dict(duration=0.5, sample_rate=4000, noise=0.0, seed=3)
    e = tf.synthesize(model_i, [33.0], temperature_noise=0.1, **kw).experiments[0]
    assert e.temperature == 33.0  # the manifest's temperature is the true one
    assert np.std(e.temperature_signal - 33.0) == pytest.approx(0.1, rel=0.05)
    assert e.temperature_input() == 33.0  # noise, not variation
    e = tf.synthesize(model_i, [33.0], record_temperature=True, **kw).experiments[0]
    np.testing.assert_array_equal(e.temperature_signal, 33.0)
    assert tf.synthesize(model_i, [33.0], temperature_noise=0.1, record_temperature=False,
                         **kw).experiments[0].temperature_signal is None
    assert tf.synthesize(model_i, [33.0], **kw).experiments[0].temperature_signal is None


def test_temperature_input_follows_a_varying_record():
    t = np.linspace(0, 1, 11)
    ramp = Experiment("a.csv", t, t, t, 31.0, temperature_signal=30.0 + 2 * t)
    T = ramp.temperature_input()
    assert isinstance(T, tf.Sampled) and T(np.array([0.5]))[0] == pytest.approx(31.0)
    steady = dataclasses.replace(ramp, temperature_signal=31.0 + 0.1 * np.sin(40 * t))
    assert steady.temperature_input() == 31.0
    assert dataclasses.replace(ramp, temperature_signal=None).temperature_input() == 31.0


def test_roles_and_synthesis_options(model_i):
    data = tf.synthesize(model_i, [31.0], validate=[33.0, 39.0], duration=0.1, sample_rate=1000)
    assert [e.temperature for e in data.fit] == [31.0] and [e.temperature for e in data.validate] == [33.0, 39.0]
    assert all(e.role == "validate" for e in data.validate) and data.fit[0].role == "fit"
    assert data.fit[0].time.size == 101 and data.fit[0].sample_rate == pytest.approx(1000)
    d = data.fit[0].description
    assert "li2009" in d and "sawtooth" in d and "noise 2e-08 m" in d


def test_synthesis_needs_an_input_and_sane_values(model_i):
    bare = dataclasses.replace(model_i, input=None)
    with pytest.raises(tf.InputError, match="no \\[input\\]"):
        tf.synthesize(bare, [31.0], duration=0.05)
    e = tf.synthesize(bare, [31.0], duration=0.05, sample_rate=2000, input=tf.Sawtooth(30.0, 5.0)).experiments[0]
    assert e.voltage.max() > 0 and e.input == tf.Sawtooth(30.0, 5.0)
    for kw, words in (({"noise": -1e-9}, "noise"), ({"quantization": float("nan")}, "quantization"),
                      ({"duration": 0.0}, "duration"), ({"drift": float("inf")}, "drift")):
        with pytest.raises(tf.InputError, match=words):
            tf.synthesize(model_i, [31.0], **kw)
    with pytest.raises(tf.InputError, match="temperature"):
        tf.synthesize(model_i, [float("nan")])
    with pytest.raises(tf.InputError, match="at least one temperature"):
        tf.synthesize(model_i, [])


# -- experiment files -------------------------------------------------------------------------

HEADER = "time[s],voltage[V],displacement[um]\n"
ROWS = "".join(f"{i * 1e-3:.6f},{i * 0.1:.3f},{i * 0.01:.4f}\n" for i in range(20))  # row i is on line i + 2


def test_units_are_converted_to_si(tmp_path):
    path = tmp_path / "run.csv"
    path.write_text("time[ms],voltage[mV],displacement[nm],temperature[C],stage_displacement[mm]\n" +
                    "".join(f"{i},{i},{10 * i},35,{i}\n" for i in range(12)))
    cols = read_experiment_csv(path)
    assert cols["time"][1] == pytest.approx(1e-3) and cols["voltage"][1] == pytest.approx(1e-3)
    assert cols["displacement"][1] == pytest.approx(10e-9) and cols["stage_displacement"][1] == pytest.approx(1e-3)
    np.testing.assert_array_equal(cols["temperature"], 35.0)
    path.write_text("time,voltage,displacement[µm]\n" + "".join(f"{i},{i},{i}\n" for i in range(12)),
                    encoding="utf-8")
    cols = read_experiment_csv(path)
    assert cols["time"][1] == 1.0 and cols["displacement"][1] == pytest.approx(1e-6)


def test_a_large_file_reads_fast_and_still_names_the_bad_line(tmp_path):
    """The fast path (numpy) and the exact scanner agree; the scanner finds the line."""
    n = 50_000
    t = np.arange(n) * 1e-4
    rows = np.column_stack([t, np.sin(t), np.cos(t)])
    path = tmp_path / "big.csv"
    with open(path, "w") as fh:
        fh.write(HEADER)
        np.savetxt(fh, rows, delimiter=",", fmt="%.10g")
    cols = read_experiment_csv(path)
    np.testing.assert_allclose(cols["displacement"], np.cos(t) * 1e-6, rtol=1e-9)
    lines = path.read_text().splitlines()
    lines[40_001] = lines[40_001].rsplit(",", 1)[0] + ",1.2.3"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(tf.InputError, match="line 40002, column 3 \\(displacement\\[um\\]\\): not a number"):
        read_experiment_csv(path)


BAD_CSV = [  # (id, file text or None for no file, fragments the message must contain)
    ("missing file", None, ["no such file"]),
    ("empty file", "", ["empty file"]),
    ("header only", HEADER, ["no data rows"]),
    ("missing column", "time[s],voltage[V]\n" + "".join(f"{i},{i}\n" for i in range(20)),
     ["line 1", "missing column displacement"]),
    ("unknown column", HEADER.replace("\n", ",force[N]\n") + ROWS.replace("\n", ",1\n"),
     ["line 1, column 4", "unknown column 'force'"]),
    ("unknown unit", HEADER.replace("[um]", "[furlong]") + ROWS,
     ["line 1, column 3", "unknown unit 'furlong'", "m, mm, um"]),
    ("temperature unit", HEADER.replace("\n", ",temperature[K]\n") + ROWS.replace("\n", ",300\n"),
     ["line 1, column 4", "unknown unit 'K'"]),
    ("duplicate column", HEADER.replace("\n", ",time[ms]\n") + ROWS.replace("\n", ",1\n"),
     ["line 1, column 4", "duplicate column 'time'"]),
    ("bad header cell", HEADER.replace("[um]", "[um"), ["line 1, column 3", "name[unit]"]),
    ("wrong cell count", HEADER + ROWS.replace("0.0400\n", "0.0400,7\n", 1), ["line 6:", "4 values, expected 3"]),
    ("too few cells", HEADER + ROWS.replace(",0.0400\n", "\n", 1), ["line 6:", "2 values, expected 3"]),
    ("not a number", HEADER + ROWS.replace("0.0300", "abc", 1),
     ["line 5, column 3 (displacement[um])", "not a number: 'abc'"]),
    ("empty cell", HEADER + ROWS.replace("0.300,", ",", 1), ["line 5, column 2 (voltage[V])", "not a number"]),
    ("NaN", HEADER + ROWS.replace("0.0400\n", "nan\n", 1), ["line 6, column 3 (displacement[um])", "not a finite"]),
    ("inf", HEADER + ROWS.replace("0.500,", "inf,", 1), ["line 7, column 2 (voltage[V])", "not a finite"]),
    ("non-monotonic time", HEADER + ROWS.replace("0.005000", "0.003000"),
     ["line 7, column 1 (time[s])", "time must increase strictly", "line 6"]),
    ("repeated time", HEADER + ROWS.replace("0.005000", "0.004000"),
     ["line 7, column 1 (time[s])", "time must increase strictly"]),
    ("irregular sampling", HEADER + ROWS.replace("0.008000", "0.008500"),
     ["line 10, column 1 (time[s])", "irregular sampling", "1 %"]),
    ("too few samples", HEADER + ROWS[:60], ["3 data rows", "at least 10 samples"]),
    ("implausible temperature", HEADER.replace("\n", ",temperature[C]\n")
     + "".join(f"{i * 1e-3},{i},{i},{400 if i == 12 else 35}\n" for i in range(20)),
     ["line 14, column 4 (temperature[C])", "not a plausible temperature"]),
    ("blank lines keep line numbers", HEADER + "\n" + ROWS.replace("0.0400\n", "0.0400\n\n", 1).replace(
        "0.0900", "x", 1), ["line 13, column 3", "not a number: 'x'"]),
]


@pytest.mark.parametrize("text,words", [c[1:] for c in BAD_CSV], ids=[c[0] for c in BAD_CSV])
def test_bad_experiment_files_name_file_line_and_column(text, words, tmp_path):
    path = tmp_path / "run.csv"
    if text is not None:
        path.write_text(text, encoding="utf-8")
    with pytest.raises(tf.InputError) as e:
        read_experiment_csv(path)
    msg = str(e.value)
    assert msg.startswith(f"{path}: ") and msg.count("\n") == 0, msg
    for w in words:
        assert w in msg, (w, msg)


def test_unreadable_experiment_files(tmp_path):
    with pytest.raises(tf.InputError, match="is a folder") as e:
        read_experiment_csv(tmp_path)
    assert str(e.value) == f"{tmp_path}: is a folder, not an experiment CSV file"  # one message, not wrapped
    path = tmp_path / "latin1.csv"
    path.write_bytes(HEADER.encode() + ROWS.encode() + "0.1,1,2\xb5\n".encode("latin-1"))
    with pytest.raises(tf.InputError, match="line 22: not UTF-8"):
        read_experiment_csv(path)


# -- manifests --------------------------------------------------------------------------------

def manifest(tmp_path, text, csv=HEADER + ROWS):
    (tmp_path / "run.csv").write_text(csv)
    (tmp_path / "dataset.toml").write_text(text)
    return tmp_path


GOOD = '[[experiment]]\nfile = "run.csv"\ntemperature = 30.0\n'
BAD_MANIFEST = [  # (id, dataset.toml, fragments)
    ("unknown key", GOOD + 'rol = "fit"\n', ["[[experiment]] 1", "unknown key 'rol'"]),
    ("unknown key in the 2nd", GOOD + GOOD + 'temp = 3\n', ["[[experiment]] 2", "unknown key 'temp'"]),
    ("unknown top-level key", 'title = "x"\n' + GOOD, ["unknown key 'title'"]),
    ("escaping path", GOOD.replace("run.csv", "../run.csv"), ["[[experiment]] 1", "'../run.csv'", "inside"]),
    ("escaping path in the middle", GOOD.replace("run.csv", "a/../../run.csv"), ["inside the dataset folder"]),
    ("absolute path", GOOD.replace("run.csv", "/etc/passwd"), ["[[experiment]] 1", "'/etc/passwd'", "inside"]),
    ("TOML syntax", '[[experiment]\nfile = "run.csv"\n', ["TOML syntax error", "line 1, column 13"]),
    ("TOML syntax, line 3", GOOD.replace("30.0", "30.0.1"), ["TOML syntax error", "line 3"]),
    ("missing temperature", '[[experiment]]\nfile = "run.csv"\n', ["[[experiment]] 1", "no temperature"]),
    ("temperature not a number", GOOD.replace("30.0", '"hot"'), ["'temperature' must be a number"]),
    ("implausible temperature", GOOD.replace("30.0", "1000.0"), ["not plausible"]),
    ("missing 'file'", '[[experiment]]\ntemperature = 30.0\n', ["[[experiment]] 1", "missing 'file'"]),
    ("bad role", GOOD + 'role = "train"\n', ["[[experiment]] 1", "'role'", "train"]),
    ("bad input", GOOD + 'input = "wobble:x=1"\n', ["[[experiment]] 1", "wobble"]),
    ("no experiments", 'name = "x"\n', ["no [[experiment]]"]),
    ("name not a string", 'name = 3\n' + GOOD, ["'name' must be a string"]),
]


@pytest.mark.parametrize("text,words", [c[1:] for c in BAD_MANIFEST], ids=[c[0] for c in BAD_MANIFEST])
def test_bad_manifests_name_dataset_toml_and_the_entry(text, words, tmp_path):
    folder = manifest(tmp_path, text)
    with pytest.raises(tf.InputError) as e:
        tf.load_dataset(folder)
    msg = str(e.value)
    assert msg.startswith(f"{folder / 'dataset.toml'}: "), msg
    for w in words:
        assert w in msg, (w, msg)


def test_manifest_errors_in_an_experiment_file_name_that_file(tmp_path):
    folder = manifest(tmp_path, GOOD.replace("run.csv", "nope.csv"))
    with pytest.raises(tf.InputError, match="nope.csv: no such file"):
        tf.load_dataset(folder)
    folder = manifest(tmp_path, GOOD, csv=HEADER + ROWS.replace("0.0300", "abc", 1))
    with pytest.raises(tf.InputError, match="run.csv: line 5, column 3"):
        tf.load_dataset(folder)


def test_temperature_from_the_csv_column(tmp_path):
    csv = HEADER.replace("\n", ",temperature[C]\n") + "".join(
        f"{i * 1e-3},{i},{i},{35 + 0.01 * (i % 3)}\n" for i in range(20))
    folder = manifest(tmp_path, '[[experiment]]\nfile = "run.csv"\nrole = "validate"\n', csv=csv)
    e = tf.load_dataset(folder).experiments[0]
    assert e.temperature == pytest.approx(np.mean(35 + 0.01 * (np.arange(20) % 3)))
    assert e.role == "validate" and e.temperature_input() == e.temperature


def test_missing_or_wrong_dataset_folder(tmp_path):
    with pytest.raises(tf.InputError, match="no such dataset folder"):
        tf.load_dataset(tmp_path / "nonexistent")
    with pytest.raises(tf.InputError, match="no dataset.toml"):
        tf.load_dataset(tmp_path)
    (tmp_path / "run.csv").write_text(HEADER + ROWS)
    with pytest.raises(tf.InputError, match="not a dataset folder"):
        tf.load_dataset(tmp_path / "run.csv")
    folder = manifest(tmp_path, GOOD)
    assert len(tf.load_dataset(folder / "dataset.toml").experiments) == 1  # the manifest itself will do


def test_save_refuses_what_it_could_not_load_back(small, tmp_path):
    twice = dataclasses.replace(small, experiments=[small.experiments[0], small.experiments[0]])
    with pytest.raises(tf.InputError, match="same file"):
        tf.save_dataset(twice, tmp_path / "a")
    escaping = dataclasses.replace(small, experiments=[dataclasses.replace(small.experiments[0], file="../x.csv")])
    with pytest.raises(tf.InputError, match="inside the dataset folder"):
        tf.save_dataset(escaping, tmp_path / "b")
    (tmp_path / "file").write_text("")
    with pytest.raises(tf.InputError, match="cannot create"):
        tf.save_dataset(small, tmp_path / "file")
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


# -- command line -----------------------------------------------------------------------------

def synth_parser():
    p = argparse.ArgumentParser(prog="thermofriction")
    add_synth_command(p.add_subparsers(dest="command"))
    return p


def test_synth_command(tmp_path, capsys):
    p = synth_parser()
    args = p.parse_args(["synth", "li2009-model-i", "--temperatures", "31, 40", "--validate", "35", "--duration",
                         "0.1", "--sample-rate", "2000", "--noise", "1e-8", "--quantization", "1e-9",
                         "--temperature-noise", "0.05", "--drift", "1e-9", "--record-stage", "--seed", "4",
                         "-o", str(tmp_path / "d")])
    assert args.run(args) == 0
    out = capsys.readouterr().out
    assert out.count("wrote") == 4 and "dataset.toml" in out and "T31C.csv" in out
    data = tf.load_dataset(tmp_path / "d")
    assert [e.temperature for e in data.fit] == [31.0, 40.0] and [e.temperature for e in data.validate] == [35.0]
    e = data.experiments[0]
    assert e.time.size == 201 and e.temperature_signal is not None and e.stage_displacement is not None
    same = tf.synthesize(tf.load_model("li2009-model-i"), [31.0, 40.0], validate=[35.0], duration=0.1,
                         sample_rate=2000, noise=1e-8, quantization=1e-9, temperature_noise=0.05, drift=1e-9,
                         record_stage=True, seed=4)
    np.testing.assert_allclose(e.displacement, same.experiments[0].displacement, rtol=6e-10, atol=1e-18)
    args = p.parse_args(["synth", "li2009-model-i", "--temperatures", "33", "--duration", "0.05",
                         "--record-temperature", "--input", "sawtooth:amplitude=20,frequency=10", "-o",
                         str(tmp_path / "e")])
    assert args.run(args) == 0
    e = tf.load_dataset(tmp_path / "e").experiments[0]
    np.testing.assert_array_equal(e.temperature_signal, 33.0)
    assert e.input == tf.Sawtooth(20.0, 10.0) and e.stage_displacement is None


@pytest.mark.parametrize("argv,words", [
    (["--temperatures", "31,abc"], "--temperatures"),
    (["--temperatures", ""], "at least one temperature"),
    (["--temperatures", "31", "--duration", "-1"], "--duration"),
    (["--temperatures", "31", "--noise=-1e-9"], "--noise"),
    (["--temperatures", "31", "--input", "wobble:x=1"], "wobble"),
])
def test_synth_command_bad_values_are_input_errors(argv, words, tmp_path):
    args = synth_parser().parse_args(["synth", "li2009-model-i", *argv, "-o", str(tmp_path / "d")])
    with pytest.raises(tf.InputError, match=words):
        args.run(args)
    assert not (tmp_path / "d").exists()


def test_synth_help_documents_every_option():
    p = argparse.ArgumentParser(prog="thermofriction")
    text = add_synth_command(p.add_subparsers()).format_help()
    for opt in ("--temperatures", "--validate", "--duration", "--sample-rate", "--input", "--noise", "--quantization",
                "--temperature-noise", "--drift", "--record-temperature", "--record-stage", "--seed", "--output"):
        assert opt in text, opt
    assert "[m]" in text and "[C]" in text and "[Hz]" in text
