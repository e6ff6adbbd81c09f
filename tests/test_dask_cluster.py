"""Scale-out on a real Dask cluster: a `dask scheduler` and two `dask worker` processes on
127.0.0.1, started and stopped by these tests (bounded in time). A sweep and a fleet identification
run through ``--scheduler``; one worker is killed while it holds a task; every row must still be
there and equal, to the last bit, to a sequential run in this process (the independent reference:
no Dask at all)."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf
from child_signals import default_signals

distributed = pytest.importorskip("distributed")

START_TIMEOUT = 90.0   # s: a scheduler and its workers on a busy 2-core machine
RUN_TIMEOUT = 240.0    # s: one command line run


def _dask_command():
    exe = Path(sys.executable).parent / "dask"
    if exe.exists():
        return [str(exe)]
    found = shutil.which("dask")
    if found is None:
        pytest.skip("the 'dask' command is not installed")
    return [found]


class Cluster:
    """A scheduler and named workers in their own process groups; ``kill(name)`` SIGKILLs one."""

    def __init__(self, folder: Path):
        self.folder = folder
        self.procs = {}
        self.logs = []
        self.address = None

    def _spawn(self, name, args):
        log = open(self.folder / f"{name}.log", "w")
        self.logs.append(log)
        self.procs[name] = subprocess.Popen(_dask_command() + args, stdout=log, stderr=subprocess.STDOUT,
                                            start_new_session=True, cwd=self.folder,
                                            preexec_fn=default_signals)

    def start(self, n_workers=2):
        file = self.folder / "scheduler.json"
        self._spawn("scheduler", ["scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                                  "--scheduler-file", str(file)])
        deadline = time.monotonic() + START_TIMEOUT
        while not file.exists() or not file.read_text().strip():
            if time.monotonic() > deadline or self.procs["scheduler"].poll() is not None:
                raise RuntimeError("the scheduler did not start: " + (self.folder / "scheduler.log").read_text())
            time.sleep(0.1)
        time.sleep(0.2)  # the file is written whole, but give its writer a moment
        self.address = json.loads(file.read_text())["address"]
        for i in range(n_workers):
            self.add_worker(f"w{i}", wait=False)
        self.wait_for(n_workers)
        return self

    def add_worker(self, name, wait=True):
        # no nanny: the worker is the process itself, so that killing it loses its tasks for real
        self._spawn(name, ["worker", self.address, "--nthreads", "1", "--no-nanny", "--no-dashboard",
                           "--host", "127.0.0.1", "--name", name, "--death-timeout", "60"])
        if wait:
            self.wait_for(sum(1 for n, p in self.procs.items() if n != "scheduler" and p.poll() is None))

    def wait_for(self, n):
        with distributed.Client(self.address, timeout=START_TIMEOUT) as c:
            c.wait_for_workers(n, timeout=START_TIMEOUT)

    def kill(self, name):
        os.killpg(self.procs[name].pid, signal.SIGKILL)
        self.procs[name].wait(timeout=30)

    def stop(self):
        for name, p in self.procs.items():
            if p.poll() is None:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(p.pid, signal.SIGTERM)
        for p in self.procs.values():
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(p.pid, signal.SIGKILL)
                p.wait(timeout=20)
        for log in self.logs:
            log.close()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    c = Cluster(tmp_path_factory.mktemp("dask-cluster"))
    try:
        yield c.start(2)
    finally:
        c.stop()


def _cli(*args, cwd):
    return subprocess.Popen([sys.executable, "-m", "thermofriction", *map(str, args)], cwd=cwd,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _run_killing(cluster, args, cwd, victim):
    """Runs the command line and SIGKILLs worker ``victim`` as soon as it holds one of our tasks;
    returns (the finished process's (status, stdout, stderr), the keys the victim held)."""
    with distributed.Client(cluster.address, timeout=START_TIMEOUT) as watcher:
        addresses = {info["name"]: addr for addr, info in watcher.scheduler_info(n_workers=-1)["workers"].items()}
        proc = _cli(*args, cwd=cwd)
        held, deadline = [], time.monotonic() + RUN_TIMEOUT
        try:
            while not held and proc.poll() is None and time.monotonic() < deadline:
                held = [k for k in watcher.processing().get(addresses[victim], ()) if "thermofriction-" in str(k)]
                if not held:
                    time.sleep(0.005)
            running_at_kill = proc.poll() is None
            if held:
                cluster.kill(victim)
            out, err = proc.communicate(timeout=RUN_TIMEOUT)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
    assert held and running_at_kill, f"worker {victim} never held a task while the run went on: {err}"
    return (proc.returncode, out, err), held


def test_sweep_through_scheduler_survives_a_killed_worker_and_equals_the_sequential_run(cluster, tmp_path):
    grid = ["--grid", "temperature=30:41.5:0.5", "--grid", "amplitude=10,20,30"]
    common = ["sweep", "li2009-model-i", *grid, "--duration", "1", "--sample-rate", "1000"]
    ref = subprocess.run([sys.executable, "-m", "thermofriction", *common, "--scheduler", "sequential",
                          "-o", "seq.csv", "-q"], cwd=tmp_path, capture_output=True, text=True, timeout=RUN_TIMEOUT)
    assert ref.returncode == 0, ref.stderr
    (status, out, err), held = _run_killing(
        cluster, [*common, "--scheduler", cluster.address, "--batch-size", "3", "-o", "dask.csv"], tmp_path, "w0")
    assert status == 0, err
    assert f"Dask scheduler {cluster.address}" in out
    seq = (tmp_path / "seq.csv").read_text().splitlines()
    got = (tmp_path / "dask.csv").read_text().splitlines()
    assert len(got) == 1 + 24 * 3  # the header and every point
    assert got == seq  # every row, in order, equal to the last digit
    cluster.add_worker("w2")  # two workers again for the next test


def _unit(folder, name, fc_factor, seed):
    """A small actuator dataset from a LuGre truth away from the presets (fc, sigma0 scaled)."""
    base = tf.load_model("li2009-base")
    fr = base.friction
    import dataclasses
    truth = dataclasses.replace(base, friction=dataclasses.replace(fr, fc=fr.fc * fc_factor,
                                                                   sigma0=fr.sigma0 * (0.9 + 0.02 * seed)))
    data = tf.synthesize(truth, [35.0], duration=0.4, sample_rate=2000, noise=20e-9, seed=seed)
    tf.save_dataset(data, folder / name)
    return folder / name


def test_fleet_identification_through_scheduler_survives_a_killed_worker(cluster, tmp_path):
    fleet = tmp_path / "fleet"
    fleet.mkdir()
    for i, f in enumerate((0.8, 0.82, 0.78, 0.81, 1.3)):
        _unit(fleet, f"unit-{i}", f, i)
    (fleet / "unit-broken").mkdir()
    (fleet / "unit-broken" / "dataset.toml").write_text("[[experiment]]\nfile = 'missing.csv'\n")
    opts = ["--method", "base", "--starts", "2"]
    ref = subprocess.run([sys.executable, "-m", "thermofriction", "identify", "fleet", *opts, "--scheduler",
                          "sequential", "-o", "seq", "-q"], cwd=tmp_path, capture_output=True, text=True,
                         timeout=RUN_TIMEOUT)
    assert ref.returncode == 1 and "unit-broken: not identified" in ref.stderr
    (status, out, err), held = _run_killing(
        cluster, ["identify", "fleet", *opts, "--scheduler", cluster.address, "-o", "dask"], tmp_path, "w1")
    assert status == 1, err  # the broken dataset; the others identified
    assert "unit-broken: not identified" in err and "missing.csv" in err
    seq, got = tmp_path / "seq", tmp_path / "dask"
    assert (got / "fleet.csv").read_text() == (seq / "fleet.csv").read_text()
    def undated(path):  # the [provenance] date is when each fit ran; everything else must be equal
        return [line for line in path.read_text().splitlines() if not line.startswith("date = ")]
    for i in range(5):
        assert undated(got / f"unit-{i}.toml") == undated(seq / f"unit-{i}.toml")
    assert not (got / "unit-broken.toml").exists()
    summary = json.loads((got / "fleet.json").read_text())
    assert summary["identified"] == 5 and [f["dataset"] for f in summary["failures"]] == ["unit-broken"]
    # the actuator made with 1.3/0.8 x the others' Coulomb level is the one named
    assert [o["dataset"] for o in summary["parameters"]["fc"]["outliers"]] == ["unit-4"]
    assert "outlier: unit-4: fc" in out  # (w2 goes on alone for the next test)


def test_scheduler_that_does_not_answer_is_one_message(tmp_path):
    r = subprocess.run([sys.executable, "-m", "thermofriction", "sweep", "li2009-model-i", "--grid", "temperature=35",
                        "--duration", "0.2", "--scheduler", "tcp://127.0.0.1:9", "-o", "x.csv"], cwd=tmp_path,
                       capture_output=True, text=True, timeout=RUN_TIMEOUT, env=dict(os.environ,
                                                                                    DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT="2s"))
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert "tcp://127.0.0.1:9: cannot connect" in r.stderr
    assert not (tmp_path / "x.csv").exists()


def test_python_client_is_used_and_left_open(cluster):
    with distributed.Client(cluster.address, timeout=START_TIMEOUT) as client:
        grid = {"temperature": [31.0, 36.0, 41.0], "amplitude": [15.0, 25.0]}
        model = tf.load_model("li2009-model-i")
        got = tf.sweep(model, grid, duration=0.4, sample_rate=1000, scheduler=client, batch_size=2)
        ref = tf.sweep(model, grid, duration=0.4, sample_rate=1000, scheduler="sequential")
        assert client.status == "running"
        for name in got.columns:
            np.testing.assert_array_equal(got[name], ref[name])
