"""Closed-loop compensation over a warm-up, told the true temperature, an online estimate, or nothing (issue 45,
item 3; docs/control.md#compensation-over-a-warm-up). A script, not a test:

    .venv/bin/python benchmarks/study_warmup_loop.py [-o study.html] [--figures docs/figures] [--quick]

Two systems warm up under a duty cycle of moves and dwells:
- the stage (the stage-model-i preset, 1 kg, LuGre with the laws of Li et al. 2009) from 30 to 41.5 C in 4
  minutes of 1 mm moves in 0.5 s with 0.5 s dwells;
- a joint written here (0.05 kg m^2, LuGre whose Coulomb, static and viscous levels fall with the oil's
  temperature) from 25 to 55 C in 5 minutes of 1 rad moves in 1 s with 1 s dwells.

The truth is written here, outside the package: a two-node heat path (contact, housing, ambient) driven by the
duty cycle's friction power at the contact temperature (the steady LuGre force at the reference velocity, its
parameters from tests/reference, averaged over a cycle), integrated by scipy's solve_ivp; a proxy sensor lags the
housing by 30 s and reads it with 0.05 K of noise. The loop (thermofriction.control.simulate_loop, the C core)
runs the stage's friction at that temperature, period by period. Each compensation (feed-forward and the
observer) is told the true temperature (a perfect sensor), the estimate of a TemperatureEstimator (no sensor:
the friction a disturbance observer measures from a noisy encoder; with the lagging proxy as well), or the
start temperature (blind). The estimator's heat path is the truth's with each value 10 % off (C +10 %, R -10 %,
the proxy's lag +10 %): an identification's error, not the truth itself. The stage's time constants are the
illustrative ones of docs/self-heating.md; the joint's are shortened (a real joint warms over an hour) so that
the simulation stays minutes.

Also at constant temperatures (the issue's "study's two temperatures": 30 and 41.5 C for the stage, 25 and 55 C
for the joint, the sine and point-to-point references of docs/control.md): the estimator started at the stage's
temperature (soaked at a known ambient) and 5 C off.
"""

from __future__ import annotations

import argparse
import base64
import io
import math
import sys
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

import thermofriction as tf
from thermofriction import control as C

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
import reference as R  # noqa: E402  (the parameters at a temperature, outside the package)


def joint_model() -> tf.Model:
    """A robot joint at its output (rad, N m): 0.05 kg m^2, LuGre; fc, fs fall 2 %/K and sigma2 3 %/K from 25 C."""
    laws = {"fc": tf.Exp(a=3.0 * math.exp(0.02 * 25), b=-0.02, range=(20.0, 60.0)),
            "fs": tf.Exp(a=3.9 * math.exp(0.02 * 25), b=-0.02, range=(20.0, 60.0)),
            "sigma2": tf.Exp(a=2.0 * math.exp(0.03 * 25), b=-0.03, range=(20.0, 60.0))}
    friction = tf.LuGre(sigma0=3e3, sigma1=math.sqrt(3e3 * 0.05), sigma2=None, fc=None, fs=None, vs=0.05)
    return tf.Model(tf.MassPlant(mass=0.05), friction, tf.ModelI(laws))


@dataclass(frozen=True)
class System:
    name: str
    model: tf.Model
    pid: C.PID
    cycle: tuple          # (distance, move_time, dwell) of the duty cycle
    sine: tuple           # (amplitude, frequency) of the constant-temperature sine
    ambient: float        # [C]
    temperatures: tuple   # the two constant temperatures [C]
    duration: float       # the warm-up [s]
    heat: tuple           # (C_contact, R_contact_housing, C_housing, R_housing_ambient) [J/K, K/W]
    position_noise: float  # the encoder's noise [m or rad]
    v_min: float          # the estimator's gate [m/s or rad/s]
    unit: str             # the tracking error's unit, um or urad


SYSTEMS = [
    System("stage", tf.load_model("stage-model-i"), C.DEFAULT_PID, (1e-3, 0.5, 0.5), (1e-3, 0.5), 30.0, (30.0, 41.5),
           240.0, (5e-4, 3e4, 3e-3, 4.4e4), 1e-9, 1e-4, "um"),
    System("joint", joint_model(), C.PID(kp=2e3, ki=2e4, kd=14.0, tau_d=2e-4), (1.0, 1.0, 1.0), (1.0, 0.25), 25.0,
           (25.0, 55.0), 300.0, (4.0, 14.0, 15.0, 10.0), 2e-7, 5e-3, "urad"),
]
PROXY_LAG, PROXY_NOISE = 30.0, 0.05  # [s], [K]
DT = 1e-4
INERTIA_FEEDFORWARD = False  # --inertia-feedforward: every loop adds the reference's inertia force


def cycle_power(model, cycle, T) -> float:
    """The duty cycle's mean friction power [W] at contact temperature T: the steady LuGre force at the
    reference velocity (tests/reference's parameters), |F v| averaged over one cycle."""
    p = R.friction_params(model, T)
    v = cycle.velocity
    F = (p.fc + (p.fs - p.fc) * np.exp(-(v / p.vs) ** 2)) * np.sign(v) + p.sigma2 * v
    return float(np.mean(np.abs(F * v)))


def truth(system: System, time_grid):
    """The contact, housing and proxy temperatures [C] at the control instants (solve_ivp on the two-node path)."""
    C1, R1, C2, R2 = system.heat
    cycle = C.point_to_point(*system.cycle)
    grid = np.linspace(system.ambient - 10, system.ambient + 40, 201)
    power = np.array([cycle_power(system.model, cycle, T) for T in grid])
    Ta = system.ambient

    def rates(t, y):
        Tc, Th, Tp = y
        P = np.interp(Tc, grid, power)
        return [(P - (Tc - Th) / R1) / C1, ((Tc - Th) / R1 - (Th - Ta) / R2) / C2, (Th - Tp) / PROXY_LAG]

    sol = solve_ivp(rates, (0.0, time_grid[-1]), [Ta, Ta, Ta], method="LSODA", rtol=1e-9, atol=1e-9,
                    dense_output=True)
    Tc, Th, Tp = sol.sol(time_grid)
    reading = Tp + np.random.default_rng(7).normal(0.0, PROXY_NOISE, time_grid.size)
    return Tc, Th, reading


def estimator(system: System, proxy: bool, eta: float = 1.0) -> C.TemperatureEstimator:
    """The truth's heat path with each value 10 % off; the friction noise of the disturbance observer.
    eta = 0 for a stage held at its temperature by a thermostat (no self-heating)."""
    C1, R1, C2, R2 = system.heat
    m = system.model.plant.mass
    r_F = 6.0 * (m * system.position_noise / DT ** 2) ** 2  # (x_i - 2 x_{i-1} + x_{i-2}) of white noise: 6 sigma^2
    kw = dict(proxy="housing", tau_p=1.1 * PROXY_LAG, r_p=PROXY_NOISE ** 2) if proxy else {}
    return C.TemperatureEstimator(C_th=1.1 * C1, R_th=0.9 * R1, C_2=1.1 * C2, R_2=0.9 * R2, r_F=r_F, eta=eta,
                                  v_min=system.v_min, **kw)


def cases(system: System, proxy_reading, start: float):
    """(name, compensation kind, told, extra simulate_loop arguments) of the study."""
    out = [("none", None, None, {})]
    for kind in ("feed-forward", "observer"):
        out += [(f"{kind}, true T", kind, None, {}),
                (f"{kind}, estimator", kind, estimator(system, False), {}),
                (f"{kind}, estimator + proxy", kind, estimator(system, True),
                 {"proxy_temperature": proxy_reading} if proxy_reading is not None else None),
                (f"{kind}, blind", kind, start, {})]
    out.append(("observer, estimator started 5 C off", "observer", estimator(system, False),
                {"start": start + 5.0, "start_variance": 25.0}))
    return [c for c in out if c[3] is not None]


def compensation(system, kind, told):
    if kind is None:
        return None
    if kind == "feed-forward":
        return C.FeedForward(system.model, temperature=told)
    return C.Observer(system.model, 100.0, temperature=told)


def binned(result, width: float):
    """Per bin of `width` seconds: its centre, the RMS tracking error, RMS friction-estimate error, mean
    temperature-estimate error and the mean told temperature."""
    n = int(round(width / DT))
    m = result.time.size // n * n
    def per(a, f):
        return f(a[:m].reshape(-1, n), axis=1)
    rms = lambda a, axis: np.sqrt(np.mean(a ** 2, axis=axis))  # noqa: E731
    dT = result.temperature_error
    return {"t": per(result.time, np.mean), "error": per(result.error, rms),
            "friction": per(result.friction_error, rms),
            "dT": per(dT if dT is not None else np.zeros(m), np.mean),
            "told": per(result.compensation_temperature, np.mean)}


def run_case(system, ref, temperature, kind, told, extra, **kw):
    t0 = time.perf_counter()
    r = C.simulate_loop(system.model, ref, temperature=temperature, pid=system.pid,
                        compensation=compensation(system, kind, told), friction_measurement=C.DisturbanceObserver(
                            position_noise=system.position_noise), inertia_feedforward=INERTIA_FEEDFORWARD,
                        **extra, **kw)
    return r, time.perf_counter() - t0


def summary(r, settle: float) -> dict:
    """RMS and max tracking error, RMS friction-estimate error, temperature-estimate error (RMS, max after
    the first `settle` seconds)."""
    dT = r.temperature_error
    dT = dT if dT is not None and np.all(np.isfinite(dT)) else None
    late = r.time >= min(settle, r.time[-1] / 2)
    last = r.time >= r.time[-1] - 60.0
    return {"rms": r.rms_error, "max": r.max_error, "friction_rms": float(np.sqrt(np.mean(r.friction_error ** 2))),
            "first": float(np.sqrt(np.mean(r.error[r.time < 10.0] ** 2))),
            "last": float(np.sqrt(np.mean(r.error[last] ** 2))),
            "dT_rms": math.nan if dT is None else float(np.sqrt(np.mean(dT ** 2))),
            "dT_max_late": math.nan if dT is None else float(np.max(np.abs(dT[late])))}


def warmup(system: System, quick: bool):
    """The warm-up runs of one system: rows (name, summary) and the binned series for the figures."""
    duration = 20.0 if quick else system.duration
    ref = C.duty_cycle(*system.cycle, duration, DT)
    Tc, Th, proxy = truth(system, ref.time)
    rows, series = [], {}
    for name, kind, told, extra in cases(system, proxy, system.ambient):
        r, seconds = run_case(system, ref, Tc, kind, told, extra, ambient=system.ambient)
        rows.append((name, summary(r, 60.0), seconds))
        series[name] = binned(r, 2 * (system.cycle[1] + system.cycle[2]))
        print(f"  {system.name} warm-up, {name:30s} RMS {r.rms_error / SCALE[system.unit]:9.4g} {system.unit}  "
              f"({seconds:.1f} s)", flush=True)
        del r
    return rows, series, (ref.time, Tc, Th, proxy)


SCALE = {"um": 1e-6, "urad": 1e-6}


def constant(system: System, quick: bool):
    """At each constant temperature, each reference: true T, estimator from the right start and 5 C off, blind."""
    d, mt, dw = system.cycle
    refs = [C.sine_reference(*system.sine, 2.0 if quick else 4.0, DT), C.point_to_point(d, mt, dw, DT)]
    if system.unit == "urad":  # the references name their strokes in mm: a joint's are radians
        refs = [replace(refs[0], name=f"sine {system.sine[0]:g} rad, {system.sine[1]:g} Hz"),
                replace(refs[1], name=f"point-to-point {d:g} rad in {mt:g} s")]
    rows = []
    for ref in refs:
        for T in system.temperatures:
            for kind in ("feed-forward", "observer"):
                est = estimator(system, False, eta=0.0)  # held at T: the estimator told so
                runs = [("true T", None, {}), ("estimator", est, {"start": T}),
                        ("estimator, 5 C off", est, {"start": T - 5.0, "start_variance": 25.0}),
                        ("blind", system.ambient, {})]
                for label, told, kw in runs:
                    r, _ = run_case(system, ref, T, kind, told, {}, ambient=T, **kw)
                    rows.append((ref.name, T, f"{kind}, {label}", summary(r, 1.0)))
    return rows


def figure(system: System, series, temps):
    import logging
    import matplotlib
    matplotlib.use("Agg")
    logging.getLogger("matplotlib.font_manager").setLevel(logging.ERROR)
    import matplotlib.pyplot as plt
    k = 1 / SCALE[system.unit]
    t, Tc, Th, proxy = temps
    fig, ax = plt.subplots(2, 2, figsize=(12, 7.5), constrained_layout=True)
    a = ax[0, 0]
    s = slice(None, None, 2000)
    a.plot(t[s], Tc[s], color="k", lw=2, label="contact (truth)")
    a.plot(t[s], Th[s], color="0.6", lw=1.5, label="housing (truth)")
    a.plot(t[s], proxy[s], color="0.6", lw=0.6, ls=":", label="proxy reading (30 s lag)")
    styles = {"true T": ("k", "-"), "estimator": ("#1f77b4", "-"), "estimator + proxy": ("#2ca02c", "--"),
              "estimator started 5 C off": ("#ff7f0e", "-."),
              "blind": ("#d62728", "-"), "none": ("0.5", ":")}
    for name, label in (("observer, estimator", "estimate (no sensor)"),
                        ("observer, estimator + proxy", "estimate (with the proxy)"),
                        ("observer, estimator started 5 C off", "estimate (started 5 °C off)")):
        c, ls = styles[name.split(", ", 1)[1]]
        a.plot(series[name]["t"], series[name]["told"], color=c, ls=ls, label=label)
    a.set(xlabel="time [s]", ylabel="temperature [°C]", title=f"{system.name}: the warm-up and its estimates")
    a.legend(fontsize=8, frameon=False)
    for name, b in series.items():
        kind, _, how = name.partition(", ")
        if kind == "feed-forward":
            continue
        c, ls = styles[how or "none"]
        ax[0, 1].semilogy(b["t"], b["error"] * k, color=c, ls=ls, label=name)
        if kind == "observer":
            ax[1, 0].semilogy(b["t"], b["friction"], color=c, ls=ls, label=name)
            if how.startswith("estimator"):  # blind's error is the whole warm-up (the table): off this scale
                ax[1, 1].plot(b["t"], b["dT"], color=c, ls=ls, label=name)
    ax[0, 1].set(xlabel="time [s]", ylabel=f"RMS tracking error per cycle [{system.unit.replace('u', 'µ')}]",
                 title="tracking error (observer compensation)")
    ax[1, 0].set(xlabel="time [s]", ylabel="RMS friction-estimate error per cycle [N" +
                 (" m]" if system.unit == "urad" else "]"), title="friction-estimate error (observer)")
    ax[1, 1].set(xlabel="time [s]", ylabel="told minus true temperature, per cycle [K]",
                 title="temperature-estimate error (the estimators)")
    ax[1, 1].axhline(0, color="0.8", lw=0.8)
    for a in (ax[0, 1], ax[1, 0], ax[1, 1]):
        a.legend(fontsize=8, frameon=False)
    return fig


def table_html(head, rows):
    th = "".join(f"<th>{h}</th>" for h in head)
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in r) + "</tr>" for r in rows)
    return f"<table border=1 cellpadding=3 style='border-collapse:collapse;font-size:13px'><tr>{th}</tr>{body}</table>"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("-o", "--output", type=Path, default=Path("warmup_loop.html"))
    ap.add_argument("--figures", type=Path, help="also save the figures (PNG) in this folder")
    ap.add_argument("--quick", action="store_true", help="20 s warm-ups: a smoke run, not the study")
    ap.add_argument("--systems", default="stage,joint", help="which systems, comma-separated")
    ap.add_argument("--inertia-feedforward", action="store_true",
                    help="every loop adds the reference's inertia force (computed torque): what is left of the "
                         "tracking error is the friction compensation's")
    args = ap.parse_args(argv)
    global INERTIA_FEEDFORWARD
    INERTIA_FEEDFORWARD = args.inertia_feedforward
    parts = ["<html><body style='font-family:sans-serif'><h1>Compensation over a warm-up</h1>"]
    for system in SYSTEMS:
        if system.name not in args.systems.split(","):
            continue
        k, u = 1 / SCALE[system.unit], system.unit.replace("u", "µ")
        rows, series, temps = warmup(system, args.quick)
        print(f"\n{system.name}: warm-up {temps[1][0]:.1f} -> {temps[1][-1]:.1f} C in {temps[0][-1]:.0f} s")
        head = ["compensation", f"RMS error [{u}]", f"first 10 s [{u}]", f"last minute [{u}]", f"max error [{u}]",
                "RMS friction error", "RMS T error [K]", "max T error after 1 min [K]"]
        print("| " + " | ".join(head) + " |")
        print("|---" * len(head) + "|")
        html = []
        for name, s, _ in rows:
            cells = [name, f"{s['rms'] * k:.3g}", f"{s['first'] * k:.3g}", f"{s['last'] * k:.3g}",
                     f"{s['max'] * k:.3g}", f"{s['friction_rms']:.3g}", f"{s['dT_rms']:.3g}", f"{s['dT_max_late']:.3g}"]
            print("| " + " | ".join(cells) + " |")
            html.append(cells)
        fig = figure(system, series, temps)
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=90)
        if args.figures:
            args.figures.mkdir(parents=True, exist_ok=True)
            fig.savefig(args.figures / f"warmup_{system.name}.png", dpi=90)
        parts.append(f"<h2>{system.name}: warm-up {temps[1][0]:.1f} → {temps[1][-1]:.1f} °C</h2>" + table_html(
            head, html))
        parts.append(f"<img src='data:image/png;base64,{base64.b64encode(buf.getvalue()).decode()}'>")
        crow = constant(system, args.quick)
        print(f"\n{system.name}: constant temperatures")
        print(f"| reference | T | compensation | RMS error [{u}] | max error [{u}] | RMS T error [K] |")
        print("|---|---|---|---|---|---|")
        html = []
        for ref, T, name, s in crow:
            cells = [ref, f"{T:g}", name, f"{s['rms'] * k:.3g}", f"{s['max'] * k:.3g}", f"{s['dT_rms']:.3g}"]
            print("| " + " | ".join(cells) + " |")
            html.append(cells)
        parts.append(f"<h3>{system.name}: constant temperatures</h3>" + table_html(
            ["reference", "T [°C]", "compensation", f"RMS error [{u}]", f"max error [{u}]", "RMS T error [K]"], html))
    args.output.write_text("".join(parts) + "</body></html>", encoding="utf-8")
    print(f"wrote {args.output}")


if __name__ == "__main__":
    main()
