"""Cost per communication step of the two FMU integrators, through fmpy (a script, not a test).

    .venv/bin/python benchmarks/bench_fmu.py

The li2009-model-i preset (stick-slip actuator, Model I at 35 C) exported twice in the same run: with
the adaptive integrator (the default) and with the fixed-step real-time integrator at 10 us. fmpy's FMI 2
API drives each over two cycles of the 30 V, 5 Hz sawtooth at communication steps of 0.1 ms and 1 ms
(the real-time FMU takes 10 and 100 fixed steps per communication step), the drive set with its slope
at each point. Each fmi2DoStep call is timed on its own (wall time from Python, fmpy's ctypes call
included; best of 3 runs per step): the median, the 99th percentile and the maximum in microseconds,
their ratio between the two FMUs, and each FMU's largest error against tf.simulate (share of the range
of the displacement and of the friction force). The floor: the same timing around fmi2GetReal of one
output (a ctypes call that integrates nothing).
"""

import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

import thermofriction as tf
from thermofriction.fmu import export_fmu

T = 35.0
FIXED_STEP = 1e-5
REPEATS = 3


def run(path, workdir, t, u, h):
    """Per-step wall times [s] (one row per repeat) and the last run's outputs."""
    md = read_model_description(str(path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzipped = extract(str(path), unzipdir=str(workdir / path.stem))
    times = np.empty((REPEATS, len(t) - 1))
    floor = np.empty((REPEATS, len(t) - 1))
    for r in range(REPEATS):
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                        instanceName=f"bench{r}")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.setReal([vr["temperature"], vr["voltage"]], [T, u[0]])
        fmu.exitInitializationMode()
        x = np.empty((len(t), 2))
        x[0] = fmu.getReal([vr["displacement"], vr["friction_force"]])
        for k in range(len(t) - 1):
            fmu.setReal([vr["voltage"]], [u[k]])
            fmu.setRealInputDerivatives([vr["voltage"]], [1], [(u[k + 1] - u[k]) / h])
            t0 = time.perf_counter()
            fmu.doStep(currentCommunicationPoint=t[k], communicationStepSize=h)
            t1 = time.perf_counter()
            fmu.getReal([vr["displacement"]])
            t2 = time.perf_counter()
            times[r, k], floor[r, k] = t1 - t0, t2 - t1
            x[k + 1] = fmu.getReal([vr["displacement"], vr["friction_force"]])
        fmu.terminate()
        fmu.freeInstance()
    return times, floor, x


def main():
    model = tf.load_model("li2009-model-i")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        paths = {"adaptive": tmp / "adaptive.fmu", f"realtime {FIXED_STEP:g} s": tmp / "realtime.fmu"}
        export_fmu(model, paths["adaptive"])
        export_fmu(model, paths[f"realtime {FIXED_STEP:g} s"], integrator="realtime", step=FIXED_STEP)
        for h in (1e-4, 1e-3):
            t = np.arange(int(round(0.4 / h)) + 1) * h
            u = tf.Sawtooth(amplitude=30.0, frequency=5.0, rise=0.999)(t)
            ref = tf.simulate(model, input=tf.Sampled(t, u), t_eval=t, temperature=T)
            rows, floors = {}, []
            for name, path in paths.items():
                times, floor, x = run(path, tmp / f"{h:g}", t, u, h)
                best = times.min(axis=0) * 1e6  # best of the repeats, per step [us]
                floors.append(np.median(floor.min(axis=0)) * 1e6)
                err = [np.max(np.abs(x[:, i] - want)) / np.ptp(want)
                       for i, want in enumerate((ref.displacement, ref.friction_force))]
                rows[name] = (np.median(best), np.percentile(best, 99), best.max(), err)
            print(f"li2009-model-i at {T:g} C, {len(t) - 1} communication steps of {h * 1e3:g} ms through fmpy "
                  f"(fmi2DoStep wall time, best of {REPEATS}; an fmi2GetReal call takes {min(floors):.1f} us):")
            print(f"  {'integrator':<18} {'median [us]':>12} {'p99 [us]':>10} {'max [us]':>10} {'p99/median':>11} "
                  f"{'err x':>9} {'err F':>9}")
            for name, (med, p99, mx, err) in rows.items():
                print(f"  {name:<18} {med:12.1f} {p99:10.1f} {mx:10.1f} {p99 / med:11.2f} {err[0]:9.2%} "
                      f"{err[1]:9.2%}")
            (a, b) = rows.values()
            print(f"  adaptive / realtime: median {a[0] / b[0]:.2f}x, 99th percentile {a[1] / b[1]:.2f}x, "
                  f"maximum {a[2] / b[2]:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
