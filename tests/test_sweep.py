"""Design sweeps (tf.sweep, `thermofriction sweep`): the grid, the metrics against analytic results
and against tf.simulate run point by point (an independent path through the library), failures
per point, the table's files, Ctrl-C. The runs on a real multi-process Dask cluster are in
test_dask_cluster.py, those on the default's threads in test_scale.py; here most runs are sequential (the
baseline), some use the local Dask cluster (--scheduler processes)."""

from __future__ import annotations

import dataclasses
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import thermofriction as tf
from child_signals import default_signals
from thermofriction.errors import InputError
from thermofriction.scale.sweep import parse_axis


def run(*args, cwd, timeout=240):
    return subprocess.run([sys.executable, "-m", "thermofriction", *map(str, args)], cwd=cwd, capture_output=True,
                          text=True, timeout=timeout)


# -- the grid ---------------------------------------------------------------------------------

def test_axis_range_includes_its_stop_and_lists_keep_their_order():
    name, v = parse_axis("temperature=30:42:0.25")
    assert name == "temperature" and v.size == 49 and v[0] == 30 and v[-1] == 42
    assert np.allclose(np.diff(v), 0.25, rtol=1e-12)
    assert parse_axis("temperature=30:31:0.3")[1].tolist() == pytest.approx([30, 30.3, 30.6, 30.9])
    assert parse_axis(" amplitude = 30,10,20")[1].tolist() == [30, 10, 20]
    assert parse_axis("sigma0.b=-0.05")[1].tolist() == [-0.05]


@pytest.mark.parametrize("spec, words", [
    ("temperature", "NAME=START:STOP:STEP"), ("=1,2", "NAME="), ("t=1:2", "START:STOP:STEP"),
    ("t=2:1:0.1", "START <= STOP"), ("t=1:2:0", "positive STEP"), ("t=1,x", "not a number: 'x'"),
    ("t=1,nan", "finite"), ("t=1_0", "not a number"), ("t=0:1e12:1e-3", "limit")])
def test_bad_axes_are_one_message(spec, words):
    with pytest.raises(InputError) as e:
        parse_axis(spec)
    assert words in str(e.value)


def test_points_are_the_product_with_the_last_axis_fastest():
    res = tf.sweep(tf.load_model("li2009-model-i"), {"temperature": [31.0, 35.0], "amplitude": [10.0, 20.0, 30.0]},
                   duration=0.2, sample_rate=1000, scheduler="sequential")
    assert res["temperature"].tolist() == [31, 31, 31, 35, 35, 35]
    assert res["amplitude"].tolist() == [10, 20, 30] * 2
    rec = res.to_records()
    assert rec.dtype.names == ("temperature", "amplitude", "mean_step", "final_displacement", "peak_friction_force",
                               "error")


def test_unknown_names_and_metrics_are_refused_before_any_work():
    m = tf.load_model("li2009-model-i")
    with pytest.raises(InputError, match=r"grid 'sigma0': it follows a law .* coefficients \(sigma0.a, sigma0.b\)"):
        tf.sweep(m, {"sigma0": [1e6]}, temperature=35, scheduler="sequential")
    with pytest.raises(InputError, match="grid 'bogus'"):
        tf.sweep(m, {"bogus": [1]}, temperature=35, scheduler="sequential")
    with pytest.raises(InputError, match="unknown metric 'speed'"):
        tf.sweep(m, {"temperature": [35]}, metrics=["speed"], scheduler="sequential")
    with pytest.raises(InputError, match="depends on temperature"):
        tf.sweep(m, {"amplitude": [10]}, scheduler="sequential")
    with pytest.raises(InputError, match="scheduler must be"):
        tf.sweep(m, {"temperature": [35]}, scheduler=3)


# -- the metrics ------------------------------------------------------------------------------

def test_prescribed_coulomb_metrics_equal_the_analytic_values():
    """Prescribed motion x(t) = A sin(2 pi f t) under Coulomb friction: the peak friction force is
    fc and the final displacement A sin(2 pi f T), for every point of an fc x amplitude grid."""
    model = tf.Model(tf.PrescribedMotion(), tf.Coulomb(fc=1.0), input=tf.Sine(amplitude=1e-5, frequency=1.0))
    fc, amp = [0.3, 1.7, 4.1], [2e-6, 3.3e-5]
    res = tf.sweep(model, {"fc": fc, "amplitude": amp}, duration=0.9, sample_rate=1000,
                   metrics=["peak_friction_force", "final_displacement", "displacement_range"], scheduler="sequential")
    assert res.failed == 0
    np.testing.assert_allclose(res["peak_friction_force"], res["fc"], rtol=1e-9)
    expected = res["amplitude"] * np.sin(2 * np.pi * 0.9)
    np.testing.assert_allclose(res["final_displacement"], expected, rtol=1e-6, atol=1e-6 * max(amp))
    np.testing.assert_allclose(res["displacement_range"], 2 * res["amplitude"], rtol=1e-6)
    assert res.units["fc"] == "N" and res.units["amplitude"] == "m" and res.header("final_displacement") == "final_displacement[m]"


def test_metrics_equal_simulate_point_by_point_for_parameters_away_from_the_presets():
    base = tf.load_model("li2009-base")
    grid = {"sigma0": [7.3e5, 3.1e6], "frequency": [3.0, 11.0], "rise": [0.9, 0.999]}
    res = tf.sweep(base, grid, duration=0.5, sample_rate=2000, metrics=list(tf.scale.METRICS),
                   scheduler="sequential", batch_size=3)
    assert len(res) == 8 and res.failed == 0
    for i in range(len(res)):
        m = dataclasses.replace(base, friction=dataclasses.replace(base.friction, sigma0=res["sigma0"][i]))
        w = dataclasses.replace(base.input, frequency=res["frequency"][i], rise=res["rise"][i])
        r = tf.simulate(m, 0.5, input=w, sample_rate=2000)
        assert res["mean_step"][i] == r.step_sizes.mean()
        assert res["last_step"][i] == r.step_sizes[-1]
        assert res["mean_velocity"][i] == r.mean_velocity
        assert res["final_displacement"][i] == r.displacement[-1]
        assert res["displacement_range"][i] == np.ptp(r.displacement)
        assert res["peak_friction_force"][i] == np.max(np.abs(r.friction_force))


def test_result_does_not_depend_on_the_batching():
    m = tf.load_model("li2009-model-i")
    grid = {"temperature": np.arange(30.0, 41.6, 1.5), "amplitude": [12.0, 27.0]}
    runs = [tf.sweep(m, grid, duration=0.3, sample_rate=1000, scheduler="sequential", batch_size=b)
            for b in (1, 5, 1000)]
    for r in runs[1:]:
        for name in r.columns:
            np.testing.assert_array_equal(r[name], runs[0][name])


def test_a_failing_point_is_recorded_and_the_rest_go_on(tmp_path):
    base = tf.load_model("li2009-base")
    res = tf.sweep(base, {"fc": [0.8, -1.0, 1.1]}, duration=0.3, sample_rate=1000, scheduler="sequential")
    assert res.failed == 1 and list(res.errors) == [1] and "fc" in res.errors[1]
    assert res.ok.tolist() == [True, False, True]
    assert np.isnan(res["mean_step"][1]) and np.all(np.isfinite(res["mean_step"][[0, 2]]))
    res.to_csv(tmp_path / "s.csv")
    lines = (tmp_path / "s.csv").read_text().splitlines()
    assert lines[0] == "fc[N],mean_step[m],final_displacement[m],peak_friction_force[N],error"
    assert lines[2].startswith("-1.0,nan,nan,nan,") and "fc" in lines[2]
    back = np.genfromtxt(tmp_path / "s.csv", delimiter=",", skip_header=1, usecols=(0, 1, 2, 3))
    np.testing.assert_array_equal(back[[0, 2]], np.column_stack([res[n] for n in ("fc", "mean_step",
                                                                                  "final_displacement",
                                                                                  "peak_friction_force")])[[0, 2]])


# -- the command line -------------------------------------------------------------------------

def test_cli_sweep_on_the_local_cluster_equals_the_sequential_run(tmp_path):
    grid = ["--grid", "temperature=30:41:1", "--grid", "amplitude=10,30"]
    seq = run("sweep", "li2009-model-i", *grid, "--duration", "0.3", "--sample-rate", "1000", "--scheduler",
              "sequential", "-o", "seq.csv", cwd=tmp_path)
    assert seq.returncode == 0, seq.stderr
    loc = run("sweep", "li2009-model-i", *grid, "--duration", "0.3", "--sample-rate", "1000", "--scheduler",
              "processes", "--workers", "2", "-o", "local.csv", cwd=tmp_path)
    assert loc.returncode == 0, loc.stderr
    assert "a local Dask cluster (2 workers)" in loc.stdout and "24 points (0 failed)" in loc.stdout
    assert (tmp_path / "local.csv").read_text() == (tmp_path / "seq.csv").read_text()


def test_cli_table_on_standard_output(tmp_path, monkeypatch, capsys):
    from thermofriction.cli import main
    monkeypatch.chdir(tmp_path)
    assert main(["sweep", "li2009-base", "--grid", "fc=0.7,0.9", "--duration", "0.2", "--scheduler", "sequential",
                 "-o", "-"]) == 0
    out, err = capsys.readouterr()
    lines = out.splitlines()
    assert lines[0].startswith("fc[N],mean_step[m],") and len(lines) == 3 and "2 points (0 failed)" in err
    assert os.listdir(tmp_path) == []


def test_cli_failed_points_exit_1_and_are_named(tmp_path):
    r = run("sweep", "li2009-base", "--grid", "fc=0.8,-1,1.1", "--duration", "0.3", "--scheduler", "sequential",
            "-o", "s.csv", cwd=tmp_path)
    assert r.returncode == 1 and "Traceback" not in r.stderr
    assert "point 1 (fc = -1) failed:" in r.stderr and "3 points (1 failed)" in r.stdout
    assert (tmp_path / "s.csv").exists()


@pytest.mark.parametrize("args, words", [
    (["--grid", "bogus=1"], "grid 'bogus'"),
    (["--grid", "temperature=30:42"], "START:STOP:STEP"),
    (["--grid", "temperature=35", "--metrics", "speed"], "unknown metric 'speed'"),
    (["--grid", "amplitude=10"], "depends on temperature"),
    (["--grid", "temperature=35", "--scheduler", "sequential", "--rtol", "2"], "--rtol must be below 1")])
def test_cli_bad_sweeps_exit_2_and_write_nothing(tmp_path, monkeypatch, capsys, args, words):
    from thermofriction.cli import main
    monkeypatch.chdir(tmp_path)
    status = main(["sweep", "li2009-model-i", *args, "--scheduler", "sequential", "-o", "s.csv"])
    err = capsys.readouterr().err
    assert status == 2 and words in err and "Traceback" not in err
    assert os.listdir(tmp_path) == []


def test_cli_parquet_needs_pyarrow_or_writes_it(tmp_path):
    args = ["sweep", "li2009-model-i", "--grid", "temperature=31,35", "--duration", "0.2", "--scheduler",
            "sequential", "-o", "s.parquet"]
    try:
        import pyarrow.parquet as pq
    except ImportError:
        r = run(*args, cwd=tmp_path)
        assert r.returncode == 2 and "needs pyarrow" in r.stderr and os.listdir(tmp_path) == []
        return
    r = run(*args, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    table = pq.read_table(tmp_path / "s.parquet")
    assert table.column_names[:2] == ["temperature[C]", "mean_step[m]"] and table.num_rows == 2


def test_ctrl_c_stops_the_local_cluster_and_writes_nothing(tmp_path):
    """SIGINT while the local cluster works: exit 130, no table, no temporary file, no worker left."""
    psutil = pytest.importorskip("psutil")
    proc = subprocess.Popen([sys.executable, "-m", "thermofriction", "sweep", "li2009-model-i", "--grid",
                             "temperature=30:41.5:0.01", "--duration", "2", "--scheduler", "processes", "--workers",
                             "1", "--batch-size", "5",
                             "-o", "s.csv"], cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=default_signals)
    try:
        deadline, workers = time.monotonic() + 120, []
        parent = psutil.Process(proc.pid)
        while time.monotonic() < deadline and proc.poll() is None:  # the worker runs once it has used CPU
            workers = [c for c in parent.children(recursive=True) if c.cpu_times().user > 1.0]
            if workers:
                break
            time.sleep(0.2)
        assert workers, "the local cluster's worker never started"
        time.sleep(1.0)
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    assert "interrupted; no output was written" in err and "Traceback" not in err
    assert os.listdir(tmp_path) == []
    gone, alive = psutil.wait_procs(workers, timeout=30)
    assert not alive


def _exit_on_one(i):
    if i == 1:
        os._exit(3)  # a crash of the worker process, every time it runs this task
    return 2 * i


def test_a_task_that_kills_its_workers_is_recorded_and_the_rest_go_on():
    import dask

    from thermofriction.scale.cluster import Runner
    # Dask retries a task whose worker died on other workers, by default up to 3 times: once here
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}), Runner("processes", workers=2) as runner:
        out = runner.map(_exit_on_one, [(i,) for i in range(6)], on_error=lambda i, why: ("lost", why))
    assert out[1] == ("lost", "its worker died each time it ran (a crash or out of memory?)")
    # Dask also gives up on a task that shared a dying worker with it too often; all others ran
    assert sum(o == 2 * i for i, o in enumerate(out)) >= 3 and all(o == 2 * i or o[0] == "lost"
                                                                    for i, o in enumerate(out))


def test_import_does_not_load_dask():
    code = ("import sys, thermofriction as tf; tf.sweep; tf.identify_fleet; tf.propagate; "
            "print(any(m.split('.')[0] in ('dask', 'distributed') for m in sys.modules))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.stdout.strip() == "False", r.stderr
