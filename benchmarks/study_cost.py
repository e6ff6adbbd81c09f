"""The cost of a rough-start fit as a distribution (issue 42, item 1): over truths drawn here, with starts 2-3x
off, the median, 90th percentile and worst of each fit's cost in plain-C simulations of its fit runs, and where
its evaluations go, stage by stage.

Truths (drawn here, away from the presets and from the package's generator; their displacements integrated by
SciPy's solve_ivp through the independent reference implementation tests/reference/, never by thermofriction's
simulate; 20 nm noise, 1 nm quantisation; the paper's actuator input, tests/truths.py's SAW):

- ``model-i``: masses drawn; sigma0, fc and sigma1 each with an exponential or a linear law (drawn), sigma1
  log-uniform over 0.5-30 N s/m (at its low end poorly determined); 5 temperatures;
- ``model-ii``: tests/truths.py's Model II truth (dF with a break between 34 and 39 C); 9 temperatures;
- ``free-me``: a ``model-i`` truth with m_e fitted too (``free=("m_e",)``), its start 2-3x off; 8 temperatures;
- ``stribeck-mass``: a ``model-i`` truth with Stribeck laws on fs and vs, fitted from a LuGre start without
  Stribeck (fs = fc) whose held m_e is 1.5x off (the issue's never-converging case; not in the closing targets);
- ``force``: a joint's friction torque (tests/lookalike.py: LuGre with a Stribeck effect and direction-dependent
  levels, drawn here, integrated by SciPy's LSODA under an analytic motion; AR(1) torque noise, quantised encoder
  and torque, jittered sampling, a sensor offset per run): 3 runs of 40 s at 250 Hz, two fitted and one held out;
  LuGre with fc_neg and fs_neg (8 parameters) fitted with per-run offsets, the model driven by the position;
- ``force-ripple``: the same with a position ripple in the truth (20-80 a turn, 1-4 times the noise), fitted with
  its period given and its first harmonic's amplitudes (10 parameters).

The force kinds' unit is their own: the C core's exact stepping of the prescribed motion of the fit runs
(``tf_prescribed_force`` through the force measurement, no sensitivities) with the truth's values, the fastest
of 5, timed in the same process (bench_rough_start.py's ``exact_force_time``).

Starts: every fitted law (Model II: sigma0, sigma1, fc and the dF values; force: sigma0, sigma1, fc, the Stribeck
excess fs - fc, vs and sigma2, the negative side's levels starting from the positive ones, the ripple's amplitudes
from zero) multiplied or divided by a factor drawn in [2, 3] (benchmarks/bench_rough_start.py's, as its plain-C unit ``Plain``: one source).

The cost: the fit's wall (and CPU, all threads) time over the unit's, one plain-C Dormand-Prince simulation of
the same fit runs with the truth (benchmarks/baseline_dopri5.c, the fastest of 5, timed in the same process).
The SciPy modules the package imports on first use are imported before the first fit (warm_imports): the first
truth's cost is then a fit's like the others'.
The stages: the study wraps the package's stage functions (STAGES) and counts, per stage, the model evaluations
(``Problem.evaluate``, what ``FitResult.nfev`` counts), those with a Jacobian, the C core's calls and time and the
stage's own wall time (the innermost stage running; "other" outside every stage), and logs every least-squares
run (its stage, evaluations, limit, status, samples and the parameter that moved most). Nothing in src/ changes;
the fit's own ``nfev`` is recorded beside the study's count (they agree: tests/test_study_cost.py).

Run: nice -n 10 python benchmarks/study_cost.py [--quick] [--truths N] [--kinds model-i,...] [--out FILE]
     (default kinds model-i, model-ii, free-me; the force kinds with --kinds force,force-ripple)
     python benchmarks/study_cost.py --summarise FILE   (the table from a finished or partial run)
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import dataclasses
import functools
import json
import math
import os
import sys
import threading
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
import lookalike as L  # noqa: E402
import reference as R  # noqa: E402
from truths import SAW, model_ii_truth, random_plant  # noqa: E402

import thermofriction as tf  # noqa: E402
from thermofriction.fitting import optimiser, problem  # noqa: E402
from thermofriction.identification import front, model_i, model_ii, procedures  # noqa: E402
from thermofriction.models import Exp, Linear, ModelI  # noqa: E402
from bench_rough_start import JOINT, Plain, exact_force_time, factors, law_errors, model_ii_start, scaled_law  # noqa: E402

T5 = (30.5, 33.5, 36.5, 39.5, 41.5)
T8 = tuple(np.round(np.linspace(30.5, 41.5, 8), 2))
T9 = tuple(np.round(np.linspace(30.5, 41.5, 9), 2))
KINDS = ("model-i", "model-ii", "free-me", "stribeck-mass", "force", "force-ripple")
FORCE_KINDS = ("force", "force-ripple")
#: the force kinds' fitted parameters (the ripple's amplitudes added with a ripple)
FORCE_NAMES = ("sigma0", "sigma1", "fc", "fc_neg", "fs", "fs_neg", "vs", "sigma2")
CORE = ("simulate", "simulate_sensitivities", "prescribed_force")
#: (owner, attribute, stage): the innermost one running names the stage
STAGES = [(optimiser, "_screened_starts", "start screening"),
          (model_i._PerTemperature, "run", "per-temperature fits"),
          (model_ii, "fit_friction", "per-temperature fits"), (model_ii, "_dF_per_temperature", "per-temperature fits"),
          (model_i, "_laws_through", "laws"), (model_ii, "_dF_law", "laws"),
          (model_i, "checked_kinds", "law kinds"),
          (model_i._PerTemperature, "profiled_constant", "profile"), (model_i, "profiled", "profile"),
          (model_i, "settled_constants", "profile"),
          (front, "identify_model_i", "joint refinement"), (front, "identify_model_ii", "joint refinement"),
          (front, "with_held_tests", "held tests"), (procedures, "uncertainty", "intervals"),
          (model_i, "widened", "intervals"), (front, "fit_friction", "force fit"),
          (front, "with_ripple_advice", "ripple advice"), (front, "_with_generalisation", "held-out check"),
          (front, "model_free", "model-free map")]
COUNTS = ("evaluations", "jacobians", "core_calls", "core_time", "wall")


class Ledger:
    """Per stage: evaluations, Jacobians, C core calls and time, own wall time; and the least-squares runs."""

    def __init__(self):
        self.stack = ["other"]
        self.rows = collections.defaultdict(lambda: dict.fromkeys(COUNTS, 0))
        self.runs = []
        self.lock = threading.Lock()
        self.since = time.perf_counter()

    def switch(self, stage=None):
        """Charges the wall time since the last switch to the running stage; enters ``stage`` (None: leaves)."""
        now = time.perf_counter()
        with self.lock:
            self.rows[self.stack[-1]]["wall"] += now - self.since
            self.since = now
            self.stack.append(stage) if stage else self.stack.pop()

    def add(self, **counts):
        with self.lock:
            row = self.rows[self.stack[-1]]
            for k, v in counts.items():
                row[k] += v

    def total(self, what):
        return sum(r[what] for r in self.rows.values())


def _in_stage(ledger, stage, function):
    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        ledger.switch(stage)
        try:
            return function(*args, **kwargs)
        finally:
            ledger.switch()
    return wrapper


def _counted_evaluate(ledger, evaluate):
    @functools.wraps(evaluate)
    def wrapper(self, theta, jac=False):
        ledger.add(evaluations=1, jacobians=int(jac))
        return evaluate(self, theta, jac)
    return wrapper


def _timed_core(ledger, call):
    def wrapper(*args):
        t0 = time.perf_counter()
        try:
            return call(*args)
        finally:
            ledger.add(core_calls=1, core_time=time.perf_counter() - t0)
    return wrapper


def _logged_least_squares(ledger, least_squares):
    @functools.wraps(least_squares)
    def wrapper(prob, transform, phi0, bounds, max_nfev, *args, **kwargs):
        before = prob.nfev
        res = least_squares(prob, transform, phi0, bounds, max_nfev, *args, **kwargs)
        move = np.abs(np.asarray(res.x) - np.asarray(phi0))
        i = int(np.argmax(move))
        ledger.runs.append({"stage": ledger.stack[-1], "parameters": len(prob.names), "rtol": prob.rtol,
                            "points": prob.n_points,
                            "temperatures": sorted({round(float(t.nominal_temperature), 2) for t in prob.traces}),
                            "limit": max_nfev, "evaluations": prob.nfev - before, "status": int(res.status),
                            "moved_most": prob.names[i], "move": float(move[i])})
        return res
    return wrapper


@contextlib.contextmanager
def staged():
    """While active, the package's stages, evaluations, core calls and least-squares runs go to the yielded
    Ledger (the originals are put back after)."""
    ledger = Ledger()
    core = sys.modules["thermofriction._core"]
    patches = [(owner, attr, _in_stage(ledger, stage, getattr(owner, attr))) for owner, attr, stage in STAGES]
    patches += [(problem.Problem, "evaluate", _counted_evaluate(ledger, problem.Problem.evaluate)),
                (optimiser, "_least_squares", _logged_least_squares(ledger, optimiser._least_squares))]
    patches += [(core, n, _timed_core(ledger, getattr(core, n))) for n in CORE]
    saved = [(owner, attr, owner.__dict__[attr]) for owner, attr, _ in patches]
    for owner, attr, new in patches:
        setattr(owner, attr, new)
    try:
        yield ledger
    finally:
        ledger.switch("other")  # charge the last stretch
        ledger.stack = ["other"]
        for owner, attr, old in saved:
            setattr(owner, attr, old)


# --- truths, drawn here -----------------------------------------------------------------------------------------

def _law(rng, value30, relative_slope):
    """An exponential or a linear law (drawn) with ``value30`` at 30 C, changing by ``relative_slope`` per degree
    there; positive over 30-42 C."""
    if rng.random() < 0.5:
        return Exp(value30 * math.exp(-relative_slope * 30.0), relative_slope, range=(30.0, 42.0))
    slope = value30 * max(relative_slope, -0.06)  # stays above 0.28 x value30 at 42 C
    return Linear(slope, value30 - 30.0 * slope, range=(30.0, 42.0))


def model_i_truth(rng, stribeck=False):
    """Masses drawn; sigma0, fc, sigma1 (and fs, vs with ``stribeck``) each an exponential or linear law."""
    plant = random_plant(rng)
    fc30 = rng.uniform(0.2, 0.8) * 25.0 * plant.end_effector_mass  # the actuator slips (tests/truths.py)
    laws = {"sigma0": _law(rng, rng.uniform(4e5, 4e6), -rng.uniform(0.02, 0.12)),
            "fc": _law(rng, fc30, -rng.uniform(0.02, 0.1)),
            "sigma1": _law(rng, math.exp(rng.uniform(math.log(0.5), math.log(30.0))), -rng.uniform(0.0, 0.05))}
    if stribeck:
        laws["fs"] = _law(rng, fc30 * rng.uniform(1.3, 1.8), -rng.uniform(0.0, 0.03))
        laws["vs"] = _law(rng, math.exp(rng.uniform(math.log(3e-4), math.log(3e-3))), rng.uniform(0.0, 0.03))
    friction = tf.LuGre(sigma0=None, sigma1=None, fc=None, **({"fs": None, "vs": None} if stribeck else {}))
    return tf.Model(plant, friction, ModelI(laws), SAW, name="truth")


def dataset(truth, temps, duration, rate, seed):
    """The truth's runs integrated by solve_ivp (tests/reference, rtol 1e-8), with 20 nm noise and 1 nm
    quantisation."""
    rng = np.random.default_rng(seed)
    t = np.arange(round(duration * rate) + 1) / rate
    exps = []
    for T in temps:
        x = R.reference_simulate(truth, t, temperature=T, rtol=1e-8).displacement
        x = np.round((x + 20e-9 * rng.standard_normal(t.size)) / 1e-9) * 1e-9
        exps.append(tf.Experiment(file=f"T{T:g}C.csv", time=t, voltage=R.waveform_value(SAW, t), displacement=x,
                                  temperature=float(T), input=SAW, description="solve_ivp reference"))
    return tf.Dataset(name=f"study-cost-{seed}", experiments=exps)


def case(kind, seed, quick):
    """(truth, temperatures, start, identify's options) of one truth of ``kind``."""
    rng = np.random.default_rng([seed, KINDS.index(kind)])
    if kind == "model-ii":
        truth = model_ii_truth(rng)
        return truth, (T5 if quick else T9), model_ii_start(truth, rng), {"method": "model-ii"}
    truth = model_i_truth(rng, stribeck=kind == "stribeck-mass")
    fitted = {n: law for n, law in truth.laws.items() if n in ("sigma0", "sigma1", "fc")}
    laws = {n: scaled_law(law, f) for (n, law), f in zip(sorted(fitted.items()), factors(rng, 3))}
    start = dataclasses.replace(truth, thermal=ModelI(laws), name="start",
                                friction=tf.LuGre(sigma0=None, sigma1=None, fc=None))
    me = truth.plant.end_effector_mass
    if kind == "free-me":
        start = dataclasses.replace(start, plant=dataclasses.replace(truth.plant, end_effector_mass=me * factors(rng, 1)[0]))
        return truth, (T5 if quick else T8), start, {"method": "model-i", "free": ("m_e",)}
    if kind == "stribeck-mass":
        start = dataclasses.replace(start, plant=dataclasses.replace(truth.plant, end_effector_mass=me * 1.5))
    return truth, T5, start, {"method": "model-i"}


def force_truth(rng, ripple):
    """A joint's friction drawn here (tests/lookalike.py's Truth: LuGre with direction-dependent levels, a Stribeck
    effect and optionally a position ripple) and the same in thermofriction's terms (for the unit and the errors)."""
    fc = rng.uniform(0.2, 0.6)
    neg = rng.uniform(0.8, 1.25)  # the negative side's levels over the positive's
    excess = rng.uniform(0.1, 0.5)
    period = 2 * math.pi / int(rng.integers(20, 81))
    t = L.Truth(fc_pos=fc, fc_neg=fc * neg, fs_pos=fc * (1 + excess), fs_neg=fc * neg * (1 + excess),
                vs=math.exp(rng.uniform(math.log(0.03), math.log(0.2))),
                sigma0=math.exp(rng.uniform(math.log(50.0), math.log(500.0))), sigma1=rng.uniform(0.1, 1.0),
                sigma2=rng.uniform(0.05, 0.2), ripple=rng.uniform(0.02, 0.08) if ripple else 0.0, ripple_period=period)
    friction = tf.LuGre(sigma0=t.sigma0, sigma1=t.sigma1, fc=t.fc_pos, fs=t.fs_pos, vs=t.vs, sigma2=t.sigma2,
                        fc_neg=t.fc_neg, fs_neg=t.fs_neg,
                        **({"ripple_period": period, "ripple_sin1": t.ripple, "ripple_cos1": 0.0} if ripple else {}))
    return t, tf.Model(JOINT, friction, name="truth")


def force_case(kind, seed, quick):
    """(data, the truth as a model, the start, identify's options) of one force truth of ``kind``."""
    rng = np.random.default_rng([seed, KINDS.index(kind)])
    ripple = kind == "force-ripple"
    truth, model = force_truth(rng, ripple)
    duration, rate = (8.0, 250.0) if quick else (40.0, 250.0)
    data, _ = L.lookalike_experiments(truth=truth, motion="position", offsets=tuple(rng.uniform(-0.1, 0.1, 3)),
                                      duration=duration, rate=rate, noise=0.01, seed=seed)
    v = model.friction.values()
    f = dict(zip(("sigma0", "sigma1", "fc", "fs", "vs", "sigma2"), factors(rng, 6)))
    start = {n: v[n] * f[n] for n in ("sigma0", "sigma1", "fc", "vs", "sigma2")}
    start["fs"] = start["fc"] + (v["fs"] - v["fc"]) * f["fs"]
    if ripple:
        start.update(ripple_period=v["ripple_period"], ripple_cos1=0.0, ripple_sin1=0.0)
    names = list(FORCE_NAMES) + (["ripple_cos1", "ripple_sin1"] if ripple else [])
    init = tf.Model(JOINT, tf.LuGre(**start), name="start")
    return data, model, init, {"method": "base", "parameters": names, "offset": "per-experiment"}


def force_errors(fit, truth, names):
    """(largest relative error, largest error in 95 % half-widths, its parameter) of the fitted ``names`` against
    the truth's values (the ripple's amplitudes relative to the ripple's size)."""
    v = truth.friction.values()
    size = math.hypot(v.get("ripple_cos1") or 0.0, v.get("ripple_sin1") or 0.0)
    rel, half, worst = 0.0, 0.0, "-"
    for n in names:
        p = fit.parameters[n]
        e = abs(p.value - v[n])
        h = e / max(0.5 * (p.ci95[1] - p.ci95[0]), 1e-300)
        rel = max(rel, e / (size if n.startswith("ripple_") else abs(v[n])))
        if h > half:
            half, worst = h, n
    return rel, half, worst


def run_force_case(kind, seed, quick):
    """One force truth of ``kind`` identified from its start, its cost in its own exact stepping."""
    data, truth, start, opts = force_case(kind, seed, quick)
    unit = exact_force_time(truth, data)
    with staged() as ledger:
        t0, c0 = time.perf_counter(), time.process_time()
        fit = tf.identify(data, init=start, **opts)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    rel, half, worst = force_errors(fit, truth, opts["parameters"])
    # the optimum these data give (the look-alike's logger -- quantised, lagged, jittered -- leaves the truth outside
    # the intervals): the same fit from the truth's values, not timed; how far the rough start's lands from it
    best = tf.identify(data, init=dataclasses.replace(truth, name="from the truth"), **opts)
    same = max(abs(fit.parameters[n].value - best.parameters[n].value)
               / max(0.5 * (best.parameters[n].ci95[1] - best.parameters[n].ci95[0]), 1e-300) for n in opts["parameters"])
    return {"values": {n: fit.parameters[n].value for n in opts["parameters"]}, "same_optimum": same, "cost_from_truth": float(best.cost), "fit_cost": float(fit.cost),
            "kind": kind, "seed": seed, "quick": quick, "wall": wall, "cpu": cpu, "unit_wall": unit[0],
            "unit_cpu": unit[1], "cost": wall / unit[0], "cost_cpu": cpu / unit[1], "nfev": fit.nfev,
            "njev": fit.njev, "success": bool(fit.success), "message": str(fit.message),
            "adequate": fit.adequate, "rel_error": rel, "half_widths": half, "worst": worst,
            "ripple_advice": (fit.fit_quality or {}).get("ripple"),
            "stages": {k: dict(v) for k, v in ledger.rows.items()}, "runs": ledger.runs,
            "evaluations": ledger.total("evaluations"), "load": os.getloadavg()[0]}


def run_case(kind, seed, quick, plain):
    """One truth of ``kind`` identified from its start: its cost, stages, least-squares runs and recovery."""
    if kind in FORCE_KINDS:
        return run_force_case(kind, seed, quick)
    truth, temps, start, opts = case(kind, seed, quick)
    duration, rate = (0.4, 5000.0) if quick else (2.0, 10_000.0)
    data = dataset(truth, temps, duration, rate, seed)
    unit = plain.time(truth, data.fit)
    with staged() as ledger:
        t0, c0 = time.perf_counter(), time.process_time()
        fit = tf.identify(data, init=start, **opts)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    try:
        rel, half, worst = law_errors(fit, truth, temps)
    except (KeyError, ValueError, ZeroDivisionError):  # a law the fit does not have (stribeck-mass: fs, vs)
        rel, half, worst = math.nan, math.nan, "-"
    if "free" in opts:
        me, p = truth.plant.end_effector_mass, fit.parameters["m_e"]
        rel, half = max(rel, abs(p.value - me) / me), max(half, abs(p.value - me) / (0.5 * (p.ci95[1] - p.ci95[0])))
    return {"kind": kind, "seed": seed, "quick": quick, "wall": wall, "cpu": cpu, "unit_wall": unit[0],
            "unit_cpu": unit[1], "cost": wall / unit[0], "cost_cpu": cpu / unit[1], "nfev": fit.nfev,
            "njev": fit.njev, "success": bool(fit.success), "message": str(fit.message),
            "adequate": fit.adequate, "rel_error": rel, "half_widths": half, "worst": worst,
            "stages": {k: dict(v) for k, v in ledger.rows.items()}, "runs": ledger.runs,
            "evaluations": ledger.total("evaluations"), "load": os.getloadavg()[0]}


# --- the table ---------------------------------------------------------------------------------------------------

def percentiles(values):
    """(median, 90th percentile, worst) of ``values``."""
    v = np.asarray(values, float)
    return float(np.median(v)), float(np.quantile(v, 0.9)), float(v.max())


def stage_shares(rows):
    """Per stage, its total evaluations and wall time over ``rows`` as fractions of all of theirs."""
    ev = collections.Counter()
    wall = collections.Counter()
    for r in rows:
        for s, c in r["stages"].items():
            ev[s] += c["evaluations"]
            wall[s] += c["wall"]
    te, tw = max(sum(ev.values()), 1), max(sum(wall.values()), 1e-300)
    return {s: (ev[s] / te, wall[s] / tw) for s in sorted(wall, key=wall.get, reverse=True)}


def summarise(rows):
    """Prints, per kind, the cost's median, 90th percentile and worst, and where the slowest fits spend."""
    print(f"{'kind':14s} {'n':>3s} {'cost median':>11s} {'p90':>7s} {'worst':>7s} | {'CPU median':>10s} {'p90':>7s} "
          f"{'worst':>7s} | {'eval. median':>11s} {'worst':>6s} | {'wall med. [s]':>13s} | recovered (2 half-w.)")
    for kind in KINDS:
        rs = [r for r in rows if r["kind"] == kind]
        if not rs:
            continue
        c, cc, n, w = (percentiles([r[k] for r in rs]) for k in ("cost", "cost_cpu", "evaluations", "wall"))
        ok = sum(1 for r in rs if r["half_widths"] <= 2)
        same = [r for r in rs if "same_optimum" in r]
        print(f"{kind:14s} {len(rs):3d} {c[0]:11.0f} {c[1]:7.0f} {c[2]:7.0f} | {cc[0]:10.0f} {cc[1]:7.0f} "
              f"{cc[2]:7.0f} | {n[0]:11.0f} {n[2]:6.0f} | {w[0]:13.1f} | {ok} of {len(rs)}"
              + (f"; at the optimum from the truth's start (1 half-width): "
                 f"{sum(1 for r in same if r['same_optimum'] <= 1)} of {len(same)}" if same else ""))
    for kind in KINDS:
        rs = sorted((r for r in rows if r["kind"] == kind), key=lambda r: r["cost"])
        if not rs:
            continue
        slow = rs[int(0.9 * (len(rs) - 1)):]  # the tenth that costs most (at least the worst)
        print(f"\n{kind}: stages (share of evaluations, of wall time): all fits / the slowest {len(slow)}")
        every, worst = stage_shares(rs), stage_shares(slow)
        for s in every:
            w = worst.get(s, (0.0, 0.0))
            print(f"  {s:22s} {every[s][0]:6.0%} {every[s][1]:6.0%}   |  {w[0]:6.0%} {w[1]:6.0%}")
        runs = [x for r in rs for x in r["runs"]]
        spent = max(sum(x["evaluations"] for x in runs), 1)
        limit = [x for x in runs if x["status"] == 0]
        far = collections.Counter(x["moved_most"] for x in runs if x["move"] > 5.0)
        print(f"  least-squares runs at their evaluation limit: {len(limit)} of {len(runs)}, "
              f"{sum(x['evaluations'] for x in limit) / spent:.0%} of the runs' evaluations; runs moving a parameter "
              f"by more than e^5 (log) or 5 starts: {dict(far)}")
        for r in slow:
            print(f"  slow: seed {r['seed']}, cost {r['cost']:.0f}, {r['evaluations']} evaluations, "
                  f"{r['message'][:90]}")
            for run in sorted(r["runs"], key=lambda x: -x["evaluations"])[:4]:
                print(f"    {run['stage']:20s} {run['evaluations']:3d} of {run['limit']} evaluations at rtol "
                      f"{run['rtol']:g} ({run['parameters']} parameters; status {run['status']}; moved most: "
                      f"{run['moved_most']} by {run['move']:.2g})")


def warm_imports():
    """Imports the SciPy modules the package imports on first use (the multi-start's Latin hypercube, the held tests'
    chi-square, the baseline's splines), so that the first fit timed does not pay for them: 0.9 s, 40-170 units of a
    force fit, were in the first truth's cost alone."""
    import scipy.interpolate  # noqa: F401
    import scipy.linalg  # noqa: F401
    import scipy.optimize  # noqa: F401
    import scipy.special  # noqa: F401
    import scipy.stats  # noqa: F401


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one truth per kind, 0.4 s at 5 kHz, 5 temperatures")
    ap.add_argument("--truths", type=int, default=None, help="truths per kind (default 20; --quick: 1)")
    ap.add_argument("--kinds", default="model-i,model-ii,free-me", help=f"comma-separated of {', '.join(KINDS)}")
    ap.add_argument("--seed", type=int, default=0, help="the first truth's seed")
    ap.add_argument("--out", help="append each fit's record to this JSON-lines file")
    ap.add_argument("--summarise", help="only print the table of this JSON-lines file")
    args = ap.parse_args(argv)
    if args.summarise:
        summarise([json.loads(line) for line in Path(args.summarise).read_text().splitlines() if line.strip()])
        return []
    kinds = args.kinds.split(",")
    for k in kinds:
        if k not in KINDS:
            raise SystemExit(f"unknown kind {k!r} (one of {', '.join(KINDS)})")
    n = args.truths or (1 if args.quick else 20)
    warm_imports()
    plain = Plain(model_i_truth(np.random.default_rng(0)), 35.0)
    rows = []
    for seed in range(args.seed, args.seed + n):  # the kinds interleaved: a partial run has them all
        for kind in kinds:
            r = run_case(kind, seed, args.quick, plain)
            rows.append(r)
            print(f"{kind:14s} seed {seed:3d}: cost {r['cost']:6.0f} (CPU {r['cost_cpu']:6.0f}), "
                  f"{r['evaluations']} evaluations, {r['wall']:.1f} s, half-widths {r['half_widths']:.2g}, "
                  f"load {r['load']:.1f}", flush=True)
            if args.out:
                with open(args.out, "a") as f:
                    f.write(json.dumps(r) + "\n")
    summarise(rows)
    return rows


if __name__ == "__main__":
    main()
