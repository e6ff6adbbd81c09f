"""Force data's initial model (``Force.initial_model``): a prescribed-motion model of the data's kind, with
starting values read off the data where the initial model gives none (:func:`read_start`, screened by short fits:
:func:`screen_starts`), and the records at rest refused (:func:`moving_speed`). The force measurement's class is
passed in (``force``): this module sits below measurements/force.py, which calls it."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..data.force import units_of
from ..data.motion import with_v_smooth
from ..errors import ComputationError, InputError
from ..fitting.optimiser import fit
from ..fitting.parameters import friction_parameters
from ..models import LuGre, Model, PrescribedMotion, load_model
from ..models.transforms import with_friction_model

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


#: a Stribeck velocity to start from where none is read off the data: this fraction of their moving speed (a
#: joint's 0.13 rad/s of its 1.3), inside the speeds the runs sweep, where the curve's fall towards fc is seen
STRIBECK_START = 0.1


def stribeck_speeds(experiments) -> tuple:
    """(largest, start): the largest speed of the experiments' driving motion, and a Stribeck velocity inside
    their speeds to start a fit from (STRIBECK_START of :func:`moving_speed`). A Stribeck velocity above the
    largest leaves g(v) = fc + (fs - fc) exp(-|v/vs|^delta) above fc + (fs - fc)/e on every sample: the curve's
    fall towards fc is never seen, and neither fc nor vs is determined (a fit from a rough start ended there, at
    vs = 5.7 rad/s on runs of at most 1.5 rad/s, 37 % above the data's optimum: issue 42)."""
    exps = list(experiments)
    start = STRIBECK_START * moving_speed(exps)
    return max(float(np.max(np.abs(np.asarray(e.drive_velocity, float)))) for e in exps), start


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
#: the screening's short fits run on each run's first this many samples (a joint's 120 s record at 4 ms: its first
#: 24 s, six cycles of its motion): the start's misfit shows there; on the whole record they were a third of the fit
SCREEN_SAMPLES = 6000


def _head(exp, n):
    """``exp`` cut to its first ``n`` samples (every sampled column), or as it is where it is no longer."""
    if len(exp.time) <= n:
        return exp
    return dataclasses.replace(exp, **{f.name: getattr(exp, f.name)[:n] for f in dataclasses.fields(exp)
                                       if isinstance(getattr(exp, f.name), np.ndarray)
                                       and len(getattr(exp, f.name)) == len(exp.time)})


def screen_starts(experiments, candidates, plant=None, progress=None, *, force) -> dict:
    """The candidate [friction] section whose short fit (SCREEN_EVALUATIONS evaluations at the coarse tolerance,
    each run's own offset profiled out, on the SCREEN_RUNS runs nearest the middle temperature) ends with the least
    misfit, as read (not the short fit's values: on a drive's command recorded 0.5 s late they walked to fc ~ 0, and
    the delay's misalignment was no longer seen). A start whose fit cannot run is not chosen; the first where none
    can. ``force``: the force measurement's class (the short fits' residuals; measurements/force.py: screened)."""
    if len(candidates) < 2:
        return candidates[0]
    exps = list(getattr(experiments, "fit", experiments))
    mid = float(np.median([e.temperature for e in exps]))
    exps = [_head(e, SCREEN_SAMPLES) for e in sorted(exps, key=lambda e: (abs(e.temperature - mid), len(e.time)))
            [:SCREEN_RUNS]]
    best = (math.inf, candidates[0])
    for k, section in enumerate(candidates):
        model = Model(plant or PrescribedMotion(), LuGre.from_dict(section))
        names = [n for n in ("sigma0", "sigma1", "fc", "fs", "vs", "sigma2") if n in section]
        per_run = force("per-experiment")
        try:
            outcome = fit(model, friction_parameters(model, names, excess=True),
                          [per_run.make_trace(e, model) for e in exps], rtol=1e-6, starts=1,
                          max_nfev=SCREEN_EVALUATIONS)
        except (ComputationError, InputError):
            continue
        cost = float(outcome.r @ outcome.r)
        if progress:
            progress(f"start {k + 1} of {len(candidates)} read off the data: misfit {cost:.4g}")
        if cost < best[0]:
            best = (cost, section)
    return best[1]


def start_section(experiments, kind: str = "lugre", plant: PrescribedMotion | None = None, screen: bool = True,
                  progress=None, *, force) -> dict:
    """A [friction] section of ``kind`` with starting values read off the data (:func:`read_start`), screened by
    short fits (:func:`screen_starts`, with the force measurement's class ``force``): measurements/force.py
    force_start, which documents it."""
    candidates = read_start(experiments)
    section = screen_starts(experiments, candidates, plant, progress, force=force) if screen else candidates[0]
    if kind == "lugre":
        return section
    start = Model(plant or PrescribedMotion(), LuGre.from_dict(section))
    return with_friction_model(start, kind).friction.to_dict()


def force_initial(init, method, data, experiments, *, force, friction=None, free=(), procedure="direct"):
    """The initial model for force data (``Force.initial_model``; ``force`` the force measurement's class): a
    prescribed-motion model of the data's kind (linear or rotary); a plant-only file (or one naming only the
    friction model), or none, gets its friction values from the data."""
    if free:
        raise InputError("free= frees plant parameters; a prescribed-motion model has none to fit")
    if method == "model-ii" and procedure != "direct":
        raise InputError("Model II's paper procedure reads stick-slip displacements; force data use the direct one")
    if not experiments:
        raise InputError("the dataset has no experiment with role 'fit'")
    rotary = units_of(getattr(data, "experiments", experiments))
    init = _from_plant_only(init, experiments, rotary, force)
    if init.plant.type != "prescribed":
        raise InputError(f"force data are fitted with a prescribed-motion model ([plant] type = \"prescribed\"); "
                         f"the initial model's plant is '{init.plant.type}'")
    if init.plant.rotary != rotary:
        want = "rotary" if rotary else "linear"
        raise InputError(f"the data are {want} ({'rad, N m' if rotary else 'm, N'}) but the initial model's motion is "
                         f"{init.plant.motion}: set motion = \"{want}\" in its [plant]")
    if friction is not None:
        init = with_friction_model(init, friction)
        if init.friction.description.smoothed_sign and "fs" in init.friction.law_targets:
            # asked for: a Stribeck map, not the Coulomb map a start without an excess fits
            init = _with_excess(init, experiments)
    if init.heat is not None:
        raise InputError("a self-heating model ([heat]) cannot be fitted to force data yet")
    moving_speed(experiments)  # a record at rest is refused whatever the initial model (it determines nothing)
    return _v_smooth_from_data(init, experiments)


def _with_excess(init, experiments):
    """A Stribeck map whose start has no excess (fs = fc: none seen in the data's slowest sliding) gets one to fit
    from: fs a tenth above fc, vs a tenth of the data's moving speed (the fit's defaults drop fs and vs where there
    is no excess, which made --friction stribeck a plain Coulomb map)."""
    values = init.friction.values()
    if "fs" in init.laws or values.get("fc") is None or (values.get("fs") or 0.0) > values["fc"]:
        return init
    return init.with_friction(fs=1.1 * values["fc"], vs=STRIBECK_START * moving_speed(experiments))


def _v_smooth_from_data(init, experiments):
    """A friction model whose ``v_smooth`` is left at its default gets one velocity step of the data where the
    velocity is quantised (a firmware's fixed steps): far below a step, a static model chatters at rest."""
    default = {f.name: f.default for f in dataclasses.fields(init.friction)}.get("v_smooth")
    if default is None or getattr(init.friction, "v_smooth", None) != default:
        return init
    return with_v_smooth(init, experiments)


def _from_plant_only(init, experiments, rotary, force):
    def start(plant, inp, model="lugre"):
        if plant.type != "prescribed":
            raise InputError("force data are fitted with a prescribed-motion model: [plant] type = \"prescribed\"")
        return start_section(experiments, model, plant, force=force)

    if init is None:
        plant = PrescribedMotion(motion="rotary" if rotary else "linear")
        return Model(plant, LuGre.from_dict(start_section(experiments, "lugre", plant, force=force)))
    if isinstance(init, Model):
        return init
    return load_model(init, friction_from=start)


__all__ = ["read_start", "screen_starts", "start_section", "moving_speed", "stribeck_speeds", "STRIBECK_START",
           "MIN_TRAVEL_STEPS", "force_initial"]
