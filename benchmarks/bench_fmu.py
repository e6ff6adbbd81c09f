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

    .venv/bin/python benchmarks/bench_fmu.py --figure docs/figures/fmu-fmpy.png

draws docs/fmu.md's figure instead: fmpy.simulate_fmu (its own master algorithm, inputs held over each
step) runs both FMUs over 1 s of the sawtooth with the temperature rising 30 -> 41.5 C, beside
tf.simulate on the smooth signals, at output intervals of 0.1 ms and 10 us.
"""

import argparse
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


def figure(path):
    """docs/fmu.md's figure: what fmpy.simulate_fmu gives at two output intervals."""
    import fmpy
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from thermofriction._io import atomic_write

    model = tf.load_model("li2009-model-i")
    saw = tf.Sawtooth(amplitude=30.0, frequency=5.0, rise=0.999)
    t = np.linspace(0.0, 1.0, 100001)
    temperature = 30.0 + 11.5 * t
    signal = np.array(list(zip(t, saw(t), temperature)),
                      dtype=[("time", float), ("voltage", float), ("temperature", float)])
    runs = {}
    with tempfile.TemporaryDirectory() as tmp:
        fmus = {"adaptive FMU": Path(tmp) / "adaptive.fmu", "real-time FMU, step 1 µs": Path(tmp) / "realtime.fmu"}
        export_fmu(model, fmus["adaptive FMU"])
        export_fmu(model, fmus["real-time FMU, step 1 µs"], integrator="realtime", step=1e-6)
        for h in (1e-4, 1e-5):
            for name, fmu in fmus.items():
                res = fmpy.simulate_fmu(str(fmu), stop_time=1.0, output_interval=h, input=signal,
                                        output=["displacement"])
                ref = tf.simulate(model, input=saw, t_eval=res["time"], temperature=tf.Sampled(t, temperature))
                runs[h, name] = (res["time"], res["displacement"], ref.displacement)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 6.4), sharex=True, height_ratios=(3, 2))
    time_, x, ref = runs[1e-5, "adaptive FMU"]
    top.plot(time_, ref * 1e6, color="0.6", lw=4, label="tf.simulate")
    top.plot(time_, x * 1e6, color="C0", lw=1.2, label="adaptive FMU (fmpy, output interval 10 µs)")
    top.plot(*(v * s for v, s in zip(runs[1e-5, "real-time FMU, step 1 µs"][:2], (1, 1e6))), color="C1", lw=1,
             ls="--", label="real-time FMU, step 1 µs (fmpy, 10 µs)")
    top.set_ylabel("end-effector displacement [µm]")
    top.legend(loc="upper left")
    top.set_title("li2009-model-i as an FMU in fmpy.simulate_fmu: sawtooth 30 V, 5 Hz; temperature 30 → 41.5 °C",
                  fontsize=10)
    styles = {(1e-4, "adaptive FMU"): ("C3", "-"), (1e-5, "adaptive FMU"): ("C0", "-"),
              (1e-5, "real-time FMU, step 1 µs"): ("C1", "--")}
    for (h, name), (color, ls) in styles.items():
        time_, x, ref = runs[h, name]
        err = (x - ref) / np.ptp(ref) * 100
        bottom.plot(time_, err, color=color, ls=ls, lw=1,
                    label=f"{name}, output interval {h * 1e6:g} µs (max {np.max(np.abs(err)):.2f} %)")
    bottom.axhline(0.0, color="0.5", lw=0.5)
    bottom.set_ylabel("FMU - tf.simulate\n[% of the displacement range]")
    bottom.set_xlabel("time [s]")
    bottom.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    with atomic_write(path, "wb") as fh:
        fig.savefig(fh, format="png", dpi=110)
    for key, (time_, x, ref) in runs.items():
        print(f"output interval {key[0] * 1e6:g} µs, {key[1]}: max |FMU - tf.simulate| = "
              f"{np.max(np.abs(x - ref)) / np.ptp(ref):.3%} of the displacement range, at 1 s "
              f"{abs(x[-1] - ref[-1]) / np.ptp(ref):.3%}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--figure", metavar="PNG", help="draw docs/fmu.md's figure to PNG instead")
    args = parser.parse_args()
    if args.figure:
        figure(args.figure)
        return 0
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
