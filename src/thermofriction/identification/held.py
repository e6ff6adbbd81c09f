"""Held values checked against the data (a procedure-layer step after a fit): for every parameter the fit holds --
the plant's masses and stiffness, the friction model's fs, vs, sigma2, delta, a law held at the initial model's --
a score (Lagrange-multiplier) test from the sensitivities at the optimum says whether the data contradict it.

At the optimum the residuals r are orthogonal to the fitted directions J. A held parameter whose column j (its
sensitivity, offsets profiled out as the measurement does) leaves a part j' = (I - J J^+) j that r still projects on
is one the data would move: LM = (j'^T r)^2 / (s^2 tau j'^T j') is chi-squared with one degree of freedom if the held
value is right (a law's coefficients together: as many as it has), with s^2 the residual variance and tau the
residuals' integrated autocorrelation time (their variance inflation: correlated residuals carry less information).
A held value is contradicted where p < LEVEL / (the number of tests) and freeing it would remove at least MATERIAL
of the misfit. fs held at fc (no Stribeck effect) is tested in the directions of an excess at three vs together.
The held columns are the Problem's own sensitivities (one more simulation with them as extra targets)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._lazy import lazy
from ..models import ModelI
from ..measurements import amount
from .advice import MATERIAL, TRY_AT_MOST, OutOfSample, holds, tried
from ..fitting.parameters import EXCESS, PLANT_UNITS, get_value
from ..fitting.problem import Problem, counting
from ..measurements import make_traces

special = lazy("scipy.special")

#: the family-wise level at which held values are said to be contradicted (Bonferroni over the tests): strict, as
#: a right model's small misfits (integration error, a law's shape) must not raise false alarms, while a wrong
#: mass or a missing Stribeck effect gives p < 1e-12
LEVEL = 1e-3
#: held friction parameters tested where the model has them; plant parameters tested by form
FRICTION_HELD = ("fs", "vs", "sigma2", "delta", "z_ba")
PLANT_HELD = {True: ("m_e", "m", "wn"), False: ("m_e", "m", "k")}  # modal form: wn for the stiffness
_FIELDS = {"m_e": "end_effector_mass", "m": "mass", "wn": "natural_frequency", "k": "stiffness"}
#: Stribeck velocities at which a missing Stribeck effect (fs = fc) is looked for [m/s]
STRIBECK_VS = (3e-4, 3e-3, 3e-2)


def _candidates(model, varying) -> list:
    """[(label, [names])]: the held quantities of ``model`` that can be tested (fs without a Stribeck excess: apart,
    :func:`_stribeck_columns`)."""
    out = []
    plant = model.plant
    if hasattr(plant, "modal"):
        for name in PLANT_HELD[bool(plant.modal)]:
            if name not in varying and getattr(plant, _FIELDS.get(name, ""), None) is not None:
                out.append((name, [name]))
    values = model.friction.values()
    laws = model.laws if isinstance(model.thermal, ModelI) else {}
    for name in FRICTION_HELD:
        if name in laws:
            continue  # below, with the other laws held whole
        if values.get(name) is None or name in varying or name == "fs" and EXCESS in varying:
            continue
        if name in ("fs", "vs") and not _has_excess(model):
            continue  # no Stribeck excess: vs does nothing, and fs is tested apart
        out.append((name, [name]))
    for name, law in laws.items():  # a law held whole (e.g. at the initial model's, for lack of information)
        coefs = [f"{name}.{c}" for c in law.coefficient_names()]
        if coefs and not any(c in varying for c in coefs):
            out.append((name, coefs))
    return out


def _has_excess(model) -> bool:
    if isinstance(model.thermal, ModelI) and "fs" in model.laws:
        return True
    values = model.friction.values()
    return values.get("fs") is not None and values.get("fc") is not None and values["fs"] > values["fc"]


def _score(r, J, cols, s2tau, floor=False):
    """(statistic, degrees of freedom) of the score test of the held columns ``cols`` given the fitted ``J``.
    ``floor``: the one held value is at the lower end of its domain (sigma2 = 0): only a move up contradicts it,
    so a score pointing down counts as none (and one pointing up as half the two-sided p, by the caller)."""
    if J.shape[1]:
        scale = np.linalg.norm(J, axis=0)
        scale[scale == 0] = 1.0
        Q, _ = np.linalg.qr(J / scale)
        cols = cols - Q @ (Q.T @ cols)
    norms = np.linalg.norm(cols, axis=0)
    keep = norms > 1e-9 * max(float(np.max(norms, initial=0.0)), 1e-300)
    if not keep.any():
        return 0.0, 0
    if floor and cols.shape[1] == 1 and float(cols[:, 0] @ r) > 0:  # the data would move it below its floor
        return 0.0, 1
    U, S, _ = np.linalg.svd(cols[:, keep] / norms[keep], full_matrices=False)
    U = U[:, S > 1e-8 * S[0]]
    g = U.T @ r
    return float(g @ g) / s2tau, U.shape[1]


def _advice(label, dof) -> str:
    if label in PLANT_UNITS:
        return f"try --free {label} (free=[\"{label}\"])"
    if label == "fs":
        return "fit a Stribeck effect (add fs,vs to --parameters, from a start with fs > fc)"
    return f"fit it (add {label} to --parameters{', with fs' if label == 'vs' else ''})"


def _stribeck_columns(res, varying, traces, rtol):
    """The sensitivities to fs at fs = fc (a Stribeck effect the model does not have) at each of STRIBECK_VS: the
    model's output is the same at any vs there, the direction in which fs would move it is not."""
    model = res.model
    values = model.friction.values()
    fc_law = model.laws.get("fc") if isinstance(model.thermal, ModelI) else None
    if not hasattr(model.friction, "vs") or _has_excess(model) or "fs" in varying or EXCESS in varying \
            or values.get("fc") is None and fc_law is None:
        return None
    cols = []
    for vs in STRIBECK_VS:
        if fc_law is None:
            m, names, scale = model.with_friction(fs=values["fc"], vs=vs), ["fs"], np.ones(1)
        else:  # fs following fc's law (fs = fc at every temperature): the direction of its level
            m = dataclasses.replace(model, friction=dataclasses.replace(model.friction, fs=None, vs=vs),
                                    thermal=ModelI({**model.laws, "fs": fc_law}))
            names = [f"fs.{c}" for c in fc_law.coefficient_names()]
            c = np.array(fc_law.coefficients(), float)
            scale = np.r_[c[0], np.zeros(len(c) - 1)] if fc_law.kind == "exp" else c
        # the fs columns alone: a column does not depend on which others are computed with it, and the fit's
        # own columns would triple the sensitivity equations of each of these runs (15 % of a freed-mass fit)
        theta = np.array([get_value(m, n) for n in names], float)
        _, J = Problem(m, names, traces, rtol=rtol, parallel=len(traces) > 1).evaluate(theta, jac=True)
        if J is None:
            return None
        cols.append(J @ scale)
    return np.column_stack(cols)


def held_tests(res, experiments, measurement, rtol=1e-8, inadequate=False, data=None, heldout=()) -> list:
    """The score test of every held value of the fit ``res``: [{name, value, statistic, dof, p_value,
    contradicted, message, tried}], most contradicted first. Empty where the model cannot be evaluated there. The
    contradicted values are tried (a refit with each freed: advice.py), and where the fit is ``inadequate`` the
    held values whose direction explains most of the misfit too, up to TRY_AT_MOST refits in all; each refit is
    scored out of sample on ``heldout`` (runs of ``data``) where there are any."""
    varying = [p.name for p in res.parameters.varying]
    if not res.n_points:
        return []
    candidates = _candidates(res.model, set(varying))
    held_names = [n for _, names in candidates for n in names]
    traces = make_traces(experiments, res.model, measurement)
    theta = np.array([get_value(res.model, n) for n in varying + held_names], float)
    problem = Problem(res.model, varying + held_names, traces, rtol=rtol, parallel=len(traces) > 1)
    r, J = problem.evaluate(theta, jac=True)
    if r is None:
        return []
    n, p = J.shape[0], len(varying)
    dof = max(n - p - measurement.offsets_in(traces), 1)
    s2tau = float(r @ r) / dof * float(res.statistics.get("variance_inflation", 1.0))
    groups, k = [], p
    for label, names in candidates:
        groups.append((label, names, J[:, k:k + len(names)],
                       get_value(res.model, names[0]) if len(names) == 1 else None))
        k += len(names)
    stribeck = _stribeck_columns(res, varying, traces, rtol)
    if stribeck is not None:
        groups.append(("fs", ["fs"], stribeck, res.model.friction.values().get("fc")))
    out = []
    for label, names, cols, value in groups:
        floor = value == 0.0 and cols.shape[1] == 1  # at the lower end of its domain: one-sided
        stat, df = _score(r, J[:, :p], cols, s2tau, floor)
        if df:
            out.append({"name": label, "value": value, "statistic": stat, "dof": df,
                        "p_value": float(special.chdtrc(df, stat)) * (0.5 if floor and stat > 0 else 1.0),
                        "misfit_share": stat * s2tau / max(float(r @ r), 1e-300), "_columns": cols, "_J": J[:, :p],
                        "_names": names})
    for i, t in enumerate(out):  # held values that move the data the same way (m and m_e on a modal plant): one
        t["same_as"] = next((u["name"] for u in out[:i] if u["dof"] == t["dof"]
                             and abs(u["statistic"] - t["statistic"]) <= 1e-6 * max(t["statistic"], 1e-300)), None)
    for t in out:
        t["contradicted"] = bool(t["p_value"] < LEVEL / len(out) and t["misfit_share"] >= MATERIAL)
    order = {t["name"]: i for i, t in enumerate(out)}
    out = sorted(out, key=lambda t: (t["same_as"] is not None, t["p_value"], order[t["name"]]))
    to_try = [t for t in out if t["contradicted"] and t["same_as"] is None]
    if inadequate:
        to_try += sorted((t for t in out if t["same_as"] is None and not t["contradicted"]),
                         key=lambda t: -t["misfit_share"])
    outside = OutOfSample(res, experiments, measurement, data, heldout) if to_try and heldout else None
    for i, t in enumerate(to_try):
        # the advice is tried before it is said (advice.py): a refit from the optimum with the value freed, scored
        # on the fit runs and out of sample
        t["tried"] = tried(res, t, traces, r, rtol, STRIBECK_VS, outside) if i < TRY_AT_MOST else None
        if t["tried"] is not None and not holds(t["tried"]):
            t["contradicted"] = False
    primary = {t["name"]: t for t in out}
    for t in out:  # a value that moves the data as another does follows that one's verdict
        if t["same_as"] is not None:
            t["contradicted"] = primary[t["same_as"]]["contradicted"]
        t["message"] = _message(t, out, stribeck is not None, res)
    return out


def _rmses(before, after, unit) -> str:
    return f"{amount(before, unit)} -> {amount(after, unit)}"


def _freeing(t) -> str:
    """What a refit frees, in words: "a Stribeck effect" (fs at fc, with vs), else the held value's name."""
    return "a Stribeck effect" if t["name"] == "fs" and t["dof"] > 1 else t["name"]


def _gain_text(trial, res, what) -> str:
    """A tried refit's measured gain, out of sample first where it was scored there: "freeing m_e lowers the
    held-out RMSE 23.16 nm -> 20.54 nm (fit runs 24.8 nm -> 20.7 nm; a refit of 12 evaluations)"."""
    fit_runs = _rmses(res.rmse, trial["rmse_after"], res.unit)
    n = trial["evaluations"]
    if "heldout_gain" not in trial:
        return f"freeing {what} lowers the RMSE on the fit runs {fit_runs} (a refit of {n} evaluations; " \
               f"{trial['basis']})"
    changed = _rmses(trial["heldout_before"], trial["heldout_after"], res.unit)
    return f"freeing {what} lowers the held-out RMSE {changed} (fit runs {fit_runs}; a refit of {n} evaluations)"


def _how(trial) -> str:
    """How a value was tried: a refit, or one Gauss-Newton step measured by an exact run (advice.STEP_BELOW)."""
    return ("a Gauss-Newton step with it free (its gain measured by an exact run, as the linearization predicts it)"
            if trial.get("stepped") else "a refit with it free")


def _not_worth(trial, res) -> str:
    """Why a tried refit's gain is not worth a parameter (advice.holds), measured: too small on the fit runs, or
    not held out of sample."""
    fit_runs = f"{_rmses(res.rmse, trial['rmse_after'], res.unit)}, {100 * trial['gain']:.2g} % of the misfit"
    if trial["gain"] < MATERIAL:
        return f"{_how(trial)} lowers the RMSE on the fit runs only {fit_runs}, less than {100 * MATERIAL:g} " \
               f"%: not contradicted"
    if "heldout_gain" not in trial:  # (tried because the fit is not adequate; the score test does not single it out)
        return f"a refit with it free lowers the RMSE on the fit runs {fit_runs} ({trial['basis']})"
    return (f"a refit with it free, which lowers the RMSE on the fit runs {fit_runs}, changes the held-out RMSE "
            f"{_rmses(trial['heldout_before'], trial['heldout_after'], res.unit)} ({100 * trial['heldout_gain']:.2g} "
            f"% of its misfit): the gain does not hold out of sample; not contradicted")


def _message(t, out, stribeck, res) -> str:
    """What is said of one held value: contradicted, with the advice and the gain its refit measured; not
    contradicted, with why (the score alone, or a refit that gained too little)."""
    what = f"{t['name']} held at {t['value']:.4g}" if t["value"] is not None else f"{t['name']}'s law held"
    if t["name"] == "fs" and stribeck:
        what = "fs held at fc (no Stribeck effect)"
    p_text = ("p < 1e-12" if t["p_value"] < 1e-12 else f"p = {t['p_value']:.2g}") + \
        f", {100 * t['misfit_share']:.2g} % of the misfit by the linearization"
    also = [u["name"] for u in out if u["same_as"] == t["name"]]
    also = f" (or {', '.join(also)}: the same direction in these data)" if also else ""
    trial = t.get("tried")
    if trial is not None:
        if t["contradicted"]:
            return f"{what} is contradicted by the data ({p_text}){also}: {_advice(t['name'], t['dof'])}; " \
                   f"{_gain_text(trial, res, _freeing(t))}"
        return f"{what}: the score test points away from it ({p_text}){also}, but {_not_worth(trial, res)}"
    if t["contradicted"]:
        return (f"{what} is contradicted by the data ({p_text}){also} (not tried: only the {TRY_AT_MOST} most "
                f"contradicted values are refitted)")
    return f"{what}: not contradicted by the data ({p_text}){also}"


#: the stated prior range of a law held for lack of information: its level within a factor PRIOR_FACTOR either way
#: (95 %), as a normal prior on the law's log scale
PRIOR_FACTOR = 3.0


def _consider(res, tests, secants=None):
    """The fitted parameters' covariance with the uncertainty of the laws held for lack of information added (a
    consider covariance): each held law's level, within a factor PRIOR_FACTOR either way (95 %), shifts the fitted
    parameters by G = -J^+ j (j: the sensitivity to the law's log scale), so cov += G G^T sd^2 -- or, for a constant
    held with its range (``secants``: name -> the shifts of refits with it held at the range's two ends, each end
    1.96 standard deviations out), by those shifts: cov += d d^T / 1.96^2, half from each end. Intervals,
    standard errors and correlations are updated; the report says what was included."""
    varying = res.parameters.varying
    se = np.array([p.stderr for p in varying], float)
    if not varying or not np.all(np.isfinite(se)) or res.correlation.shape != (len(varying),) * 2:
        return
    cov = np.nan_to_num(res.correlation) * np.outer(se, se)
    sd = math.log(PRIOR_FACTOR) / 1.959964
    for t in tests:
        if len((secants or {}).get(t["name"]) or ()) == 2:  # refits at its range's ends (model_i.py): the shifts
            for shift in secants[t["name"]]:                 # to them as 1.96 standard deviations, half each
                cov = cov + np.outer(shift, shift) / (2 * 1.959964 ** 2)
            continue
        law = res.model.laws[t["name"]]
        c = np.array(law.coefficients(), float)
        scale = np.r_[c[0], np.zeros(len(c) - 1)] if law.kind == "exp" else c
        j = t["_columns"] @ scale
        G = -np.linalg.lstsq(t["_J"], j, rcond=None)[0]
        cov = cov + np.outer(G, G) * sd ** 2
    se_new = np.sqrt(np.maximum(np.diag(cov), 0.0))
    tq = float(special.stdtrit(max(res.statistics.get("effective_samples", 1e6) - len(varying), 1.0), 0.975))
    for par, s in zip(varying, se_new):
        par.stderr = float(s)
        if par.positive and par.value > 0:
            f = math.exp(min(tq * s / par.value, 700.0))
            par.ci95 = (par.value / f, par.value * f)
        else:
            par.ci95 = (par.value - tq * s, par.value + tq * s)
    with np.errstate(invalid="ignore", divide="ignore"):
        res.correlation = cov / np.outer(se_new, se_new)
    grown = max(se_new / np.where(se > 0, se, np.inf))
    ranges = res.details.get("held_ranges") or {}
    grown_text = f"standard errors up to {grown:.3g} times those with {'it' if len(tests) == 1 else 'them'} held exactly"
    for name in (t["name"] for t in tests if t["name"] in ranges):
        span = ranges[name]
        lacking = name in (res.details.get("held_for_lack_of_information") or ())
        free = span.get("free_in_profile") or []
        source = ("where the per-temperature fits' misfit, profiled over it, rises by 3.84 in chi-square"
                  + (f", {', '.join(free)} free at each temperature there" if free else "")
                  if span["from"] == "profile" else f"a stated factor {PRIOR_FACTOR:g} either way")
        res.warnings.append(f"{name} {'could not be determined and ' if lacking else ''}is held where the joint "
                            f"refinement left it ({span['value']:.4g}); its range, "
                            f"{span['low']:.4g} to {span['high']:.4g} (95 %: {source}), reaches the other intervals "
                            f"through refits with it held at both ends: {grown_text}")
    others = [t["name"] for t in tests if t["name"] not in ranges]
    if others:
        one = len(others) == 1
        res.warnings.append(f"{', '.join(others)} could not be determined and {'is' if one else 'are'} held at the "
                            f"initial model's law; the intervals include {'its' if one else 'their'} level within a "
                            f"stated factor {PRIOR_FACTOR:g} either way (95 %): {grown_text}")
    res.details["considered"] = {"parameters": [t["name"] for t in tests], "prior_factor": PRIOR_FACTOR}


def _tried_text(tests, res) -> str:
    """The refits tried, with their measured gains, for the not-adequate warning: what would help and what not."""
    out = []
    for t in tests:
        trial = t.get("tried")
        if trial is None or t["contradicted"]:  # (a contradicted value is said with its gain in its own warning)
            continue
        what = _freeing(t)
        if holds(trial):
            out.append(f"{_gain_text(trial, res, what)} ({_advice(t['name'], t['dof'])})")
        elif trial["gain"] < MATERIAL:
            by = "; a Gauss-Newton step, measured by an exact run" if trial.get("stepped") else ""
            out.append(f"freeing {what} removes {100 * trial['gain']:.2g} % of the misfit (less than "
                       f"{100 * MATERIAL:g} %: not worth a parameter{by})")
        else:
            out.append(f"freeing {what} removes {100 * trial['gain']:.2g} % of the misfit on the fit runs but only "
                       f"{100 * trial['heldout_gain']:.2g} % on the held-out runs (RMSE "
                       f"{_rmses(trial['heldout_before'], trial['heldout_after'], res.unit)}): the gain does not hold "
                       f"out of sample, not worth a parameter")
    return ", ".join(out)


def _refit_record(trial) -> dict:
    """A tried refit in the results JSON: its gain and RMSE on the fit runs, the basis it was scored out of sample
    on, and there the RMSE before and after."""
    if not trial:
        return {}
    out = {"refit_gain": trial["gain"], "refit_rmse": trial["rmse_after"], "refit_basis": trial["basis"],
           "refit_holds": holds(trial)}
    if "heldout_gain" in trial:
        out.update(refit_heldout_gain=trial["heldout_gain"], heldout_rmse=trial["heldout_before"],
                   refit_heldout_rmse=trial["heldout_after"])
    return out


def with_held_tests(res, experiments, measurement, rtol=1e-8, data=None, heldout=()):
    """``res`` with ``fit_quality["held"]``; a contradicted held value makes the fit not adequate and is said
    first in its warnings (second, after the residuals' own "not adequate", where they are far above the noise).
    The refits that try the advice are scored on the held-out runs ``heldout`` of ``data`` where there are any."""
    secants = res.details.pop("_secants", None)  # internal to the consider step below
    if res.fit_quality is None:
        return res
    if res.details.get("refined") is False:  # not at an optimum: the residuals are not orthogonal to the fit's
        res.fit_quality["held"] = None
        return res
    inadequate = res.fit_quality["adequate"] is False
    with counting() as spent:  # the tests' evaluations and their refits are the fit's too
        tests = held_tests(res, experiments, measurement, rtol, inadequate, data, heldout)
    res.nfev, res.njev = res.nfev + spent.nfev, res.njev + spent.njev
    res.fit_quality["held"] = [{**{k: t[k] for k in ("name", "value", "statistic", "dof", "p_value", "misfit_share",
                                                     "contradicted")}, **_refit_record(t.get("tried"))} for t in tests]
    bad = [t for t in tests if t["contradicted"] and t["same_as"] is None]
    lack = [t for t in tests if t["name"] in (res.details.get("held_for_lack_of_information") or ())
            or t["name"] in (res.details.get("held_ranges") or {})]
    if lack:
        _consider(res, lack, secants or {})
    gains = _tried_text(tests, res)
    if inadequate and gains and res.warnings and res.warnings[0].startswith("the fit is not adequate"):
        res.warnings[0] += f"; tried: {gains}"
    if bad:
        # after the residuals' own verdict where that already says not adequate (a model far off: the held
        # directions then share out a misfit they do not all cause), else first
        at = 1 if res.fit_quality["adequate"] is False and res.warnings and \
            res.warnings[0].startswith("the fit is not adequate") else 0
        if res.fit_quality["adequate"] is None:  # one verdict: not adequate, on the held values alone
            res.fit_quality["verdict_basis"] = "held values"
            res.warnings[:] = [w for w in res.warnings if not w.startswith("adequacy unknown")]
            n_bad = sum(1 for t in tests if t["contradicted"])  # (as the header counts them: result.py)
            res.warnings.insert(0, f"the fit is not adequate: {n_bad} held value(s) contradicted by the data "
                                   f"(below); its residuals are not held against the noise, which cannot be estimated "
                                   f"from these data ({res.fit_quality.get('why')})")
            at = 1
        res.fit_quality["adequate"] = False
        res.warnings[at:at] = [t["message"] for t in bad]
    return res


__all__ = ["held_tests", "with_held_tests", "LEVEL"]
