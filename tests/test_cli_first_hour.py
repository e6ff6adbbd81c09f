"""The first hour on the command line (issue 33): `init DIR` writes a dataset.toml that loads, `propagate` and
`report --bands` over tf.propagate and tf.report, every output option naming its formats, and unknown output
extensions refused before any work."""

from __future__ import annotations

import json
import os
import shutil

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.cli import build_parser, main
from thermofriction.cli.init import default_validation, temperature_from_name
from thermofriction.cli.outputs import _OUTPUT_FILES, FORMATS


def _files(folder):
    return {e.file: e for e in tf.load_dataset(folder).experiments}


@pytest.fixture(scope="module")
def five(tmp_path_factory):
    """Five actuator runs (one held out) written by save_dataset, CSV files named T<C>C.csv."""
    data = tf.synthesize(tf.load_model("li2009-model-i"), [31.0, 34.5, 38.4, 41.5], validate=[36.2], duration=0.3,
                         sample_rate=2000, seed=3)
    folder = tmp_path_factory.mktemp("five") / "runs"
    tf.save_dataset(data, folder)
    return folder


# -- init -----------------------------------------------------------------------------------------

def test_init_rebuilds_the_manifest_of_a_saved_dataset(five, tmp_path, capsys):
    """Round trip: the folder save_dataset wrote, without its manifest, gets one from init that loads the same
    experiments (files, temperatures from the names, held-out role from the name, the same samples)."""
    original = _files(five)
    folder = tmp_path / "runs"
    shutil.copytree(five, folder)
    (folder / "dataset.toml").unlink()
    assert main(["init", str(folder)]) == 0
    out = capsys.readouterr().out
    rebuilt = _files(folder)
    assert sorted(rebuilt) == sorted(original)
    for name, e in original.items():
        r = rebuilt[name]
        assert (r.temperature, r.role) == (e.temperature, e.role), name
        assert np.array_equal(r.displacement, e.displacement) and np.array_equal(r.voltage, e.voltage)
    assert "from the file name" in out and "T36.2C-validate.csv" in out and "wrote" in out
    assert "1 of 5 held out where the file name says so" in out


def test_init_reads_mat_files_and_temperature_columns(tmp_path, capsys):
    """MATLAB files whose names state no temperature: the manifest leaves it to the recorded column, and the
    loaded temperature is that column's mean."""
    data = tf.synthesize(tf.load_model("li2009-model-i"), [32.0, 40.0], duration=0.3, sample_rate=2000,
                         temperature_noise=0.05, seed=1)
    for e, name in zip(data.experiments, ("morning.mat", "evening.mat")):
        e.file = name
    tf.save_dataset(data, tmp_path / "mat")
    (tmp_path / "mat" / "dataset.toml").unlink()
    assert main(["init", str(tmp_path / "mat"), "--validate", "none"]) == 0
    assert "temperature" not in (tmp_path / "mat" / "dataset.toml").read_text().split("[[experiment]]", 1)[1]
    loaded = _files(tmp_path / "mat")
    for e in data.experiments:
        assert loaded[e.file].temperature == pytest.approx(np.mean(e.temperature_signal), abs=1e-9)
        assert abs(loaded[e.file].temperature - (32.0 if e.file == "morning.mat" else 40.0)) < 0.05
    assert "mean of its temperature column" in capsys.readouterr().out


def _plain_folder(five, tmp_path, names):
    folder = tmp_path / "plain"
    folder.mkdir()
    for src, dst in zip(sorted(f for f in os.listdir(five) if f.endswith(".csv")), names):
        shutil.copy(five / src, folder / dst)
    return folder


def test_init_without_a_temperature_names_the_files_and_the_way_out(five, tmp_path, capsys):
    folder = _plain_folder(five, tmp_path, ["a.csv", "b.csv", "c.csv"])
    assert main(["init", str(folder)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "a.csv, b.csv, c.csv" in err[0] and "--temperature FILE=C" in err[0]
    assert not (folder / "dataset.toml").exists()
    assert main(["init", str(folder), "--temperature", "a.csv=31", "--temperature", "b.csv=35.5",
                 "--temperature", "c.csv=40"]) == 0
    assert {f: e.temperature for f, e in _files(folder).items()} == {"a.csv": 31.0, "b.csv": 35.5, "c.csv": 40.0}
    assert main(["init", str(folder), "--force", "--temperature", "x.csv=31"]) == 2
    assert "x.csv is not one of the experiments" in capsys.readouterr().err.replace("'", "")  # (files or structs)


def test_init_asks_on_a_terminal(five, tmp_path, monkeypatch, capsys):
    folder = _plain_folder(five, tmp_path, ["a.csv", "b.csv"])
    answers = iter(["hot", "500", "33.3", "39"])  # not a number, not plausible, then two good ones
    monkeypatch.setattr("sys.stdin.isatty", lambda: True)
    monkeypatch.setattr("builtins.input", lambda prompt: next(answers))
    assert main(["init", str(folder)]) == 0
    assert {f: e.temperature for f, e in _files(folder).items()} == {"a.csv": 33.3, "b.csv": 39.0}
    assert capsys.readouterr().err.count("not a plausible temperature") == 2


def test_init_keeps_an_existing_manifest_unless_forced(five, tmp_path, capsys):
    folder = tmp_path / "runs"
    shutil.copytree(five, folder)
    before = (folder / "dataset.toml").read_bytes()
    assert main(["init", str(folder)]) == 2
    assert "--force" in capsys.readouterr().err and (folder / "dataset.toml").read_bytes() == before
    assert main(["init", str(folder), "--force", "--validate", "T31C.csv,T41.5C.csv"]) == 0
    assert {f for f, e in _files(folder).items() if e.role == "validate"} == {"T31C.csv", "T41.5C.csv"}


def test_init_that_would_not_load_writes_nothing(five, tmp_path, capsys):
    """A CSV that is no experiment: the error names it, no manifest is left; --exclude leaves it out."""
    folder = tmp_path / "runs"
    shutil.copytree(five, folder)
    (folder / "dataset.toml").unlink()
    (folder / "notes_31C.csv").write_text("what,when\n1,2\n")
    assert main(["init", str(folder)]) == 2
    err = capsys.readouterr().err
    assert "notes_31C.csv" in err and "--exclude" in err and not (folder / "dataset.toml").exists()
    assert main(["init", str(folder), "--exclude", "notes*"]) == 0
    assert "notes_31C.csv" not in _files(folder)


@pytest.mark.parametrize("name, T", [("run_35.2C.csv", 35.2), ("T35.2.csv", 35.2), ("35.2degC.mat", 35.2),
                                     ("stage_35p2C.csv", 35.2), ("temp_40.csv", 40.0), ("T30.8C-validate.csv", 30.8),
                                     ("x_35.2°C.csv", 35.2), ("run7.csv", None), ("T30C_T40C.csv", None),
                                     ("data.csv", None), ("stage-35p2C.csv", None)])  # (+ or - 35.2: issue 41)
def test_temperatures_in_file_names(name, T):
    assert temperature_from_name(name) == T


def test_the_default_split_holds_out_interior_temperatures():
    assert default_validation(list("abc")) == []
    assert default_validation(list("abcd")) == ["c"]
    assert default_validation(list("abcdefg")) == ["c", "e"]
    for n in range(4, 30):
        held = default_validation(list(range(n)))
        assert held and 0 not in held and n - 1 not in held and len(set(held)) == len(held) <= n // 3 + 1


# -- propagate and report --bands ----------------------------------------------------------------

@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """A base fit of two temperatures (one held out), its model file and results JSON as identify writes them."""
    folder = tmp_path_factory.mktemp("fit")
    data = tf.synthesize(tf.load_model("li2009-model-i"), [31.0, 41.0], validate=[36.0], duration=0.4,
                         sample_rate=2000, seed=2)
    tf.save_dataset(data, folder / "data")
    assert main(["identify", str(folder / "data"), "--method", "base", "--starts", "1", "-q",
                 "-o", str(folder / "fit.toml"), "--json", str(folder / "fit.json")]) == 0
    return folder


def test_a_fit_read_back_draws_what_the_fit_in_memory_draws(fitted):
    """The results JSON carries what tf.propagate needs: the same model, standard errors, correlations, and which
    parameters are drawn log-normally (inferred from the multiplicative intervals), so the draws are identical to
    the in-memory fit's (an independent path: the fit made again in Python)."""
    from thermofriction.cli.fits import load_fit
    from thermofriction.scale.propagate import draw_parameters

    fit = tf.identify(tf.load_dataset(fitted / "data"), "base", starts=1)
    back = load_fit(fitted / "fit.json")
    assert [p.positive for p in back.parameters.varying] == [p.positive for p in fit.parameters.varying]
    assert any(p.positive for p in fit.parameters.varying)
    names, a = draw_parameters(fit, 50, 7)
    names_back, b = draw_parameters(back, 50, 7)
    assert names == names_back and np.allclose(a, b, rtol=1e-12)
    def plain(model):  # the provenance says when and by which command: not the model
        return {k: v for k, v in model.to_dict().items() if k != "provenance"}
    assert plain(back.model) == plain(fit.model)


def test_propagate_on_the_command_line_is_tf_propagate(fitted, tmp_path, capsys):
    from thermofriction.cli.fits import load_fit
    from thermofriction.scale.propagate import load_propagation

    argv = ["propagate", str(fitted / "fit.json"), "--temperatures", "33,38", "--draws", "6", "--seed", "4",
            "--duration", "0.4", "--scheduler", "sequential", "-q"]
    assert main([*argv, "-o", str(tmp_path / "bands.json")]) == 0
    cli = load_propagation(tmp_path / "bands.json")
    api = tf.propagate(load_fit(fitted / "fit.json"), [33, 38], draws=6, seed=4, duration=0.4, sample_rate=1000,
                       scheduler="sequential", solver="auto")
    for name in ("nominal", "lower", "upper", "prediction_lower", "prediction_upper", "parameters", "step_lower"):
        assert np.allclose(getattr(cli, name), getattr(api, name), rtol=1e-12, equal_nan=True), name
    assert cli.temperatures.tolist() == [33.0, 38.0] and cli.draws == 6 and cli.level == 0.95
    assert main([*argv, "-o", str(tmp_path / "bands.csv")]) == 0
    head = (tmp_path / "bands.csv").read_text().splitlines()
    assert head[0].startswith("temperature[C],time[s],nominal[m]") and len(head) == 1 + 2 * cli.time.size
    assert main([*argv, "-o", str(tmp_path / "bands.mat")]) == 0
    import scipy.io
    mat = scipy.io.loadmat(tmp_path / "bands.mat")
    assert np.allclose(mat["lower"], cli.lower) and np.allclose(mat["temperatures"].ravel(), [33, 38])
    capsys.readouterr()


def test_report_bands_adds_the_section(fitted, tmp_path, capsys):
    assert main(["propagate", str(fitted / "fit.json"), "--temperatures", "36", "--draws", "4", "--duration", "0.4",
                 "--scheduler", "sequential", "-q", "-o", str(tmp_path / "bands.json")]) == 0
    model, data = str(fitted / "fit.toml"), str(fitted / "data")
    assert main(["report", model, data, "--bands", str(tmp_path / "bands.json"), "-o", str(tmp_path / "r.html")]) == 0
    assert "<h2>Prediction bands</h2>" in (tmp_path / "r.html").read_text()
    assert main(["report", model, data, "-o", str(tmp_path / "plain.html")]) == 0
    assert "Prediction bands" not in (tmp_path / "plain.html").read_text()
    capsys.readouterr()
    assert main(["report", model, data, "--bands", str(fitted / "fit.json"), "-o", str(tmp_path / "x.html")]) == 2
    err = capsys.readouterr().err
    assert "fit.json: not a propagation result" in err and not (tmp_path / "x.html").exists()


def _damaged(fit, how):
    d = json.loads(fit.read_text())
    name = next(iter(d["parameters"]))
    if how == "no model":
        del d["model"]
    elif how == "value null":
        d["parameters"][name]["value"] = None
    elif how == "value text":
        d["parameters"][name]["value"] = "big"
    elif how == "ci95 one number":
        d["parameters"][name]["ci95"] = [1.0]
    elif how == "correlation reordered":
        d["correlation"]["names"] = d["correlation"]["names"][::-1]
    elif how == "correlation ragged":
        d["correlation"]["matrix"] = [[1.0]]
    elif how == "n_points text":
        d["n_points"] = "many"
    elif how == "model without plant":
        del d["model"]["plant"]
    return d


@pytest.mark.parametrize("how", ["no model", "value null", "value text", "ci95 one number", "correlation reordered",
                                 "correlation ragged", "n_points text", "model without plant"])
def test_a_damaged_results_json_is_one_message(how, fitted, tmp_path, capsys):
    from thermofriction.cli.fits import load_fit
    path = tmp_path / "fit.json"
    path.write_text(json.dumps(_damaged(fitted / "fit.json", how)))
    with pytest.raises(tf.InputError, match=str(path).replace(".", r"\.")):
        load_fit(path)
    assert main(["propagate", str(path), "--temperatures", "36", "-o", str(tmp_path / "b.json")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("thermofriction: error: ") and not (tmp_path / "b.json").exists()


def test_propagate_refuses_what_is_not_a_fit(fitted, tmp_path, capsys):
    bad = tmp_path / "metrics.json"
    bad.write_text(json.dumps({"experiments": []}))
    assert main(["propagate", str(bad), "--temperatures", "36", "-o", str(tmp_path / "b.json")]) == 2
    assert "not an identification's results" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exit:  # argparse's refusal
        main(["propagate", str(fitted / "fit.json"), "--temperatures", "36,900"])
    assert exit.value.code == 2 and "900 C is not a plausible temperature" in capsys.readouterr().err


# -- output options: their formats in --help, anything else refused ---------------------------------

def _subparsers():
    import argparse
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices


def test_every_output_option_names_the_formats_it_writes():
    """Every subcommand's output option lists the extensions it writes (outputs.FORMATS, the list the refusal
    uses); an output option outside that list writes a folder (DIR)."""
    for command, p in _subparsers().items():
        for action in p._actions:
            if not set(action.option_strings) & {"-o", "--output", "--json"}:
                continue
            if (command, action.dest) in FORMATS:
                assert _OUTPUT_FILES[command][action.dest] in action.option_strings
                for ext in FORMATS[command, action.dest]:
                    assert ext in action.help, (command, action.dest, ext)
            else:
                assert action.metavar == "DIR" or "DIR" in (action.help or ""), (command, action.dest)
    assert {(c, d) for c, dests in _OUTPUT_FILES.items() for d in dests} == set(FORMATS)
    assert ".mat" in _subparsers()["simulate"].format_help()


REFUSED = {  # each command that writes files, with inputs that would fail later (the refusal comes first)
    ("simulate", "-o"): ["simulate", "no-such-model.toml", "-o", "{out}"],
    ("identify", "-o"): ["identify", "{missing}", "-o", "{out}"],
    ("identify", "--json"): ["identify", "{missing}", "--json", "{out}"],
    ("validate", "--json"): ["validate", "li2009-model-i", "{missing}", "--json", "{out}"],
    ("report", "-o"): ["report", "li2009-model-i", "{missing}", "-o", "{out}"],
    ("fmu", "-o"): ["fmu", "no-such-model.toml", "-o", "{out}"],
    ("sweep", "-o"): ["sweep", "no-such-model.toml", "--grid", "temperature=30,40", "-o", "{out}"],
    ("propagate", "-o"): ["propagate", "{missing}", "--temperatures", "36", "-o", "{out}"],
}


@pytest.mark.parametrize("key", REFUSED, ids=[" ".join(k) for k in REFUSED])
def test_an_unknown_output_extension_is_refused_before_any_work(key, tmp_path, capsys):
    command, option = key
    argv = [a.format(out=tmp_path / "out.xlsx", missing=tmp_path / "missing") for a in REFUSED[key]]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    dest = "json" if option == "--json" else "output"
    assert f"{option} {tmp_path / 'out.xlsx'}: unknown extension '.xlsx'" in err[0]
    assert all(ext in err[0] for ext in FORMATS[command, dest]), err[0]
    assert os.listdir(tmp_path) == []


def test_sweep_writes_a_mat_table(tmp_path, capsys):
    import scipy.io
    assert main(["sweep", "li2009-model-i", "--grid", "temperature=31,40", "--duration", "0.2", "--scheduler",
                 "sequential", "-q", "-o", str(tmp_path / "s.mat")]) == 0
    mat = scipy.io.loadmat(tmp_path / "s.mat")
    assert mat["temperature_C"].ravel().tolist() == [31.0, 40.0]
    assert main(["sweep", "li2009-model-i", "--grid", "temperature=31,40", "--duration", "0.2", "--scheduler",
                 "sequential", "-q", "-o", str(tmp_path / "s.csv")]) == 0
    header = (tmp_path / "s.csv").read_text().splitlines()[0].split(",")
    from thermofriction.data.matlab import matlab_name
    assert [matlab_name(h) for h in header[:-1]] == [k for k in mat if not k.startswith("__") and k != "error"]
    capsys.readouterr()
