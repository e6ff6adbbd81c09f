"""MATLAB files (docs/formats.md#matlab-files): datasets read from .mat files, simulations and
datasets written to them, and one clear message (exit 2) for each bad .mat input.

Oracles: the same runs read from the CSV files of the same dataset (a dataset written as CSV and
as .mat by different writers -- SciPy's savemat called here as MATLAB's save would write, not the
package's writer -- must load to the same arrays), and the simulation CSV for `simulate -o x.mat`."""

import os

import numpy as np
import pytest
import scipy.io

import thermofriction as tf
from conftest import run_cli


@pytest.fixture(scope="module")
def runs():
    # a truth away from the preset: fc's law scaled, another seed and temperatures
    model = tf.load_model("li2009-model-i")
    return tf.synthesize(model, [32.5, 39.0], validate=[36.2], duration=0.25, sample_rate=4000, noise=15e-9,
                         temperature_noise=0.05, record_stage=True, seed=23, name="mat-runs")


@pytest.fixture(scope="module")
def csv_folder(runs, tmp_path_factory):
    return tf.save_dataset(runs, tmp_path_factory.mktemp("csv") / "d")


def _manifest(folder, entries):
    lines = ['name = "from-matlab"']
    for e in entries:
        lines.append("[[experiment]]")
        lines += [f"{k} = {v!r}".replace("'", '"') if not isinstance(v, dict) else
                  f"{k} = {{ {', '.join(f'{a} = {b!r}' for a, b in v.items())} }}".replace("'", '"')
                  for k, v in e.items()]
    (folder / "dataset.toml").write_text("\n".join(lines) + "\n")


def _same_runs(a, b, rtol=1e-9):
    assert [e.temperature for e in a.experiments] == pytest.approx([e.temperature for e in b.experiments])
    assert [e.role for e in a.experiments] == [e.role for e in b.experiments]
    for x, y in zip(a.experiments, b.experiments):
        for name in ("time", "voltage", "displacement", "temperature_signal", "stage_displacement"):
            u, v = getattr(x, name), getattr(y, name)
            assert (u is None) == (v is None), name
            if u is not None:  # the CSV holds ten significant digits: compare on the signal's scale
                np.testing.assert_allclose(u, v, rtol=0, atol=rtol * np.ptp(v) + 1e-12 * np.max(np.abs(v)), err_msg=name)


def test_mat_variables_with_unit_suffixes_read_as_the_csv_files(runs, csv_folder, tmp_path):
    """One .mat per run, variables as a MATLAB user saves them: time in ms, lengths in um and nm,
    voltage in mV, temperature in C, vectors as rows (1xN, MATLAB's default for linspace)."""
    ref = tf.load_dataset(csv_folder)
    entries = []
    for e in ref.experiments:
        f = e.file.replace(".csv", ".mat")
        scipy.io.savemat(tmp_path / f, {"time_ms": e.time[None, :] * 1e3, "voltage_mV": e.voltage * 1e3,
                                        "displacement_um": e.displacement * 1e6,
                                        "stage_displacement_nm": e.stage_displacement * 1e9,
                                        "temperature_C": e.temperature_signal, "operator": "someone",
                                        "gain": np.eye(2)})  # other variables are ignored
        entries.append({"file": f, "temperature": e.temperature, "role": e.role, "input": e.input.spec()})
    _manifest(tmp_path, entries)
    _same_runs(tf.load_dataset(tmp_path), ref)


def test_one_mat_file_with_a_struct_per_run_and_units_in_the_manifest(runs, csv_folder, tmp_path):
    ref = tf.load_dataset(csv_folder)
    structs = {f"run{i}": {"time": e.time, "voltage": e.voltage, "displacement": e.displacement * 1e6,
                           "temperature": e.temperature_signal, "stage_displacement": e.stage_displacement * 1e6}
               for i, e in enumerate(ref.experiments)}
    scipy.io.savemat(tmp_path / "runs.mat", structs)
    _manifest(tmp_path, [{"file": "runs.mat", "struct": f"run{i}", "temperature": e.temperature, "role": e.role,
                          "units": {"displacement": "um", "stage_displacement": "um"}}
                         for i, e in enumerate(ref.experiments)])
    data = tf.load_dataset(tmp_path)
    _same_runs(data, ref)
    assert [e.struct for e in data.experiments] == ["run0", "run1", "run2"]
    # saved again: one file, a struct per run, read back the same
    again = tf.save_dataset(data, tmp_path / "again")
    assert sorted(p.name for p in again.iterdir()) == ["dataset.toml", "runs.mat"]
    assert set(scipy.io.whosmat(again / "runs.mat")) >= {("run0", (1, 1), "struct")}
    _same_runs(tf.load_dataset(again), ref)


def test_save_dataset_writes_mat_files_that_load_back_exactly(runs, tmp_path):
    import dataclasses
    mat = dataclasses.replace(runs, experiments=[dataclasses.replace(e, file=e.file.replace(".csv", ".mat"))
                                                 for e in runs.experiments])
    folder = tf.save_dataset(mat, tmp_path / "m")
    back = tf.load_dataset(folder)
    for x, y in zip(back.experiments, runs.experiments):  # doubles in the file: exact up to the um scaling
        np.testing.assert_allclose(x.displacement, y.displacement, rtol=1e-15, atol=0)
        np.testing.assert_array_equal(x.time, y.time)
    # MATLAB's view: plain double column vectors with the unit in the name
    assert dict((n, c) for n, _, c in scipy.io.whosmat(folder / back.experiments[0].file)) == {
        "time": "double", "voltage": "double", "displacement_um": "double", "temperature": "double",
        "stage_displacement_um": "double"}


def test_simulate_to_mat_holds_the_csv_columns(tmp_path):
    args = ["simulate", "li2009-model-ii", "--temperature", "37.3", "--duration", "0.3", "--sample-rate", "3000"]
    r1 = run_cli(*args, "-o", tmp_path / "s.mat")
    r2 = run_cli(*args, "-o", tmp_path / "s.csv")
    assert r1.returncode == 0 and r2.returncode == 0, r1.stderr + r2.stderr
    m = scipy.io.loadmat(tmp_path / "s.mat")
    header = (tmp_path / "s.csv").read_text().splitlines()[0].split(",")
    table = np.loadtxt(tmp_path / "s.csv", delimiter=",", skiprows=1)
    from thermofriction.data.matlab import matlab_name
    assert "velocity_m_per_s" in m and "displacement_m" in m
    for j, h in enumerate(header):  # the CSV has 12 significant digits
        np.testing.assert_allclose(m[matlab_name(h)].ravel(), table[:, j], rtol=1e-11, atol=1e-300, err_msg=h)
    # one whole 5 Hz period in 0.3 s: the displacement over it, read from the CSV at the period's ends
    assert m["cycle_times_s"].ravel() == pytest.approx([0.0, 0.2])
    x = np.interp([0.0, 0.2], table[:, 0], table[:, header.index("displacement[m]")])
    assert m["step_sizes_m"].ravel() == pytest.approx([x[1] - x[0]], rel=1e-9)


# -- bad input: one line naming the file and the variable, exit 2 --------------------------------

N = 40
T = np.arange(N) / 1000.0


def good(**change):
    v = {"time": T, "voltage": np.linspace(0, 30, N), "displacement_um": np.linspace(0, 3, N)}
    v.update(change)
    return {k: x for k, x in v.items() if x is not None}


def v73(path):
    # a v7.3 file is HDF5 behind MATLAB's 512-byte header (the HDF5 signature at offset 512)
    path.write_bytes(b"MATLAB 7.3 MAT-file, Platform: GLNXA64".ljust(116, b" ") + b"\0" * 12 + b"\x00\x02IM"
                     + b"\0" * (512 - 132) + b"\x89HDF\r\n\x1a\n" + b"\0" * 200)


def corrupted_compressed(path):
    # a v7 file (compressed variables) whose zlib stream is damaged half-way: SciPy raises zlib.error
    scipy.io.savemat(path, good(), do_compression=True)
    raw = bytearray(path.read_bytes())
    for i in range(200, len(raw) - 20, 7):
        raw[i] ^= 0x5A
    path.write_bytes(bytes(raw))


BAD = [
    ("v7.3 file", v73, None, ["run.mat", "v7.3", "-v7", "CSV"]),
    ("empty file", lambda p: p.write_bytes(b""), None, ["run.mat", "empty file (0 bytes)", "interrupted copy"]),
    ("truncated header", lambda p: p.write_bytes(b"MATLAB 5.0 MAT-file"), None,
     ["run.mat", "not a readable MATLAB file"]),
    ("corrupted compressed stream", corrupted_compressed, None, ["run.mat", "not a readable MATLAB file"]),
    ("not a MATLAB file", lambda p: p.write_bytes(os.urandom(300)), None, ["run.mat", "not a readable MATLAB file"]),
    ("matrix", good(displacement_um=np.ones((N, 2))), None, ["run.mat", "'displacement_um'", f"{N}x2", "vector"]),
    ("text", good(voltage="thirty volts"), None, ["run.mat", "'voltage'", "text"]),
    ("complex", good(voltage=np.ones(N) * (1 + 1j)), None, ["run.mat", "'voltage'", "complex"]),
    ("lengths differ", good(voltage=np.ones(N - 1)), None, ["run.mat", "'voltage'", f"{N - 1} values", f"{N}"]),
    ("missing", good(displacement_um=None, displacment_um=np.ones(N)), None,
     ["run.mat", "missing displacement", "displacment_um"]),
    ("unknown unit", good(displacement_um=None, displacement_inch=np.ones(N)), None,
     ["run.mat", "'displacement_inch'", "unknown unit 'inch'", "displacement_um"]),
    ("twice", good(displacement=np.ones(N) * 1e-6), None, ["run.mat", "'displacement'", "'displacement_um'"]),
    ("nan", good(displacement_um=np.where(np.arange(N) == 17, np.nan, 1.0)), None,
     ["run.mat", "'displacement_um', element 18", "not a finite number"]),
    ("time backwards", good(time=np.where(np.arange(N) == 9, 0.0, T)), None,
     ["run.mat", "'time', element 10", "increase strictly"]),
    ("no struct", good(), {"struct": "run1"}, ["run.mat", "no variable 'run1'", "time"]),
    ("not a struct", good(), {"struct": "time"}, ["run.mat", "'time'", "must be a struct"]),
    ("units clash", good(), {"units": {"displacement": "nm"}}, ["run.mat", "'displacement_um'", "um", "nm",
                                                                "once"]),
    ("bad manifest unit", good(displacement_um=None, displacement=np.ones(N)), {"units": {"displacement": "furlong"}},
     ["dataset.toml", "[[experiment]] 1", "furlong"]),
]


def _write(tmp_path, content, extra):
    path = tmp_path / "run.mat"
    if callable(content):
        content(path)
    else:
        scipy.io.savemat(path, content)
    _manifest(tmp_path, [{"file": "run.mat", "temperature": 35.0, **(extra or {})}])


@pytest.mark.parametrize("content,extra,expected", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_mat_input_is_one_clear_message(tmp_path, content, extra, expected):
    _write(tmp_path, content, extra)
    with pytest.raises(tf.InputError) as info:
        tf.load_dataset(tmp_path)
    err = str(info.value)
    assert len(err.splitlines()) == 1, err
    for text in expected:
        assert text in err, (text, err)


@pytest.mark.parametrize("case", ["v7.3 file", "matrix", "empty file", "corrupted compressed stream"])
def test_bad_mat_input_exits_2_on_the_command_line(tmp_path, case):
    _, content, extra, expected = next(b for b in BAD if b[0] == case)
    _write(tmp_path, content, extra)
    r = run_cli("identify", tmp_path, "--method", "base")
    assert r.returncode == 2, (r.stdout, r.stderr)
    err = r.stderr.strip()
    assert "Traceback" not in err and len(err.splitlines()) == 1 and err.startswith("thermofriction: error:"), err
    for text in expected:
        assert text in err, (text, err)


def test_struct_and_units_keys_refused_for_csv_files(csv_folder, tmp_path):
    text = (csv_folder / "dataset.toml").read_text().replace('role = "fit"', 'role = "fit"\nstruct = "run1"', 1)
    for f in csv_folder.iterdir():
        (tmp_path / f.name).write_bytes(f.read_bytes())
    (tmp_path / "dataset.toml").write_text(text)
    with pytest.raises(tf.InputError, match=r"\[\[experiment\]\] 1: 'struct' applies to MATLAB files"):
        tf.load_dataset(tmp_path)


def test_identify_and_validate_results_round_trip_through_mat_files(csv_folder, tmp_path):
    """identify --json r.mat and validate --json m.mat (real CLI runs), loaded back with scipy.io:
    every fitted parameter's name, value, error and unit, and every experiment's RMSE, equal the JSON
    written by the same run to the last bit (numbers) and character (text)."""
    import json
    out = run_cli("identify", csv_folder, "--method", "base", "--starts", "1", "--json", tmp_path / "r.json")
    assert out.returncode == 0, out.stderr
    out = run_cli("identify", csv_folder, "--method", "base", "--starts", "1", "--json", tmp_path / "r.mat")
    assert out.returncode == 0, out.stderr
    ref = json.loads((tmp_path / "r.json").read_text())
    mat = scipy.io.loadmat(tmp_path / "r.mat", simplify_cells=True)
    params = mat["parameters"]
    assert list(params["name"]) == list(ref["parameters"])
    for k, name in enumerate(params["name"]):
        assert params["value"][k] == ref["parameters"][name]["value"]
        assert params["unit"][k] == ref["parameters"][name]["unit"]
    exps = mat["experiments"]
    assert list(np.atleast_1d(exps["file"])) == [e["file"] for e in ref["experiments"]]
    np.testing.assert_array_equal(np.atleast_1d(exps["rmse_offset_removed"]),
                                  [e["rmse_offset_removed"] for e in ref["experiments"]])
    assert mat["fit_quality"]["ratio"] == ref["fit_quality"]["ratio"]
    assert mat["method"] == ref["method"]
    assert np.shape(mat["correlation"]["matrix"]) == (len(params["name"]),) * 2

    assert run_cli("validate", "li2009-base", csv_folder, "--json", tmp_path / "m.mat").returncode in (0, 1)
    assert run_cli("validate", "li2009-base", csv_folder, "--json", tmp_path / "m.json").returncode in (0, 1)
    vm = scipy.io.loadmat(tmp_path / "m.mat", simplify_cells=True)
    vj = json.loads((tmp_path / "m.json").read_text())
    np.testing.assert_array_equal(np.atleast_1d(vm["experiments"]["max_error_pct"]),
                                  [e["max_error_pct"] for e in vj["experiments"]])


def test_results_to_mat_turns_json_shapes_into_matlab_shapes():
    """Independent of any fit: the documented mapping on a hand-made document."""
    from thermofriction.data.matlab_results import results_to_mat
    m = results_to_mat({"a.b": {"value": 1.0, "unit": "N"}, "c": {"value": "nan", "unit": ""}})
    assert list(m["name"]) == ["a.b", "c"] and np.isnan(m["value"][1]) and m["value"][0] == 1.0
    t = results_to_mat([{"file": "x.csv", "T": 30.0}, {"file": "y.csv", "T": "inf"}])
    assert list(t["file"]) == ["x.csv", "y.csv"] and np.isinf(t["T"][1])
    assert results_to_mat([[1, 0.5], [0.5, 1]]).shape == (2, 2)
    assert results_to_mat(None).size == 0
