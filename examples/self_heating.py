"""Self-heating of the paper's actuator (docs/models.md#self-heating): the li2009-self-heating preset stepping at 5, 50
and 500 Hz for five minutes from 30 C. For each frequency: the interface temperature, the drift of
the step per cycle, and the error of a prediction that ignores self-heating (the step size at
30 C times the number of cycles); the two-time-scale method against the full simulation.

Run: python examples/self_heating.py [-o REPORT.html] [--figures DIR] [--duration S] [--no-full]
(docs/self-heating.md shows its figures: --figures docs/figures)
"""

import argparse
import sys
from pathlib import Path

import numpy as np

import thermofriction as tf
from thermofriction.heating import Full, TwoTimeScale, simulate_heating
from thermofriction.reporting import heating_report

FREQUENCIES = (5.0, 50.0, 500.0)
T_START = 30.0


def run(frequency, duration, full=True, model=None):
    """Two-time-scale prediction, optionally the full simulation, and the constant-temperature
    prediction (start-up from rest plus the periodic step at 30 C per cycle), on one grid."""
    model = model or tf.load_model("li2009-self-heating")
    saw = tf.Sawtooth(amplitude=30, frequency=frequency, rise=0.999)
    avg = simulate_heating(model, duration, input=saw, temperature=T_START, solver=TwoTimeScale())
    ref = simulate_heating(model, duration, input=saw, temperature=T_START, solver=Full()) if full else None
    table = tf.heating.cycle_table(model, saw, [T_START])
    cycles = np.round(avg.time * frequency)
    warm = 6  # cycle_table's warm-up: its start-up excess applies from then on
    constant = table.step_size[0] * cycles + np.where(cycles >= warm, table.startup[0], 0.0)
    return {"label": f"{frequency:g} Hz", "frequency": frequency, "result": avg, "reference": ref,
            "constant": constant}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("-o", "--output", type=Path, default=Path("self_heating.html"), help="HTML report")
    ap.add_argument("--figures", type=Path, help="also save the figures (SVG and PNG) in this folder")
    ap.add_argument("--duration", type=float, default=300.0, help="seconds of operation (default 300)")
    ap.add_argument("--no-full", action="store_true", help="skip the full simulations (the reference)")
    args = ap.parse_args(argv)
    runs = [run(f, args.duration, full=not args.no_full) for f in FREQUENCIES]
    model = tf.load_model("li2009-self-heating")
    h = model.heat
    print(f"li2009-self-heating: C_th = {h.heat_capacity:g} J/K, R_th = {h.thermal_resistance:g} K/W, "
          f"eta = {h.heat_fraction:g}, tau = {h.time_constant:g} s; {args.duration:g} s from {T_START:g} C")
    print(f"{'f [Hz]':>7} {'rise [K]':>9} {'step 0 [um]':>12} {'step end [um]':>14} {'x end [mm]':>11} "
          f"{'const-T x [mm]':>15} {'|dT| vs full [K]':>17} {'x err vs full':>14} {'2TS [s]':>8} {'full [s]':>9}")
    for r in runs:
        a, ref, c = r["result"], r["reference"], r["constant"]
        truth = ref if ref is not None else a
        dT = np.max(np.abs(a.temperature - ref.temperature)) if ref is not None else np.nan
        dx = abs(a.displacement[-1] - ref.displacement[-1]) / abs(ref.displacement[-1]) if ref is not None else np.nan
        print(f"{r['frequency']:7g} {a.temperature[-1] - a.temperature[0]:9.3f} {a.step_size[0] * 1e6:12.4f} "
              f"{a.step_size[-1] * 1e6:14.4f} {truth.displacement[-1] * 1e3:11.4f} {c[-1] * 1e3:15.4f} "
              f"{dT:17.2e} {dx:14.2e} {a.stats['seconds']:8.3f} "
              f"{ref.stats['seconds'] if ref is not None else np.nan:9.2f}")
    heating_report(runs, args.output, figures_dir=args.figures, command="python " + " ".join(sys.argv))
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
