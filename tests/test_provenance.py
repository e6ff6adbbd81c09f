"""A fitted model's own name, description and provenance (docs/formats.md#provenance): in the model
file, in the results JSON, through a save/load round trip, and refused when malformed.

Oracles: the data hash against the system's own ``sha256sum`` (an independent implementation of
the documented recipe), the clock for the date, the package's version, the command line typed."""

import datetime
import json
import shutil
import subprocess

import pytest

import thermofriction as tf
from conftest import run_cli


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """One CLI identification: its dataset folder, model file, JSON and standard output."""
    root = tmp_path_factory.mktemp("prov")
    data = root / "bench-runs"
    r = run_cli("synth", "li2009-model-i", "--temperatures", "33.5", "--validate", "37", "--duration", "0.2",
                "--sample-rate", "2000", "--seed", "7", "-o", data)
    assert r.returncode == 0, r.stderr
    before = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0)
    r = run_cli("identify", data, "--method", "base", "--starts", "1", "--seed", "4", "-o", root / "fit.toml",
                "--json", root / "fit.json")
    after = datetime.datetime.now(datetime.timezone.utc)
    assert r.returncode == 0, r.stderr
    return data, root / "fit.toml", json.loads((root / "fit.json").read_text()), (before, after)


def test_fitted_model_has_its_own_name_and_description(fitted):
    data, path, _, _ = fitted
    model = tf.load_model(path)
    preset = tf.load_model("li2009-base")
    assert model.name != preset.name and model.description != preset.description
    assert "Eqs." not in model.description
    assert model.name == "base fit to synthetic-li2009-model-i"  # the dataset's name from synth's manifest
    assert "33.5 C" in model.description and "1 held out" in model.description and tf.__version__ in model.description


@pytest.mark.skipif(shutil.which("sha256sum") is None, reason="needs coreutils' sha256sum")
def test_data_hash_is_sha256sum_of_the_sorted_files(fitted):
    data, path, _, _ = fitted
    files = sorted(p.name for p in data.iterdir())
    assert files == ["T33.5C.csv", "T37C-validate.csv", "dataset.toml"]  # the manifest and both runs
    listing = subprocess.run(["sha256sum", *files], cwd=data, capture_output=True, check=True).stdout
    expected = subprocess.run(["sha256sum"], input=listing, capture_output=True, check=True).stdout.split()[0].decode()
    assert tf.load_model(path).provenance["data_sha256"] == expected
    # the report on the same folder names the same hash: a page can be traced to the model's data
    r = run_cli("report", path, data, "-o", path.parent / "report.html")
    assert r.returncode == 0, r.stderr
    assert f"data SHA-256 <code>{expected}</code>" in (path.parent / "report.html").read_text()


def test_provenance_records_method_date_version_options_and_command(fitted):
    data, path, results, (before, after) = fitted
    p = tf.load_model(path).provenance
    assert p["method"] == "base" and p["thermofriction"] == tf.__version__
    assert p["fit_files"] == ["T33.5C.csv"] and p["held_out_files"] == ["T37C-validate.csv"]
    assert p["initial_model"] == "li2009-base" and p["data"] == str(data)
    date = datetime.datetime.fromisoformat(p["date"].replace("Z", "+00:00"))
    assert p["date"].endswith("Z") and before <= date <= after
    assert p["options"]["starts"] == 1 and p["options"]["seed"] == 4
    assert p["command"].startswith("thermofriction identify ") and "--starts 1" in p["command"]
    # the results JSON: the same provenance at the top and in the model
    assert results["provenance"] == results["model"]["provenance"] == p


def test_model_file_round_trip_keeps_provenance(fitted, tmp_path):
    _, path, _, _ = fitted
    model = tf.load_model(path)
    model.save(tmp_path / "again.toml")
    back = tf.load_model(tmp_path / "again.toml")
    assert back.provenance == model.provenance and back.to_dict() == model.to_dict()
    # provenance is not physics: equal models whatever their history
    import dataclasses
    assert dataclasses.replace(model, provenance=None) == model


def test_report_accepts_the_json_beside_a_fitted_model(fitted, tmp_path):
    data, path, _, _ = fitted
    r = run_cli("report", path, data, "-o", tmp_path / "r.html")
    assert r.returncode == 0, r.stderr
    assert "describes another model" not in r.stderr


def test_changing_a_data_file_changes_the_hash(tmp_path):
    ds = tf.synthesize(tf.load_model("li2009-model-i"), [34.0], duration=0.1, sample_rate=1000, seed=2)
    tf.save_dataset(ds, tmp_path / "d")
    from thermofriction.identification.provenance import data_sha256
    where, h1 = data_sha256(tf.load_dataset(tmp_path / "d"))
    f = tmp_path / "d" / ds.experiments[0].file
    f.write_text(f.read_text().replace("\n0.001,", "\n0.0010,", 1))  # the same numbers, another file
    assert data_sha256(tf.load_dataset(tmp_path / "d"))[1] != h1 and where == str(tmp_path / "d")
    # in memory (never saved): the numbers, in order
    ds = tf.synthesize(tf.load_model("li2009-model-i"), [34.0], duration=0.1, sample_rate=1000, seed=2)
    w1, a1 = data_sha256(ds)
    assert w1 == "experiments in memory" and a1 == data_sha256(ds)[1]
    ds.experiments[0].displacement[5] += 1e-12
    assert data_sha256(ds)[1] != a1


@pytest.mark.parametrize("table,words", [
    ('method = "base"\ncolour = "red"', ["[provenance]", "colour"]),
    ("method = 3", ["[provenance]", "'method' must be a string"]),
    ('fit_files = "a.csv"', ["'fit_files' must be a list"]),
    ("options = { starts = { a = [1] } }", ["options 'starts'"]),
])
def test_malformed_provenance_is_refused_by_name(tmp_path, table, words):
    text = tf.load_model("li2009-base").to_toml() + "\n[provenance]\n" + table + "\n"
    (tmp_path / "m.toml").write_text(text)
    with pytest.raises(tf.InputError) as info:
        tf.load_model(tmp_path / "m.toml")
    for w in words:
        assert w in str(info.value), str(info.value)


def test_every_identify_option_fits_in_the_model_file(tmp_path):
    """Options of every shape (a table of law kinds, a list of plant parameters) go into [provenance]
    and the file loads again."""
    ds = tf.synthesize(tf.load_model("li2009-model-i"), [31.0, 40.5], duration=0.2, sample_rate=2000, noise=20e-9,
                       seed=9)
    fit = tf.identify(ds, method="model-i", starts=1, laws={"sigma0": "exp", "fc": "linear"}, free=["m_e"],
                      refine=False)
    opts = fit.model.provenance["options"]
    assert opts["laws"] == {"sigma0": "exp", "fc": "linear"} and opts["free"] == ["m_e"]
    assert fit.model.provenance["data"] == "experiments in memory"
    fit.model.save(tmp_path / "m.toml")
    assert tf.load_model(tmp_path / "m.toml").provenance == fit.model.provenance
