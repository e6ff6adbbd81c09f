"""What a warm-up fit returns (docs/self-heating.md#warm-up-without-a-contact-temperature): the package's
FitResult with the laws and the heat path's values and intervals (or "undetermined"), the contact temperature's
trajectory with its 95 % band by the delta method on the fit's covariance, the choice of one node or two, the
temperature interpolation's error against the noise, and what data would separate what these cannot."""

from __future__ import annotations

import math

import numpy as np

from ..fitting.identifiability import groups
from ..fitting.parameters import Parameters, unit_of
from ..fitting.quality import fit_quality, pooled
from ..measurements import amount
from ..models.plants import rotary_unit
from .result import FitResult
from .warm_up_fit import HEAT_UNITS, covariance, delta_band, gradient
from .warm_up_held import score_held_out
from .warm_up_path import interpolation_error

#: the most points of a record's temperature trajectory in the results
TRAJECTORY_POINTS = 2000
#: the interpolation's error, relative to the force's noise, above which it is warned about
INTERPOLATION_SHARE = 0.1
UNDETERMINED_TEXT = "undetermined"


def _scale_bearing(name: str, scale: str) -> bool:
    """Whether ``name`` carries the temperature scale (a law coefficient, a heat gain or capacity, a start
    temperature) and the scale is undetermined."""
    return scale == UNDETERMINED_TEXT and ("." in name or name in ("C_th", "R_th", "C_2", "R_2") or
                                           name.startswith("T_0"))


def _unit(model, name, rotary) -> str:
    if name in HEAT_UNITS:
        return HEAT_UNITS[name]
    if name.startswith("T_0"):
        return "C"
    u = unit_of(model, name)
    return rotary_unit(u) if rotary and u != "C" else u


def _parameters(s, problem, theta, cov, model):
    """(Parameters shown, their indices in theta): every fitted value with its standard error and 95 % interval
    (log-normal for a positive one), less those that carry an undetermined scale."""
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    params, kept = Parameters(), []
    rotary = s.unit == "N m"
    for i, (name, value, lg) in enumerate(zip(problem.layout.names, theta, problem.layout.log)):
        if _scale_bearing(name, s.scale):
            continue
        p = params.add(name, float(value), unit=_unit(model, name, rotary), min=0.0 if lg else -math.inf)
        p.stderr = float(se[i])
        z = 1.959963984540054
        if not math.isfinite(se[i]):
            p.ci95 = (0.0 if lg else -math.inf, math.inf)
        elif lg:
            f = math.exp(min(z * se[i] / value, 700.0))
            p.ci95 = (value / f, value * f)
        else:
            p.ci95 = (value - z * se[i], value + z * se[i])
        kept.append(i)
    return params, kept


def _time_constants(problem, theta, cov):
    """The heat path's time constants [s] with their standard errors (delta method): scale-free."""
    def taus(t):
        return problem.path_of(t).time_constants()
    G = gradient(taus, theta, problem.layout)
    half = delta_band(G, cov)
    return [{"value": v, "ci95_half_width": float(h)} for v, h in zip(taus(theta), half)]


def _trajectories(problem, theta, cov) -> dict:
    """Per warm-up record: the times, the contact's temperature with its 95 % band, the housing's and the
    proxy's, at up to TRAJECTORY_POINTS of the heat balance's bin edges."""
    picks = {r.label: np.unique(np.linspace(0, r.edges.size - 1, TRAJECTORY_POINTS).astype(int))
             for r in problem.warm}

    def contact(t):
        tracks, _ = problem.run(t)
        return np.concatenate([tracks[r.label].states[picks[r.label], 0] for r in problem.warm])
    half = delta_band(gradient(contact, theta, problem.layout), cov)
    tracks, _ = problem.run(theta)
    out, at = {}, 0
    for r in problem.warm:
        k = picks[r.label]
        states = tracks[r.label].states[k]
        h = half[at:at + k.size]
        at += k.size
        out[r.label] = {"time": r.edges[k], "contact": states[:, 0], "lower": states[:, 0] - h,
                        "upper": states[:, 0] + h, "unit": "C"}
        if problem.nodes == 2:
            out[r.label]["housing"] = states[:, 1]
        if problem.path_of(theta).tau_p is not None:
            out[r.label]["proxy"] = states[:, -1]
    return out


def separation_advice(problem, theta) -> str:
    """What record would separate the laws from the heat path."""
    slow = problem.path_of(theta).time_constants()[-1]
    longest = max(r.time[-1] - r.time[0] for r in problem.warm)
    proxy = "" if any(r.proxy is not None for r in problem.warm) else ", or a proxy temperature"
    return (f"a longer warm-up (the longest record here lasts {longest:.4g} s; the fitted heat path's slowest time "
            f"constant is {slow:.4g} s, and a record of three of them at least sees the rise end, while a slower "
            f"node shows only over a longer one), at two speeds or more, or soak runs at the temperatures it "
            f"reaches{proxy}")


def _separation(found, problem, theta) -> list:
    """The identifiability groups with the heat path among their members, with what record would separate them."""
    advice = separation_advice(problem, theta)
    for g in found:
        if any(n in HEAT_UNITS or n.startswith("T_0") for n in g["parameters"]):
            g["separate"] = advice if not g.get("separate") else f"{g['separate']}; {advice}"
            g["warning"] = (f"the data cannot separate {', '.join(g['parameters'])} (condition index "
                            f"{g['condition_index']:.3g}): the laws and the heat path trade along one direction. "
                            f"What would separate them: {g['separate']}")
    return found


def _determination(params, problem, theta, advice) -> list:
    """Each shown value the data leave poorly determined (standard error above half its value, uncertainty.py's
    rule), and, where one is the heat path's, what record would determine it (and whether the warm-up is short for
    its slowest time constant)."""
    out = [f"'{p.name}' is poorly determined by these data (standard error "
           f"{'infinite' if not math.isfinite(p.stderr) else f'{100 * p.stderr / abs(p.value):.0f} % of its value'})"
           for p in params.values() if p.stderr is not None and p.value and
           (not math.isfinite(p.stderr) or p.stderr > 0.5 * abs(p.value))]
    slow = problem.path_of(theta).time_constants()[-1]
    longest = max(r.time[-1] - r.time[0] for r in problem.warm)
    loose = [w for w in out if w.split("'")[1] in HEAT_UNITS]  # (a law's own looseness is the laws' matter)
    if loose:
        short = (f" (the longest record lasts {longest:.4g} s, less than three of the heat path's slowest time "
                 f"constant, {slow:.4g} s: the rise's end is not seen)" if longest < 3.0 * slow else "")
        out.append(f"the laws and the heat path are not separated by these data{short}. What record would: {advice}")
    return out


def _qualities(s, problem, theta):
    """(per-experiment rows, the force blocks' pooled quality, the proxy's RMSE per record [K])."""
    rows, quals, sizes = [], [], []
    for name, e, measured in problem.blocks(theta):
        if name.endswith(" proxy"):
            rows[-1]["proxy_rmse"] = float(np.sqrt(np.mean(e ** 2)))
            continue
        q = fit_quality(e, measured)
        quals.append(q)
        sizes.append(e.size)
        warm = next((r for r in s.warm if r.label == name), None)
        soak = next((x for x in s.soak if x.label == name), None)
        rows.append({"file": name, "temperature": None if warm else soak.temperature, "role": "fit",
                     "warm_up": warm is not None, "rmse_offset_removed": q["rmse"], "fit_quality": q,
                     "unit": s.unit})
    return rows, pooled(quals, sizes)


def _choice_warnings(choice, problem, other) -> list:
    """The verdict on one node against two."""
    if problem.nodes == 1 and choice.get("delta", -math.inf) > choice["threshold"]:
        return [f"the fit is not adequate: one node cannot follow this warm-up's fast and slow phases (a second "
                f"node, the housing, lowers AICc by {choice['delta']:.4g}); fit nodes=2 or \"auto\""]
    return []


def warm_up_result(s, final, other, choice, wall_time, held=()) -> FitResult:
    """The FitResult of a warm-up fit from its setup ``s``, the chosen fit ``final`` (problem, theta, scipy's
    result), the other node count's fit ``other``, the ``choice`` between them, and the ``held`` experiments
    (the dataset's validate records: predicted, not fitted, warm_up_held.py)."""
    problem, theta, res = final
    cov, noise_scale, (S, Vt, col, bad), stats = covariance(problem, theta, res)
    model = problem.model_of(theta)
    params, kept = _parameters(s, problem, theta, cov, model)
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = (cov / np.outer(se, se))[np.ix_(kept, kept)]
    corr[~np.isfinite(corr)] = np.nan
    np.fill_diagonal(corr, 1.0)
    found = _separation(groups(S, Vt, col, problem.layout.names, theta, se, noise_scale, bad=bad), problem, theta)
    rows, overall = _qualities(s, problem, theta)
    held_rows, held_warnings = score_held_out(problem, theta, list(held), s.unit, float(overall["rmse"]))
    warnings = _choice_warnings(choice, problem, other)
    if warnings:
        overall = dict(overall, adequate=False)
    forces, _ = problem.forces(theta)
    errors = [interpolation_error(model, r, problem.grid, problem.basis, forces[r.label]) for r in s.warm]
    noise = min(s.sigma[r.label] for r in s.warm)
    if max(errors) > INTERPOLATION_SHARE * noise:
        warnings.append(f"the force's interpolation across temperature errs by up to {amount(max(errors), s.unit)}, "
                        f"more than {INTERPOLATION_SHARE:g} of the noise ({amount(noise, s.unit)})")
    path = problem.path_of(theta)
    heat = {"nodes": path.nodes, "choice": choice, "scale": s.scale,
            "eta": "held at 1: force data determine C/eta and eta R, not eta (C_th, R_th, C_2, R_2 are per unit eta)",
            "time_constants": _time_constants(problem, theta, cov)}
    if path.tau_p is not None:
        heat["proxy"] = {"node": "housing" if path.proxy_node else "contact", "tau_p": path.tau_p}
    if s.scale == UNDETERMINED_TEXT:
        warnings.insert(0, "the temperature scale is undetermined: without soak runs at two temperatures or more "
                           "or a proxy temperature, scaling every law's slope by 1/s and the heat path's gains by s "
                           "leaves the forces unchanged; the heat path's resistances and capacities, the laws' "
                           "slopes and the contact temperature are not given (its time constants are); the fitted "
                           f"model's laws keep the initial model's scale ({', '.join(s.held)} held there): they are "
                           "no calibration")
        trajectory = UNDETERMINED_TEXT
        heat.update({k: UNDETERMINED_TEXT for k in ("C_th", "R_th") + (("C_2", "R_2") if path.nodes == 2 else ())})
    else:
        trajectory = _trajectories(problem, theta, cov)
    details = {"heat_path": heat, "temperature": trajectory, "held": s.held,
               "interpolation": {"nodes": len(problem.grid), "grid": problem.grid, "max_error": max(errors),
                                 "noise": noise, "unit": s.unit},
               "warm_up_records": [r.label for r in s.warm], "soak_runs": [x.label for x in s.soak]}
    warnings += [g["warning"] for g in found] + _determination(params, problem, theta,
                                                               separation_advice(problem, theta)) + held_warnings
    rmse = float(overall["rmse"])
    return FitResult(method="warm-up", model=model, parameters=params, correlation=corr, cost=float(2 * res.cost),
                     rmse=rmse, n_points=int(res.fun.size), nfev=problem.nfev, njev=int(res.njev or 0), starts=1,
                     wall_time=wall_time, success=bool(res.status > 0), message=str(res.message),
                     experiments=rows + held_rows,
                     warnings=warnings, statistics=stats, details=details,
                     fit_quality=overall, unit=s.unit, measurement="force",
                     removed="each record's own sensor offset (fitted)", identifiability=found)


__all__ = ["warm_up_result", "UNDETERMINED_TEXT"]
