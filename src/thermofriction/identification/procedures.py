"""Identification procedures (the top layer): a base friction model and the heat model, the result of a fit, and
what Model I (model_i.py) and Model II (model_ii.py) build on: temperature groups, base models, the default fitted
parameters (docs/models.md#thermal-extensions)."""

from __future__ import annotations

import copy
import dataclasses
import functools
import math
import os
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from ..errors import ComputationError, InputError
from ..models import LuGre, Model, ModelI
from ..models.sides import STATIC_LEVELS
from ..models.transforms import base_model
from ..measurements import REGISTRY, amount
from ..measurements.displacement import FIT_PARAMETERS as FRICTION_FIT_PARAMETERS
from ..fitting.quality import fit_quality, pooled
from .laws import SAME_TEMPERATURE
from ..fitting.optimiser import FitOutcome, fit
from ..fitting.parameters import EXCESS, Parameters, friction_parameters, get_value, unit_of, with_values
from ..fitting.problem import Problem, counting, in_context
from ..measurements import make_traces
from .result import FitResult
from ..fitting.uncertainty import uncertainty

DEFAULT_FRICTION_PARAMETERS = LuGre.description.fitted["displacement"]  # LuGre's (the paper's)


def default_fit_parameters(model: Model) -> list:
    """The default fitted parameters of ``model``'s friction model (the ``fit_parameters`` of the measurement its
    plant is fitted to: displacement's, FRICTION_FIT_PARAMETERS, for an actuator; force's for prescribed motion),
    less those it leaves unset or at zero, and GMS's C without a Stribeck effect (:func:`no_stribeck_rate`);
    under Model I, those with a law (if any has one)."""
    table = next((m.fit_parameters for m in REGISTRY.values() if model.plant.type in m.plants),
                 FRICTION_FIT_PARAMETERS)
    names = table.get(model.friction.model, DEFAULT_FRICTION_PARAMETERS)
    laws = model.laws if isinstance(model.thermal, ModelI) else {}
    values = model.friction.values()
    if "fs" in model.friction.law_targets and values.get("fs") in (None, values.get("fc")) and "fs" not in laws:
        values = {k: v for k, v in values.items() if k not in ("fs", "vs")}  # no Stribeck effect to fit
        values.pop("C", None)  # GMS's rate towards the Stribeck curve (no_stribeck_rate)
    names = [n for n in names if n in laws or (values.get(n) or 0.0) > 0.0]
    with_law = [n for n in names if n in laws]
    return with_law or names


def no_stribeck_rate(model, params) -> list:
    """GMS's C is the rate at which slipping elements follow the Stribeck curve g(v): where there is none (fs = fc,
    no law on fs), a slipping element sits at its capacity w_i g and C changes nothing, so no data determine it
    (a fit of it runs off, to 1e-10 or 6e17, issue 40 item 7). The default holds it; a warning naming C says
    so, whether it was held or fitted."""
    values = model.friction.values()
    if "C" not in model.friction.law_targets or values.get("fs") not in (None, values.get("fc")) or "fs" in model.laws:
        return []
    fitted = "C" in params and params["C"].vary
    how = "was fitted, but" if fitted else f"is held at {values['C']:.4g} N m/s:"
    return [f"'C' (the rate at which slipping GMS elements follow the Stribeck curve) {how} with no Stribeck "
            f"effect (fs = fc) a slipping element stays at its capacity and C changes nothing, so these data "
            f"cannot determine it{'; hold it' if fitted else ''} (fit fs and vs to bring it in)"]


def counted(function):
    """``function`` (which returns a FitResult) with the result's ``nfev`` and ``njev`` every model evaluation made
    while it ran: its fits', their multi-starts', the per-temperature and reference fits', scans', profiles', refits'
    (fitting.problem.counting), not only those of the fit the result was made from.

    Parameters
    ----------
    function : callable
        A procedure returning a FitResult.

    Returns
    -------
    callable
        ``function`` whose result's ``nfev`` and ``njev`` are what it spent.
    """
    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        with counting() as spent:
            res = function(*args, **kwargs)
        res.nfev, res.njev = spent.nfev, spent.njev
        return res
    return wrapper


def fit_result(method, model, params, outcome, traces, t0, extra_warnings=(), details=None) -> FitResult:
    """The result of a fit: parameters with their uncertainty, per-experiment quality, warnings."""
    corr, warns, stats = uncertainty(params, outcome, traces, model)
    found = stats.pop("identifiability", [])
    values = {p.name: p.value for p in params.values()}
    fitted = with_values(model, values)
    per, qualities, start = [], [], 0
    for tr in traces:
        n = len(tr.time)
        seg = outcome.r[start:start + tr.n_residuals]
        start += tr.n_residuals
        # the displacement residuals of a trace have their mean (the sensor's zero) removed
        quality = fit_quality(seg[:n], tr.measured)
        qualities.append(quality)
        per.append({"file": tr.name, "temperature": tr.nominal_temperature, "role": tr.role,
                    "rmse_offset_removed": quality["rmse"], "fit_quality": quality})
        if tr.measured_temperature is not None:  # [K], unweighted
            per[-1]["temperature_rmse"] = float(np.sqrt(np.mean(seg[n:] ** 2))) / tr.temperature_weight
    overall = pooled(qualities, [len(tr.time) for tr in traces])
    measurement, unit = traces[0].measurement, traces[0].unit
    first = []
    if overall["adequate"] is None:
        first.append(f"adequacy unknown: {overall['why']}; the residuals ({amount(overall['rmse'], unit)}) cannot be "
                     f"held against it: judge the fit by its error on held-out experiments (validate) instead")
    elif not overall["adequate"]:
        bad = [p["file"] for p, q in zip(per, qualities) if q["adequate"] is False]
        first.append(f"the fit is not adequate: its residuals are {overall['ratio']:.3g} times the measurement "
                        f"noise estimated from the data ({amount(overall['rmse'], unit)} against "
                        f"{amount(overall['noise'], unit)}, where a right model gives at most "
                        f"{overall['threshold']:.3g} times on these samples; not adequate in {len(bad)} of "
                        f"{len(per)} experiments): "
                        f"the model misses what the data show" + "".join(
                            f"; {c}" for c in measurement.checks(model, traces)))
    cost = float(outcome.r @ outcome.r)
    warns += _unsupported_excess(params, corr, unit) + no_stribeck_rate(fitted, params)
    return FitResult(method=method, model=fitted, parameters=params, correlation=corr, cost=cost,
                     rmse=math.sqrt(cost / len(outcome.r)), n_points=len(outcome.r), nfev=outcome.nfev,
                     njev=outcome.njev, starts=outcome.starts, wall_time=time.perf_counter() - t0,
                     success=outcome.success, message=str(outcome.message), experiments=per,
                     warnings=first + list(extra_warnings) + warns, statistics=stats, details=details or {},
                     fit_quality=overall, unit=unit, measurement=measurement.name,
                     removed=measurement.removed, identifiability=found)


def unrefined_result(method, model, params, experiments, measurement, t0, per_fits, message, warns=(), details=None,
                     rtol=1e-8) -> FitResult:
    """The result of a procedure that stops before its joint refinement (``refine=False``): the model it built
    (laws through per-temperature fits) held against all the experiments, with the residuals, the noise check
    and the Jacobian there, so that its RMSE, adequacy and intervals (linearized where it stopped, not at an
    optimum) are the data's, as a refined fit's are. ``per_fits``: the fits it was built from (their
    evaluations, and its success: every one of them converged)."""
    traces = make_traces(experiments, model, measurement)
    names = [p.name for p in params.varying]
    theta = np.array([p.value for p in params.varying], float)
    r, J = Problem(model, names, traces, rtol=rtol, parallel=len(traces) > 1).evaluate(theta, jac=True)
    if r is None:
        raise ComputationError(f"{method}: the model built without the joint refinement cannot be simulated on "
                               f"the fit experiments; run with the refinement")
    failed = [f.method for f in per_fits if not f.success]
    success = not failed
    if failed:
        message = f"{message}; not converged: {', '.join(failed)}"
    outcome = FitOutcome(theta, r, J, sum(f.nfev for f in per_fits) + 1, sum(f.njev for f in per_fits) + 1,
                         success, message, 0, time.perf_counter() - t0)
    return fit_result(method, model, params, outcome, traces, t0, list(warns) + [
        "no joint refinement (refine=False): the laws pass through the per-temperature estimates; the intervals "
        "are linearized there, not at an optimum of all the data, and the held values are not tested"],
        dict(details or {}, refined=False))


def fitted_names(init: Model, parameters) -> list:
    """The friction parameters Model I or II fits: ``parameters`` (names of the initial model's friction
    parameters, with a law or not), default :func:`default_fit_parameters`."""
    if parameters is None:
        return default_fit_parameters(init)
    if isinstance(parameters, Parameters) or isinstance(parameters, str):
        raise InputError("parameters= for Model I and II takes a list of friction parameter names, e.g. "
                         "['sigma0', 'sigma1', 'fc', 'fs', 'vs']")
    known = [f.name for f in dataclasses.fields(init.friction) if f.name != "v_smooth"]
    names = list(dict.fromkeys(parameters))
    for n in names:
        if n not in known:
            raise InputError(f"parameters: '{n}' is not a parameter of the {init.friction.model} friction model "
                             f"(one of: {', '.join(known)})")
    if not names:
        raise InputError("parameters: name at least one friction parameter")
    return names


def stribeck_start(model: Model, names) -> Model:
    """``model`` with a Stribeck excess to start from where ``names`` fit fs and it has none (fs = fc): fs a
    tenth above fc, vs 1 mm/s where it has none (a fit cannot start an excess from zero in log space)."""
    values = model.friction.values()
    if "fs" not in names or "fs" in model.laws or (values.get("fs") or 0.0) > (values.get("fc") or math.inf):
        return model
    if values.get("fc") is None:
        raise InputError("fs can be fitted with fc: give fc a value (or a law)")
    vs = values.get("vs")
    return model.with_friction(fs=1.1 * values["fc"], vs=vs if vs and vs > 0 else 1e-3)


def held_at(init, T, base, held):
    """``base`` with the ``held`` parameters at the initial model's law at ``T``; a held static level (fs, fs_neg)
    keeps the initial model's ratio to its Coulomb level where that is fitted: fs >= fc is a relation, and the
    start's fs 0.33 beside a fitted fc of 0.78 was refused as an error in the user's file."""
    start, values = base_model(init, T).friction.values(), base.friction.values()
    new = {n: start[n] for n in held}
    for level, coulomb in STATIC_LEVELS:
        if level in new and coulomb not in held and values.get(coulomb) is not None and start.get(coulomb):
            new[level] = values[coulomb] * start[level] / start[coulomb]
    return base.with_friction(**new)


def levels_held_as_ratios(init, names, new_laws, Ts) -> dict:
    """A static level neither fitted nor with a law (fs, fs_neg held as a number) as a law: its Coulomb level's
    times the initial model's ratio, held (a number would fall below the fitted law where that rises)."""
    start = base_model(init, float(Ts.mean())).friction.values()
    return {level: new_laws[coulomb].scaled(start[level] / start[coulomb])
            for level, coulomb in STATIC_LEVELS
            if level not in names and level not in init.laws and coulomb in new_laws
            and start.get(level) is not None and start.get(coulomb)}


@counted
def fit_friction(experiments, model: Model, parameters=None, *, method="base", measurement=None, **opts) -> FitResult:
    """Fits the named friction parameters (default sigma0, sigma1, fc) of ``model`` jointly on
    ``experiments``: one set of values shared by all of them.

    Parameters
    ----------
    experiments : list of Experiment
        The experiments fitted (a dataset's ``fit``).
    model : Model
        The initial model.
    parameters : list of str or Parameters, optional
        The parameters fitted; default the friction model's.
    method : str, default "base"
        The method the result names.
    measurement : Measurement, optional
        How the residuals are formed; default the experiments' own, with its default offset policy.
    **opts
        Passed on to ``fit``: ``rtol``, ``starts``, ``seed``, ``max_nfev``, ...

    Returns
    -------
    FitResult

    Raises
    ------
    InputError
        Bad arguments (an unknown parameter name, no parameter to fit, an initial value outside its bounds),
        named.
    ComputationError
        The fit failed (SolverError where a simulation stopped).
    """
    t0 = time.perf_counter()
    if not isinstance(parameters, Parameters):  # fs named on a model without an excess: one to start from
        parameters = parameters or default_fit_parameters(model)
        model = stribeck_start(model, parameters)
    traces = make_traces(experiments, model, measurement)
    if isinstance(parameters, Parameters):
        params = parameters
    else:
        params = friction_parameters(model, parameters)
    outcome = fit(model, params, traces, **opts)
    params, outcome, notes = stribeck_in_range(experiments, model, params, traces, outcome, opts)
    return fit_result(method, model, params, outcome, traces, t0, stribeck_notes(model, params) + notes)


def stribeck_in_range(experiments, model: Model, params: Parameters, traces, outcome, opts) -> tuple:
    """(params, outcome, notes): a fit whose Stribeck velocity ended above every speed of its runs (the
    measurement's ``stribeck_speeds``: force data's) fitted again, by ``opts`` with one start, from its optimum
    with vs inside the runs' speeds; the better optimum by cost kept, and a note where it is the second (its
    starts then counting the first fit's too). Above
    them g(v) stays above fc + (fs - fc)/e on every sample: the fall towards fc is never seen, fc and vs are not
    determined, and a fit from a rough start stayed there (a joint's vs at 5.7 rad/s on runs of at most 1.5 rad/s,
    its cost 37 % above the one from the truth's values, where the fit from vs = 0.13 rad/s lands in 6
    evaluations: issue 42). Its evaluations count in the procedure's (``counted``)."""
    measurement, names = traces[0].measurement, [p.name for p in params.varying]
    if "vs" not in names or not hasattr(measurement, "stribeck_speeds"):
        return params, outcome, []
    vs = float(outcome.theta[names.index("vs")])
    largest, start, unit = measurement.stribeck_speeds(experiments)
    if not vs > largest:
        return params, outcome, []
    again = copy.deepcopy(params)
    for p, value in zip(again.varying, outcome.theta):
        p.value = float(value)
    again["vs"].value = float(min(max(start, again["vs"].min), again["vs"].max))
    if opts.get("progress"):
        opts["progress"](f"vs ended at {vs:.3g} {unit}, above the runs' speeds: fitting again from {start:.3g} {unit}")
    try:
        second = fit(model, again, traces, **dict(opts, starts=1))
    except ComputationError:  # (the first optimum stands)
        return params, outcome, []
    first_cost, cost = float(outcome.r @ outcome.r), float(second.r @ second.r)
    if not cost < first_cost:
        return params, outcome, []
    return again, dataclasses.replace(second, starts=outcome.starts + second.starts), [
        f"vs ended at {vs:.3g} {unit}, above every speed of the fit runs (at most {largest:.3g} {unit}), where fc "
        f"and vs are not determined (cost {first_cost:.4g}); the fit again from vs = {start:.3g} {unit}, inside "
        f"them, ended lower (cost {cost:.4g}) and is the one kept"]


def _unsupported_excess(params: Parameters, corr, unit) -> list:
    """A fitted Stribeck excess fs - fc the data do not support (within two standard errors of zero): said."""
    names = [p.name for p in params.varying]
    if EXCESS in names:
        x = params[EXCESS]
        if x.stderr is not None and math.isfinite(x.stderr) and x.value < 2 * x.stderr:
            return [f"the data show no Stribeck excess: fs - fc = {x.value:.3g} +- {x.stderr:.3g} {x.unit}, within two "
                    f"standard errors of zero; the fitted map is Coulomb-viscous, and vs says nothing"]
        return []
    if "fs" not in names or "fc" not in params:
        return []
    fs, fc = params["fs"], params["fc"]
    se_fs, se_fc = fs.stderr or 0.0, (fc.stderr or 0.0) if fc.vary else 0.0
    rho = float(corr[names.index("fs"), names.index("fc")]) if fc.vary and np.isfinite(
        corr[names.index("fs"), names.index("fc")]) else 0.0
    se = math.sqrt(max(se_fs ** 2 + se_fc ** 2 - 2 * rho * se_fs * se_fc, 0.0))
    excess = fs.value - fc.value
    if math.isfinite(se) and excess < 2 * se:
        where = unit if unit != "m" else fs.unit  # force data: the residuals' unit (N or N m); else fs's own
        return [f"the data show no Stribeck excess: fs - fc = {excess:.3g} +- {se:.3g} {where}, within two standard "
                f"errors of zero; the fitted map is Coulomb-viscous, and vs says nothing"]
    return []


def stribeck_notes(model: Model, params: Parameters) -> list:
    """A friction model with a Stribeck term whose excess fs - fc is not fitted because the initial model has
    none (fs = fc): said, instead of a result that silently equals Coulomb's."""
    values = model.friction.values()
    if "fs" not in values or "fs" in params or isinstance(model.thermal, ModelI) and "fs" in model.laws:
        return []
    if values.get("fs") in (None, values.get("fc")):
        return [f"fs and vs were not fitted: the initial {model.friction.model} model has no Stribeck excess (fs = fc), "
                f"so the fitted map is Coulomb-viscous; give a start with fs > fc (or --parameters fs,vs) to fit one"]
    return []


DEFAULT_HEAT_PARAMETERS = ("C_th", "R_th", "eta")


@counted
def identify_heat(experiments, init: Model, parameters=None, free=(), **opts) -> FitResult:
    """Fits the lumped thermal model (docs/models.md#self-heating) -- by default C_th, R_th and eta; friction
    parameters named too are fitted jointly -- to the recorded temperatures and displacements.

    The two records have different units and noise, so the fit runs twice: first with each
    record weighted by its range, then with each weighted by its residual scatter at that first
    optimum (so that both carry unit variance, which the intervals assume), from there.
    Without a known heat input (the model's P_ext) the records fix only eta R_th and R_th C_th:
    then one of the three gets an infinite interval and a warning, as it should.

    Parameters
    ----------
    experiments : list of Experiment
        The experiments fitted, with recorded temperatures.
    init : Model
        The initial model, with a [heat] section.
    parameters : list of str, optional
        The parameters fitted: heat parameters (C_th, R_th, eta, T_0) and friction ones; default C_th, R_th,
        eta.
    free : sequence of str, default ()
        Plant parameters fitted too.
    **opts
        Passed on to ``fit``: ``rtol``, ``starts``, ``seed``, ``max_nfev``, ...

    Returns
    -------
    FitResult

    Raises
    ------
    InputError
        Bad arguments (an unknown parameter name, no parameter to fit, an initial value outside its bounds),
        named.
    ComputationError
        The fit failed (SolverError where a simulation stopped).
    """
    if init.heat is None:
        raise InputError("the heat fit needs an initial model with a [heat] section (C_th, R_th, eta guesses)")
    t0 = time.perf_counter()
    traces = make_traces(experiments, init)
    starts = [tr.initial_temperature for tr in traces]
    names = list(parameters or DEFAULT_HEAT_PARAMETERS) + list(free)
    if parameters is None and max(starts) - min(starts) < 0.1:
        # every run starts at one temperature (thermal equilibrium): estimate it with the rest, the
        # displacement pins it far better than a thermometer's first samples (0.3 um/K per cycle)
        names.append("T_0")
        init = dataclasses.replace(init, heat=dataclasses.replace(init.heat, initial_temperature=float(np.mean(starts))))
    if isinstance(parameters, Parameters):
        params = parameters
    else:
        params = Parameters()
        for name in names:
            v = get_value(init, name)
            if name == "T_0":
                params.add(name, v, unit="C")
            else:
                params.add(name, v, min=0.0, max=1.0 if name == "eta" else math.inf, unit=unit_of(init, name))
    for tr in traces:  # first pass: each record by its range
        tr.temperature_weight = max(float(np.ptp(tr.measured)), 1e-12) / max(
            float(np.ptp(tr.measured_temperature)), 1e-3)
    first = fit(init, params, traces, **opts)
    model = with_values(init, dict(zip([p.name for p in params.varying], first.theta)))
    start = 0
    for tr in traces:  # second pass: each record by its residual scatter
        n = len(tr.time)
        seg = first.r[start:start + 2 * n]
        start += 2 * n
        sx = float(np.sqrt(np.mean(seg[:n] ** 2)))
        sT = float(np.sqrt(np.mean(seg[n:] ** 2))) / tr.temperature_weight
        tr.temperature_weight = max(sx, 1e-15) / max(sT, 1e-9)
    for p, v in zip(params.varying, first.theta):
        p.value = float(min(max(v, p.min), p.max))
    outcome = fit(model, params, traces, **dict(opts, starts=1))
    return fit_result("heat", init, params, outcome, traces, t0,
                   details={"temperature_weights_m_per_K": [tr.temperature_weight for tr in traces]})


def along_temperatures(chains, step, *, alone):
    """The per-temperature continuation that Model I and Model II share: ``step(i, carried, first)`` fits the
    i-th temperature group from what its chain carried (the chain's start, then what the previous fit
    returned; ``first`` for a chain's first fit) and returns what the next fit continues from. ``chains``,
    [(indices, start)]: two of them run side by side, one per core; on one core, or where the second chain is
    empty, ``alone`` (indices, start) runs as one chain instead."""
    def run(indices, carried):
        for k, i in enumerate(indices):
            carried = step(i, carried, k == 0)

    if len(chains) > 1 and chains[1][0] and (os.cpu_count() or 1) > 1:
        with ThreadPoolExecutor(max_workers=2, thread_name_prefix="thermofriction-continuation") as executor:
            for future in [executor.submit(in_context(run), *chain) for chain in chains]:
                future.result()
    else:
        run(*alone)


def temperature_groups(experiments):
    """Fit experiments grouped by temperature (SAME_TEMPERATURE, 0.05 C, apart count as one)."""
    exps = sorted(experiments, key=lambda e: e.temperature)
    groups = []
    for e in exps:
        if groups and abs(e.temperature - groups[-1][0].temperature) < SAME_TEMPERATURE:
            groups[-1].append(e)
        else:
            groups.append([e])
    return groups


__all__ = ["counted", "held_at", "levels_held_as_ratios", "fit_friction", "stribeck_in_range", "fit_result", "unrefined_result", "along_temperatures", "base_model", "default_fit_parameters", "friction_parameters", "stribeck_notes", "stribeck_start", "fitted_names",
           "identify_heat", "temperature_groups", "FRICTION_FIT_PARAMETERS", "DEFAULT_FRICTION_PARAMETERS",
           "DEFAULT_HEAT_PARAMETERS"]
