"""Model I with laws of temperature and load, identified from force runs at several loads and temperatures
(docs/identification.md#laws-of-temperature-and-load): what ``identify`` runs where the initial model's laws depend
on the load.

1. **Per-condition fits**: at each (temperature, load) of the fit runs, the law parameters' values (and the
   constants named in ``parameters``) fitted as numbers on that condition's runs, each run's offset profiled out as
   the policy says, by the core's exact stepping (measurements/force_load.py).
2. **Laws through them**: each law fitted through the estimates (weighted by their standard errors), a law of load's
   form chosen among the candidates by AICc there (identification/load_kinds.py).
3. **Joint refinement** of every coefficient on all runs (identification/load_fit.py), the leading forms compared
   there by AICc on the effective samples; the best kept.

Where the per-condition fits are not determined (a relative standard error above DETERMINED at a condition, a fit
that failed, or too few conditions for the laws' coefficients), the joint fit starts from the given laws, and the
candidates are started through the given laws' values at the conditions: the forms are still compared on all runs.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._lazy import lazy
from ..errors import ComputationError, InputError
from ..fitting.uncertainty import inflation_of
from ..measurements.force_load import run_load, stepped_force
from ..models import Model, ModelI
from ..models.load_laws import LoadLaw, load_laws
from .load_fit import LoadFit, centred, fit_load_laws
from .load_kinds import CHECKED, effective_aicc, form_of, law_value, ranked

optimize = lazy("scipy.optimize")

#: a per-condition estimate whose standard error exceeds this fraction of its value is not determined
DETERMINED = 0.1
#: a form with more coefficients than the kept one is taken where its AICc on all runs is lower by more than this;
#: one with fewer, where it is higher by less (the simpler preferred within it, as Model I's kinds: laws.py)
PREFER_SIMPLER = 2.0
#: a static level the start's laws put at or below the Coulomb level starts this factor above it
STATIC_ABOVE = 1.2
#: two runs whose temperatures differ by less than this [C] and whose loads by less than LOAD_SAME of the larger are
#: at one condition
TEMPERATURE_SAME, LOAD_SAME = 0.05, 1e-3


def conditions(runs) -> list:
    """The fit runs grouped by condition: [(temperature, load, [runs])], in temperature then load order.

    Parameters
    ----------
    runs : list of ForceExperiment
        The fit runs, each with its load.

    Returns
    -------
    list of tuple
    """
    groups = []
    for e in sorted(runs, key=lambda e: (float(e.temperature), abs(float(e.load)))):
        T, L = float(e.temperature), float(e.load)
        for g in groups:
            if abs(g[0] - T) < TEMPERATURE_SAME and abs(abs(g[1]) - abs(L)) <= LOAD_SAME * max(abs(g[1]), abs(L)):
                g[2].append(e)
                break
        else:
            groups.append((T, L, [e]))
    return groups


def _start_at(model: Model, T: float, load: float) -> Model:
    """The model of numbers a condition's fit starts from: the laws' values at (T, load), a static level the laws
    put below its Coulomb level there raised above it (a start, which the fit then moves)."""
    values = {n: law_value(law, T, load) for n, law in model.laws.items()}
    given = {**model.friction.values(), **values}
    for fs, fc in (("fs", "fc"), ("fs_neg", "fc_neg")):
        if fs in values and given.get(fc) is not None and values[fs] <= given[fc]:
            values[fs] = STATIC_ABOVE * given[fc]
    return dataclasses.replace(model, thermal=None, friction=model.friction.with_values(**values))


def fit_condition(model: Model, T: float, load: float, runs, names, offset: str) -> dict:
    """The values of ``names`` fitted as numbers on one condition's runs (module, step 1).

    Parameters
    ----------
    model : Model
        The model whose laws give the start at (T, load).
    T, load : float
        The condition.
    runs : list of ForceExperiment
        Its runs.
    names : list of str
        The friction parameters fitted.
    offset : {"per-experiment", "shared", "none"}
        The offset policy.

    Returns
    -------
    dict
        ``temperature``, ``load``, ``files``, ``values`` and ``stderr`` (name -> float), ``rmse``, ``nfev`` and
        ``converged``.
    """
    at = _start_at(model, T, load)
    x0 = np.array([float(at.friction.values()[n]) for n in names])
    measured = np.concatenate([np.asarray(e.force, float) for e in runs])
    sizes = [len(e.time) for e in runs]
    bad = 1e3 * float(np.std(measured)) + 1.0

    def evaluate(x):
        try:
            m = dataclasses.replace(at, friction=at.friction.with_values(**dict(zip(names, map(float, x)))))
            out = [stepped_force(m, e, names) for e in runs]
        except InputError:  # a step where fs falls below fc, say: rejected
            return np.full(measured.size, bad), np.zeros((measured.size, x.size))
        return centred(np.concatenate([o[0] for o in out]) - measured, np.vstack([o[1] for o in out]), sizes, offset)
    lower = np.where(x0 > 0, 0.0, -np.inf)
    res = optimize.least_squares(lambda x: evaluate(x)[0], x0, jac=lambda x: evaluate(x)[1], x_scale="jac",
                                 bounds=(lower, np.inf), method="trf", max_nfev=100)
    r, J = evaluate(res.x)
    tau, _ = inflation_of(r, sizes)
    dof = max(r.size - x0.size - (len(runs) if offset == "per-experiment" else offset == "shared"), 1)
    cov = float(r @ r) / dof * max(tau, 1.0) * np.linalg.pinv(J.T @ J)
    se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    return {"temperature": T, "load": load, "files": [e.file for e in runs],
            "values": dict(zip(names, map(float, res.x))), "stderr": dict(zip(names, map(float, se))),
            "rmse": float(np.sqrt(np.mean(r ** 2))), "nfev": int(res.nfev),
            "converged": bool(res.status > 0 and not np.all(r == bad))}


def undetermined(per: list, laws: dict) -> str:
    """Why the per-condition fits do not determine the laws ("" where they do).

    Parameters
    ----------
    per : list of dict
        The per-condition fits (:func:`fit_condition`).
    laws : dict
        The laws fitted through them: name -> law.

    Returns
    -------
    str
    """
    # the largest form's coefficients (the temperature law's, k and the interaction), and two more for its AICc
    most = max(len(law.base.coefficients()) + 2 if isinstance(law, LoadLaw) else len(law.coefficients())
               for law in laws.values())
    if len(per) < most + 2:
        return (f"{len(per)} conditions, fewer than the {most + 2} the largest form's {most} coefficients and its "
                f"AICc need")
    for c in per:
        if not c["converged"]:
            return f"the fit at {c['temperature']:.4g} C, load {c['load']:.4g} did not converge"
        for n, v in c["values"].items():
            se = c["stderr"][n]
            if not (math.isfinite(se) and se <= DETERMINED * abs(v)):
                return (f"{n} at {c['temperature']:.4g} C, load {c['load']:.4g}: {v:.4g} +- {se:.2g}, above "
                        f"{100 * DETERMINED:g} % of its value")
    return ""




def _ranked_laws(model: Model, per: list, determined: bool) -> dict:
    """Each law's candidates fitted through the per-condition estimates (determined) or through the given law's own
    values at the conditions (unweighted): name -> [(aicc, law)], best first."""
    out = {}
    T, L = np.array([c["temperature"] for c in per]), np.array([c["load"] for c in per])
    for name, law in model.laws.items():
        if determined:
            values = np.array([c["values"][name] for c in per])
            stderr = np.array([c["stderr"][name] for c in per])
        else:
            values = np.array([law_value(law, t, x) for t, x in zip(T, L)])
            stderr = np.full_like(values, max(float(np.std(values)), 1e-12 * max(float(np.max(np.abs(values))), 1.0)))
        out[name] = ranked(law, T, L, values, stderr)
    return out


def _constants_from(model: Model, per: list, free) -> Model:
    """The constants fitted per condition started at their weighted mean over the conditions."""
    values = {}
    for n in free:
        v = np.array([c["values"][n] for c in per])
        w = np.array([1.0 / max(c["stderr"][n], 1e-300) ** 2 for c in per])
        values[n] = float(np.sum(w * v) / np.sum(w)) if np.all(np.isfinite(w)) else float(np.median(v))
    return dataclasses.replace(model, friction=model.friction.with_values(**values)) if values else model


def _score(fit: LoadFit, runs, tau: float, offset: str) -> float:
    n = sum(len(e.time) for e in runs)
    rss = sum(fit.rmse[e.file] ** 2 * len(e.time) for e in runs)
    k = len(fit.names) + {"per-experiment": len(runs), "shared": 1, "none": 0}[offset]
    return effective_aicc(rss, n, k, tau)


def _joint(model, laws, runs, free, offset):
    """The joint fit from ``model`` with ``laws``, or the ComputationError's text."""
    try:
        return fit_load_laws(dataclasses.replace(model, thermal=ModelI(laws)), runs, free, offset)
    except ComputationError as e:
        return str(e)


def chosen_by_joint_fits(model: Model, ranks: dict, runs, free, offset: str, progress=None) -> tuple:
    """The joint refinement from each law's best candidate, then each law's next CHECKED candidates in turn (the
    others at the best so far), kept where their AICc on the effective samples is lower (by PREFER_SIMPLER for a
    form with more coefficients; a simpler one within PREFER_SIMPLER of it is kept) (module, step 3).

    Parameters
    ----------
    model : Model
        The start (its constants).
    ranks : dict
        Name -> [(aicc on the estimates, law)], best first.
    runs : list of ForceExperiment
        The fit runs.
    free : sequence of str
        The constants fitted with the laws.
    offset : str
        The offset policy.
    progress : callable, optional
        Called with a line at each joint fit.

    Returns
    -------
    tuple
        (the best LoadFit, {name: [{"form", "aicc_estimates", "aicc_all", "kept"}]}, the evaluations spent).
    """
    laws = {n: r[0][1] for n, r in ranks.items()}
    if progress:
        progress("Model I with load: the joint refinement on all runs")
    best = _joint(model, laws, runs, free, offset)
    if isinstance(best, str):
        raise ComputationError(best)
    tau, spent = best.correlation_time, best.nfev
    score = _score(best, runs, tau, offset)
    table = {n: [{"form": form_of(r[0][1]), "aicc_estimates": r[0][0], "aicc_all": score, "kept": True}]
             for n, r in ranks.items()}
    for name, rank in ranks.items():
        for est, law in rank[1:1 + CHECKED]:
            if progress:
                progress(f"Model I with load: {name} as {form_of(law)} on all runs")
            trial = _joint(best.model, {**best.model.laws, name: law}, runs, free, offset)
            row = {"form": form_of(law), "aicc_estimates": est, "kept": False}
            if isinstance(trial, str):
                row.update(aicc_all=math.inf, failed=trial)
            else:
                spent += trial.nfev
                row["aicc_all"] = s = _score(trial, runs, tau, offset)
                more = len(law.coefficients()) - len(best.model.laws[name].coefficients())
                if s + PREFER_SIMPLER * np.sign(more) < score:
                    for r in table[name]:
                        r["kept"] = False
                    best, score, row["kept"] = trial, s, True
                    for other, rows in table.items():  # the others' kept forms are now scored with this one
                        for r in rows:
                            r["aicc_all"] = s if r["kept"] else r["aicc_all"]
            table[name].append(row)
    return best, table, spent


def identify_load(runs, init: Model, free=(), offset: str = "per-experiment", progress=None) -> tuple:
    """The laws of temperature and load of ``init`` identified on the fit ``runs`` (module docstring).

    Parameters
    ----------
    runs : list of ForceExperiment
        The fit runs, each with its load and a constant temperature.
    init : Model
        A prescribed-motion Model I model with laws of load, the start.
    free : sequence of str, default ()
        Friction parameters given as numbers, fitted too (per condition, then as constants).
    offset : {"per-experiment", "shared", "none"}, default "per-experiment"
        The offset policy.
    progress : callable, optional
        Called with a line at each stage.

    Returns
    -------
    tuple
        (the LoadFit, the details: ``procedure``, ``conditions``, ``why_joint``, ``forms``, ``nfev``).

    Raises
    ------
    InputError
        A run without its load, a ``free`` name that is not a number of the model.
    ComputationError
        The joint fit failed.
    """
    for e in runs:
        run_load(e)  # each run's load, or one message naming the file
    names = list(init.laws) + list(free)
    groups = conditions(runs)
    per, nfev = [], 0
    for T, L, group in groups:
        if progress:
            progress(f"Model I with load: fitting {', '.join(names)} at {T:.4g} C, load {L:.4g}")
        try:
            per.append(fit_condition(init, T, L, group, names, offset))
        except (ComputationError, ValueError, FloatingPointError) as e:  # a start the solver cannot take: not determined
            per.append({"temperature": T, "load": L, "converged": False, "why": str(e), "files": []})
        nfev += per[-1].get("nfev", 0)
    why = undetermined(per, init.laws)
    start = _constants_from(init, per, free) if not why else init
    ranks = _ranked_laws(start, per if not why else [{"temperature": T, "load": L} for T, L, _ in groups], not why)
    best, forms, spent = chosen_by_joint_fits(start, ranks, runs, free, offset, progress)
    procedure = ("per-condition fits, laws through them, joint refinement" if not why else
                 "joint fit from the given laws (per-condition fits not determined)")
    details = {"procedure": procedure, "why_joint": why, "conditions": [c for c in per if "values" in c],
               "forms": forms, "nfev": nfev + spent, "correlation_time": best.correlation_time}
    return best, details


__all__ = ["identify_load", "conditions", "fit_condition", "undetermined", "chosen_by_joint_fits", "DETERMINED"]
