"""Starting values from the data, for an initial model that gives only its plant (a model file with a
[plant] section and no [friction]): :func:`lugre_start` for displacement data, :func:`force_start` for force
data; and :func:`with_friction_model`, another friction model built from a model's values.

For displacement data:

A stick-slip actuator slips when the stage's acceleration times the end-effector mass exceeds the
friction level, so the friction level is of the order of ``m_e`` times the stage's acceleration. That
scale comes from the plant alone (the stage driven by the recorded input, nothing on it); a scan of the
friction level over four decades around it, each with bristles whose steady deflection is from 3 % to
3 times the stage's stroke (their stiffness is otherwise unknown to two decades) and lightly damped,
keeps the three starts with the lowest misfit. A short fit of the friction level, the stiffness and the
damping from each (on the shortest run) picks the start; the fit then starts from there with its
multi-start spanning a decade either way of each parameter.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..drive import experiment_waveform
from ..errors import ComputationError, InputError
from ..models import FRICTION_MODELS, Coulomb, LuGre, Model, ModelI, PrescribedMotion
from ..measurements.force import Force
from ..simulation import simulate
from .optimiser import fit
from .parameters import Parameters
from .problem import Problem, make_traces
from .procedures import base_model, friction_parameters

#: the scan, in units of m_e times the stage's acceleration scale
SCAN = np.logspace(-3, 1, 13)
DEFLECTIONS = (0.03, 0.1, 0.3, 1.0, 3.0)   # steady bristle deflection fc/sigma0, in units of the stage's stroke
DAMPING = 0.01     # sigma1 as a fraction of 2 sqrt(sigma0 m_e) (critical damping of the stuck end effector)


def lugre_start(plant, experiments, input=None) -> dict:
    """A [friction] section (LuGre) with starting values from ``experiments`` for ``plant``."""
    if plant.type != "stick-slip":
        raise InputError("starting values from the data need the stick-slip actuator's plant")
    experiments = list(experiments)
    if not experiments:
        raise InputError("no experiment to take starting values from")
    exp = min(experiments, key=lambda e: len(e.time))  # the shortest run: the scan costs one run per point
    probe = Model(plant, Coulomb(fc=1e-12, v_smooth=1e-3), input=input)
    waveform = experiment_waveform(exp, probe)
    stage = simulate(probe, t_eval=exp.time, input=waveform)
    accel = np.gradient(stage.stage_velocity, stage.time)
    a_scale = float(np.quantile(np.abs(accel), 0.999))
    stroke = float(np.ptp(stage.stage_displacement))
    if not (a_scale > 0 and stroke > 0):
        raise InputError(f"{exp.file}: the input does not move the stage: no starting values can be taken from it")
    m_e = plant.end_effector_mass
    scan = []
    for f, deflection in ((f, d) for f in SCAN for d in DEFLECTIONS):
        fc = float(f * m_e * a_scale)
        sigma0 = fc / (deflection * stroke)
        sigma1 = DAMPING * 2.0 * math.sqrt(sigma0 * m_e)
        model = Model(plant, LuGre(sigma0=sigma0, sigma1=sigma1, fc=fc), input=input)
        problem = Problem(model, ["fc"], make_traces([exp], model), rtol=1e-6, parallel=False)
        r, _ = problem.evaluate(np.array([fc]))
        cost = math.inf if r is None else float(r @ r)
        scan.append((cost, {"sigma0": sigma0, "sigma1": sigma1, "fc": fc}))
    scan = sorted((c for c in scan if math.isfinite(c[0])), key=lambda c: c[0])
    if not scan:
        raise InputError(f"{exp.file}: no friction level between {SCAN[0]:g} and {SCAN[-1]:g} x m_e x the stage's "
                         f"acceleration could be simulated: check the plant")
    # a scan point's misfit says little about where a fit from it ends (stiffness and friction level
    # trade off): a few steps of the fit from each of the best three decide
    best = None
    for _, start in scan[:3]:
        model = Model(plant, LuGre(**start), input=input)
        params = Parameters()
        for name, value in start.items():
            params.add(name, value, min=0.0)
        try:
            outcome = fit(model, params, make_traces([exp], model), rtol=1e-6, starts=1, max_nfev=15)
        except (ComputationError, InputError):  # a start whose fit cannot run is simply not chosen
            continue
        cost = float(outcome.r @ outcome.r)
        if best is None or cost < best[0]:
            best = (cost, dict(zip(start, (float(v) for v in outcome.theta))))
    values = best[1] if best is not None else scan[0][1]
    return {"model": "lugre", **values}




def with_friction_model(model: Model, kind: str) -> Model:
    """``model`` with a ``kind`` friction model (docs/identification.md#friction-models), built from
    its own friction's values where the two share a parameter (a Model I law goes with its
    parameter; laws of parameters the new model lacks are dropped). What the new model requires
    and the old one lacks is derived from the level fc and the presliding stiffness sigma0 (a GMS
    model's sum of k_i; else fc over 1 um): sigma1 = 1e-6 s x sigma0, z_ba = fc / (2 sigma0),
    C = 1e4 /s x fc, and GMS elements k_i proportional to 1/i summing to sigma0, w_i = 1/4 (four
    elements breaking loose one after the other).

    Parameters
    ----------
    model : Model
        The model.
    kind : str
        The friction model wanted (``FRICTION_MODELS``: lugre, dahl, elastoplastic, gms, stribeck, coulomb).

    Returns
    -------
    Model

    Raises
    ------
    InputError
        An unknown friction model.
    """
    if kind not in FRICTION_MODELS:
        raise InputError(f"unknown friction model '{kind}' (one of: {', '.join(FRICTION_MODELS)})")
    if model.friction.model == kind:
        return model
    cls = FRICTION_MODELS[kind]
    names = {f.name for f in dataclasses.fields(cls)} - set(cls.arrays)
    laws = {k: v for k, v in model.laws.items() if k in names}
    kw = {k: v for k, v in model.friction.values().items() if k in names}
    kw.update({k: None for k in laws})
    at = base_model(model).friction.values()  # numbers (laws at mid-range), to derive the rest from
    fc = at["fc"]
    sigma0 = at.get("sigma0") or (sum(at["k"]) if "k" in at else fc / 1e-6)
    derived = {"sigma0": sigma0, "sigma1": 1e-6 * sigma0, "z_ba": 0.5 * fc / sigma0, "C": 1e4 * fc}
    if kind == "gms":
        h = sum(1.0 / i for i in range(1, 5))
        derived.update(k=tuple(sigma0 / (i * h) for i in range(1, 5)), w=(0.25,) * 4)
    for name in cls.required:
        if name not in kw:
            kw[name] = derived[name]
    thermal = model.thermal
    if isinstance(thermal, ModelI):
        thermal = ModelI(laws) if laws else None
    return dataclasses.replace(model, friction=cls(**kw), thermal=thermal)


#: a position that stays within this many steps of its resolution dithers at rest (an encoder's last count
#: flickering): its "motion" is quantisation noise, and a fit to it determines nothing (issue 41)
MIN_TRAVEL_STEPS = 2


def _travel_in_steps(x) -> float:
    """The position's range in steps of its resolution (the least change between samples); 0 if it never moves."""
    steps = np.abs(np.diff(np.asarray(x, float)))
    steps = steps[steps > 0]
    return float(np.ptp(x)) / float(steps.min()) if steps.size else 0.0


def moving_speed(experiments) -> float:
    """The 95th percentile speed of the experiments' driving motion. Records at rest determine no friction and are
    refused before any fit (InputError naming their files): at rest in 95 % of the samples or more, or every
    position within MIN_TRAVEL_STEPS steps of its resolution."""
    exps = list(experiments)
    speed = np.abs(np.concatenate([np.asarray(e.drive_velocity, float) for e in exps])) if exps else np.zeros(0)
    top = float(np.quantile(speed, 0.95)) if speed.size else 0.0
    why = "at rest in 95 % of the samples or more" if not top > 0 else (
        f"the position stays within {MIN_TRAVEL_STEPS} steps of its resolution, a dither at rest"
        if all(_travel_in_steps(e.displacement) <= MIN_TRAVEL_STEPS for e in exps) else None)
    if why:
        files = ", ".join(str(e.file) for e in exps[:3]) + (f" and {len(exps) - 3} more" if len(exps) > 3 else "")
        raise InputError(f"{files}: the motion does not move ({why}): no friction can be taken from it")
    return top


def _static_map(e, top):
    """(fc, sigma2, b) of one run: ``F = b + fc sgn(v) + sigma2 v`` by linear least squares on the faster half of
    its sliding samples (b, its own offset, where it moves both ways); None with fewer than 4 such samples."""
    v, F = np.asarray(e.drive_velocity, float), np.asarray(e.force, float)
    speed = np.abs(v)
    sliding = speed > 0.02 * top
    if sliding.sum() < 8:
        return None
    fast = sliding & (speed >= np.median(speed[sliding]))
    both_ways = bool(np.any(v[fast] > 0) and np.any(v[fast] < 0))
    cols = [np.sign(v[fast]), v[fast]] + ([np.ones(int(fast.sum()))] if both_ways else [])
    coef, *_ = np.linalg.lstsq(np.column_stack(cols), F[fast], rcond=None)
    return abs(float(coef[0])), float(coef[1]), float(coef[2]) if both_ways else 0.0


def _reversals(e):
    """The samples where one run's driving velocity changes sign."""
    ve = np.asarray(e.drive_velocity, float)
    return np.flatnonzero(np.sign(ve[1:]) * np.sign(ve[:-1]) < 0)


def _stiffness(exps, fc):
    """The bristle stiffness from the force's rise over the position after each reversal (the secant over half
    the swing, times ln 2, is sigma0 for LuGre), at most where the swing spans a tenth of a typical sample's motion;
    None where no swing is seen. Also each run's motion since its last reversal."""
    secants, travelled = [], []
    for e in exps:
        xe, Fe, flips = np.asarray(e.displacement, float), np.asarray(e.force, float), _reversals(e)
        for i in flips:
            j = i + 1
            while j < len(Fe) and abs(Fe[j] - Fe[i]) < fc and j - i < 10_000:
                j += 1
            if j < len(Fe) and abs(xe[j] - xe[i]) > 0:
                secants.append(abs(Fe[j] - Fe[i]) / abs(xe[j] - xe[i]))
        start = np.zeros(len(xe), int)  # the sample of the last reversal before each sample
        start[flips + 1] = flips + 1
        travelled.append(np.abs(xe - xe[np.maximum.accumulate(start)]))
    sigma0 = math.log(2.0) * float(np.median(secants)) if secants else None
    step = float(np.median(np.concatenate([np.abs(np.diff(np.asarray(e.displacement, float))) for e in exps])))
    if sigma0 is not None and step > 0:
        sigma0 = min(sigma0, 2.0 * fc / (0.1 * step))
    return sigma0, travelled


def _excess(exps, maps, travelled, length, top):
    """The Stribeck excess over each run's own Coulomb-viscous line: (speeds, levels) binned by speed over the
    steady sliding (``length`` past a reversal), and the median peak of the excess within 20 such lengths after
    the reversals (where the bristles break away: the steady sliding of a smooth motion is rarely slow)."""
    rows, peaks = [], []
    for e, (fc, s2, b), moved in zip(exps, maps, travelled):
        v, F = np.asarray(e.drive_velocity, float), np.asarray(e.force, float)
        x = np.sign(v) * (F - b) - fc - s2 * np.abs(v)
        steady = (np.abs(v) > 0.02 * top) & (moved > length)
        rows.append(np.column_stack([np.abs(v[steady]), x[steady]]))
        flips = _reversals(e)
        for i, n in zip(flips, np.append(flips[1:], len(v) - 1)):
            after = np.arange(i + 1, n + 1)
            after = after[moved[after] < 20.0 * length]
            if after.size:
                peaks.append(float(np.max(x[after])))
    rows = np.concatenate(rows) if rows else np.zeros((0, 2))
    order = np.argsort(rows[:, 0])
    n_bin = max(len(order) // 40, 5)
    bins = [order[i:i + n_bin] for i in range(0, len(order), n_bin)]
    return (np.array([np.median(rows[i, 0]) for i in bins]), np.array([np.median(rows[i, 1]) for i in bins]),
            float(np.median(peaks)) if peaks else 0.0)


def read_start(experiments) -> list:
    """Starting values read off the data, as LuGre [friction] sections: the first from the static map and the
    steady sliding, the others (where they differ) with the Stribeck excess from the break-away peaks after the
    reversals, and with the bristle stiffness 3 times lower and higher (the secant's bias where the presliding
    spans a sample or two).

    - the Coulomb level fc and viscous sigma2 by linear least squares ``F = b + fc sgn(v) + sigma2 v`` on the
      faster half of each run's sliding samples, each run with its own offset b (a sensor re-zeroed per run, a
      temperature per run): their medians;
    - a Stribeck excess fs - fc from the slowest steady sliding, and vs where it has fallen by 1/e;
    - the bristle stiffness sigma0 from the force's rise over the motion after each reversal (the secant
      over half the swing, times ln 2, is sigma0 for LuGre), else fc over 1/1000 of the stroke;
    - sigma1 so that its force at the typical sliding speed is a tenth of fc."""
    exps = list(getattr(experiments, "fit", experiments))
    if not exps:
        raise InputError("no experiment to take starting values from")
    top = moving_speed(exps)
    maps = [_static_map(e, top) for e in exps]
    kept = [(e, m) for e, m in zip(exps, maps) if m is not None]
    if not kept:
        F = np.concatenate([e.force for e in exps])
        kept = [(e, (float(np.quantile(np.abs(F), 0.5)) or 1.0, 0.0, 0.0)) for e in exps]
    exps, maps = [e for e, _ in kept], [m for _, m in kept]
    fc = float(np.median([m[0] for m in maps])) or 1.0
    speed = np.abs(np.concatenate([e.drive_velocity for e in exps]))
    sigma2 = max(float(np.median([m[1] for m in maps])), 1e-3 * fc / top)
    stroke = max(float(np.ptp(np.concatenate([e.displacement for e in exps]))), 1e-300)
    sigma0, travelled = _stiffness(exps, fc)
    sigma0 = sigma0 or fc / (1e-3 * stroke)
    typical = float(np.median(speed[speed > 0.02 * top]))
    section = {"model": "lugre", "fc": fc, "sigma2": sigma2, "sigma0": sigma0, "sigma1": 0.1 * fc / typical}
    speeds, levels, peak = _excess(exps, maps, travelled, 5.0 * fc / sigma0, top)
    if levels.size > 2 and levels[0] > 0.05 * fc:
        below = np.flatnonzero(levels < levels[0] / math.e)
        vs = float(speeds[below[0]]) if below.size else float(speeds[-1])
        section.update(fs=fc + float(levels[0]), vs=max(vs, float(speeds[0])))
    out = [section]
    if peak > 0.05 * fc and peak > section.get("fs", fc) - fc:
        out.append({**section, "fs": fc + peak, "vs": section.get("vs", typical / 4.0)})
    out += [{**c, "sigma0": c["sigma0"] * f} for c in list(out) for f in (1 / 3, 3.0)]
    return out


#: the screening's short fit of each data-derived start: evaluations, and the runs it uses (the shortest few)
SCREEN_EVALUATIONS = 8
SCREEN_RUNS = 2


def screened(experiments, candidates, plant=None, progress=None) -> dict:
    """The candidate [friction] section whose short fit (SCREEN_EVALUATIONS evaluations at the coarse tolerance,
    each run's own offset profiled out, on the SCREEN_RUNS runs nearest the middle temperature) ends with the least
    misfit, as read (not the short fit's values: on a drive's command recorded 0.5 s late they walked to fc ~ 0, and
    the delay's misalignment was no longer seen). A start whose fit cannot run is not chosen; the first where none
    can."""
    if len(candidates) < 2:
        return candidates[0]
    exps = list(getattr(experiments, "fit", experiments))
    mid = float(np.median([e.temperature for e in exps]))
    exps = sorted(exps, key=lambda e: (abs(e.temperature - mid), len(e.time)))[:SCREEN_RUNS]
    best = (math.inf, candidates[0])
    for k, section in enumerate(candidates):
        model = Model(plant or PrescribedMotion(), LuGre.from_dict(section))
        names = [n for n in ("sigma0", "sigma1", "fc", "fs", "vs", "sigma2") if n in section]
        try:
            outcome = fit(model, friction_parameters(model, names, excess=True), make_traces(
                exps, model, Force("per-experiment")), rtol=1e-6, starts=1, max_nfev=SCREEN_EVALUATIONS)
        except (ComputationError, InputError):
            continue
        cost = float(outcome.r @ outcome.r)
        if progress:
            progress(f"start {k + 1} of {len(candidates)} read off the data: misfit {cost:.4g}")
        if cost < best[0]:
            best = (cost, section)
    return best[1]


def force_start(experiments, kind: str = "lugre", plant: PrescribedMotion | None = None, screen: bool = True,
                progress=None) -> dict:
    """A [friction] section of ``kind`` with starting values read off the data (:func:`read_start`), screened.

    Of the data-derived starts, the one whose short fit on the data ends lowest (:func:`screened`): a fit from the
    wrong one ended at half the Coulomb level (issue 40). A rough start: the fit's multi-start spans a decade
    either way.

    Parameters
    ----------
    experiments : list of ForceExperiment
        The force experiments (a Dataset's fit experiments where a Dataset is given).
    kind : str, default "lugre"
        The friction model.
    plant : PrescribedMotion, optional
        The plant (its motion: linear or rotary).
    screen : bool, default True
        Whether to screen the starts by short fits (else the first, from the static map).
    progress : callable, optional
        Called with a line saying what is done.

    Returns
    -------
    dict
        The [friction] section: "model" and the starting values, in SI units.

    Raises
    ------
    InputError
        No experiment; a record at rest; an unknown friction model.
    """
    candidates = read_start(experiments)
    section = screened(experiments, candidates, plant, progress) if screen else candidates[0]
    if kind == "lugre":
        return section
    start = Model(plant or PrescribedMotion(), LuGre.from_dict(section))
    return with_friction_model(start, kind).friction.to_dict()


__all__ = ["lugre_start", "force_start", "read_start", "screened", "moving_speed", "MIN_TRAVEL_STEPS", "with_friction_model"]
