"""The embedded default of the scale-out workloads (scale/cluster.py): chunks of work on threads in this
process. Each workload on 2 threads equals its sequential run to the last bit (the sequential run is the
reference: every item is computed on its own from the same arguments, so where it ran must not show);
the chunks cover the items in order, are sized from the items' time, and leave the warnings module as
it was; Ctrl-C stops the threads and writes nothing."""

from __future__ import annotations

import dataclasses
import math
import os
import signal
import subprocess
import sys
import threading
import time
import warnings

import numpy as np
import pytest

import thermofriction as tf
from child_signals import default_signals
from thermofriction.errors import InputError
from thermofriction.scale.chunks import CHUNK_MAX_SECONDS, CHUNK_SECONDS, chunk_spans
from thermofriction.scale.cluster import Runner, recorded_warnings


def _same_sweep(a, b):
    assert a.coordinates == b.coordinates and a.metrics == b.metrics
    for name in a.columns:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)  # NaN == NaN here; exact otherwise
    assert a.errors == b.errors and a.warnings == b.warnings


def test_sweep_on_threads_equals_the_sequential_run_bit_for_bit():
    """Points outside the laws' calibrated range (warnings) and a law coefficient away from the preset's:
    values, errors and warnings as in sequential mode; then points that fail (fc < 0), each on its own."""
    base = tf.load_model("li2009-model-i")
    grid = {"temperature": np.arange(27.0, 45.01, 1.0), "amplitude": [12.0, 31.0], "sigma0.b": [-0.136, -0.12]}
    ref = tf.sweep(base, grid, duration=0.25, sample_rate=2000, scheduler="sequential")
    assert ref.warnings and len(ref) == 19 * 2 * 2
    got = tf.sweep(base, grid, duration=0.25, sample_rate=2000, workers=2)
    assert got.where == "2 threads in this process"
    _same_sweep(ref, got)
    small = tf.sweep(base, grid, duration=0.25, sample_rate=2000, workers=2, batch_size=3)  # many chunks
    _same_sweep(ref, small)
    failing = tf.sweep(tf.load_model("li2009-base"), {"fc": [0.8, -1.0, 1.1, -2.0, 0.9]}, duration=0.2,
                       sample_rate=1000, workers=2, batch_size=1)
    assert list(failing.errors) == [1, 3] and failing.ok.tolist() == [True, False, True, False, True]


def test_propagation_on_threads_equals_the_sequential_run_bit_for_bit():
    base = tf.load_model("li2009-base")
    params = tf.Parameters()
    for name, rel in (("fc", 0.02), ("sigma0", 0.05)):
        value = getattr(base.friction, name)
        params.add(name, value, min=0.0)
        params[name].stderr = rel * value
    fit = tf.FitResult(method="base", model=base, parameters=params, correlation=np.array([[1.0, 0.3], [0.3, 1.0]]),
                       cost=0.0, rmse=0.0, n_points=1, nfev=0, njev=0, starts=1, wall_time=0.0, success=True,
                       message="")
    kw = dict(temperatures=[33.0, 38.0], draws=40, seed=3, duration=0.3, sample_rate=1000)
    ref = tf.propagate(fit, scheduler="sequential", **kw)
    got = tf.propagate(fit, workers=2, **kw)
    assert got.where == "2 threads in this process"
    for name in ("nominal", "median", "lower", "upper", "prediction_lower", "prediction_upper", "steps",
                 "final_displacement", "parameters", "step_lower", "step_upper"):
        np.testing.assert_array_equal(getattr(ref, name), getattr(got, name), err_msg=name)
    assert ref.failures == got.failures


def test_fleet_on_threads_equals_the_sequential_run_bit_for_bit():
    base = tf.load_model("li2009-base")
    fr = base.friction
    data = [tf.synthesize(dataclasses.replace(base, friction=dataclasses.replace(fr, fc=fr.fc * f)), [35.0],
                          duration=0.3, sample_rate=2000, noise=20e-9, seed=k) for k, f in enumerate((0.8, 0.9, 1.1))]
    ref = tf.identify_fleet(data, "base", scheduler="sequential", starts=1, parameters=["fc"])
    got = tf.identify_fleet(data, "base", workers=2, starts=1, parameters=["fc"])
    assert got.where == "2 threads in this process" and ref.names == got.names and not got.failures
    for name in ref.names:
        assert got.fits[name].parameters["fc"].value == ref.fits[name].parameters["fc"].value
        assert got.fits[name].rmse == ref.fits[name].rmse


@pytest.mark.parametrize("n, workers, seconds, kind", [
    (3603, 2, 2e-3, "threads"), (3603, 2, 2e-3, "dask"), (1000, 4, 0.5, "dask"), (7, 2, 1e-4, "threads"),
    (10**6, 2, 2e-3, "threads"), (5000, 2, None, "threads")])
def test_chunks_cover_the_items_in_order_and_are_sized_from_their_time(n, workers, seconds, kind):
    """The rules of chunk_spans, checked on what it returns: consecutive spans covering range(n); none below
    CHUNK_SECONDS of work unless too few items remain or per-worker shares need fewer; none above
    CHUNK_MAX_SECONDS; not increasing; and every worker gets several chunks when there is work for them."""
    spans = chunk_spans(n, workers, seconds, kind=kind)
    assert spans[0][0] == 0 and spans[-1][1] == n and all(b == c for (_, b), (c, _) in zip(spans, spans[1:]))
    sizes = [b - a for a, b in spans]
    assert all(s >= 1 for s in sizes) and all(x >= y for x, y in zip(sizes, sizes[1:-1]))
    if seconds is not None:
        smallest = math.ceil(CHUNK_SECONDS[kind] / seconds)
        assert all(s >= min(smallest, n) for s in sizes[:-1])
        assert max(sizes) <= max(smallest, CHUNK_MAX_SECONDS[kind] / seconds)
        if n * seconds >= 4 * workers * CHUNK_SECONDS[kind]:  # work enough for 4 chunks per worker
            assert len(spans) >= 4 * workers
    assert chunk_spans(n, workers, seconds, kind=kind, batch_size=7) == [(a, min(a + 7, n)) for a in range(0, n, 7)]
    assert max(b - a for a, b in chunk_spans(n, workers, seconds, kind=kind, largest=5)) <= 5


def test_the_first_items_time_the_chunks_and_none_runs_twice():
    """map_chunks times the first items here (chunks of 1, 2, 4, ...) and sizes the rest from them: every item
    runs once, in chunks that cover range(n) in order, and the results come back in item order."""
    calls = []

    def work(a, b):
        calls.append((a, b))
        time.sleep(1e-3 * (b - a))  # 1 ms per item: releases the GIL as the C core does
        return list(range(a, b))

    with Runner(workers=2) as runner:
        spans, outs = runner.map_chunks(work, 400, lambda a, b: (a, b))
    assert sorted(calls) == spans and [i for out in outs for i in out] == list(range(400))
    assert spans[:2] == [(0, 1), (1, 3)]  # the timed ones, here
    assert len(spans) >= 8 and max(b - a for a, b in spans) <= 400 // 8 + 1


def test_the_warnings_module_is_left_as_it_was_and_other_warnings_are_shown():
    before = (list(warnings.filters), warnings.showwarning)

    def task(i):
        with recorded_warnings() as caught:
            warnings.warn(f"recorded {i}", UserWarning)
        warnings.warn(f"shown {i}", RuntimeWarning)  # not recorded: shown as in sequential mode
        return [str(w.message) for w in caught]

    with pytest.warns(RuntimeWarning, match="shown") as shown, Runner(workers=2) as runner:
        out = runner.map(task, [(i,) for i in range(6)], records_warnings=True)
    assert out == [[f"recorded {i}"] for i in range(6)]
    assert sorted(str(w.message) for w in shown if w.category is RuntimeWarning) == [f"shown {i}" for i in range(6)]
    assert (list(warnings.filters), warnings.showwarning) == before


def test_two_threads_inside_their_blocks_at_once_record_their_own_warnings():
    """Both tasks are inside recorded_warnings when both warn (a barrier): each gets its own warning. With
    warnings.catch_warnings in each thread instead, both would land in the list of the block entered last."""
    barrier = threading.Barrier(2)

    def task(i):
        with recorded_warnings() as caught:
            barrier.wait(timeout=30)
            warnings.warn(f"task {i}", UserWarning)
            barrier.wait(timeout=30)
        return [str(w.message) for w in caught]

    before = (list(warnings.filters), warnings.showwarning)
    with Runner(workers=2) as runner:
        out = runner.map(task, [(0,), (1,)], records_warnings=True)
    assert out == [["task 0"], ["task 1"]]
    assert (list(warnings.filters), warnings.showwarning) == before


def test_recorded_blocks_nest_and_validations_side_by_side_keep_their_own_warnings(monkeypatch):
    """Two validations on a Runner's threads, both inside their experiment's prediction at once (a barrier), each
    at a temperature outside the laws' range: each result names its own temperature only, as a sequential run
    does. Before, validation recorded with warnings.catch_warnings (global state): a fleet's held-out lists could
    swap or lose warnings. The simulation's own check records in a block nested in validation's and passes its
    warnings on to it."""
    import thermofriction.validation as V

    model = tf.load_model("li2009-model-i")
    datasets = [tf.synthesize(model, [T], duration=0.05, sample_rate=2000.0, noise=0.0, seed=1) for T in (27.0, 29.0)]
    barrier = threading.Barrier(2)
    original = V.measurement_of

    def measurement_of(exps, **kw):
        measurement = original(exps, **kw)
        predict = measurement.predict

        def predicted(*args, **kwargs):
            barrier.wait(timeout=30)
            return predict(*args, **kwargs)

        object.__setattr__(measurement, "predict", predicted)
        return measurement

    monkeypatch.setattr(V, "measurement_of", measurement_of)
    with Runner(workers=2) as runner:
        out = runner.map(lambda d: tf.validate(model, d).warnings, [(d,) for d in datasets], records_warnings=True)
    for T, caught in zip((27, 29), out):
        assert any(f"temperature {T} C is outside" in w for w in caught), caught
        assert not any(f"temperature {56 - T} C" in w for w in caught), caught


def test_a_task_that_raises_stops_the_run_as_in_sequential_mode():
    def task(i):
        if i == 3:
            raise ValueError("task 3")
        return i

    for scheduler in ("sequential", "threads"):
        with pytest.raises(ValueError, match="task 3"), Runner(scheduler, workers=2) as runner:
            runner.map(task, [(i,) for i in range(8)])


@pytest.mark.parametrize("kw, words", [
    (dict(scheduler=3), "scheduler must be"), (dict(workers=0), "workers must be"),
    (dict(workers=2.0), "workers must be"), (dict(batch_size=True), "batch_size must be"),
    (dict(progress=5), "progress must be"), (dict(solver=5), "solver must be"),
    (dict(controller="tight"), "controller must be")])
def test_sweep_and_propagate_check_their_options_alike_before_any_work(kw, words):
    with pytest.raises(InputError, match=words):
        tf.sweep("li2009-model-i", {"temperature": [35.0]}, duration=0.05, **kw)
    fit = tf.FitResult(method="base", model=tf.load_model("li2009-base"), parameters=tf.Parameters(),
                       correlation=np.eye(1), cost=0.0, rmse=0.0, n_points=1, nfev=0, njev=0, starts=1,
                       wall_time=0.0, success=True, message="")
    with pytest.raises(InputError, match=words):
        tf.propagate(fit, [35.0], **kw)
    if "scheduler" in kw or "workers" in kw or "progress" in kw:
        with pytest.raises(InputError, match=words):
            tf.identify_fleet(["no-such-dataset"], "base", **kw)


def test_ctrl_c_stops_the_threads_and_writes_nothing(tmp_path):
    """SIGINT while the default's threads work: exit 130 within seconds (the running chunks end, the others
    are dropped), no table, no temporary file."""
    psutil = pytest.importorskip("psutil")
    proc = subprocess.Popen([sys.executable, "-m", "thermofriction", "sweep", "li2009-model-i", "--grid",
                             "temperature=30:41.5:0.002", "--duration", "2", "--workers", "2", "-o", "s.csv"],
                            cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=default_signals)
    try:
        me, deadline = psutil.Process(proc.pid), time.monotonic() + 120
        while time.monotonic() < deadline and proc.poll() is None and me.cpu_times().user < 2.0:
            time.sleep(0.1)  # imports (~1 s of CPU), then the sweep's first chunks
        assert proc.poll() is None, proc.communicate()
        t0 = time.monotonic()
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
        stopped = time.monotonic() - t0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    assert "interrupted; no output was written" in err and "Traceback" not in err
    assert os.listdir(tmp_path) == [] and stopped < 20
