"""The front door of identification: :func:`identify` checks its arguments, asks the data's measurement once,
starts from the right model and runs the method's procedure."""

from __future__ import annotations

import dataclasses
import math
import os
import warnings

import numpy as np

from .. import _args
from ..data.experiments import TEMPERATURE_RANGE, Dataset, run_label
from ..errors import InputError, ThermofrictionError, shorten
from ..measurements import amount, measurement_of
from ..measurements.baseline import baseline_verdict, model_free
from ..measurements.delay import parse_delay
from ..measurements.ripple import check_per_run, has_ripple
from .held import with_held_tests
from .ripple_advice import with_ripple_advice
from .laws import FIT_LAW_KINDS
from .model_i import identify_model_i
from .model_ii import identify_model_ii
from ..fitting.optimiser import one_blas_thread
from ..fitting.problem import counting
from ..models.load_laws import load_laws
from .load_blind import load_findings
from .load_result import identify_with_load
from ..models import Model
from ..models.sides import needs_period
from ..simulation import StepSizeController
from ..fitting.parameters import PLANT_UNITS, Parameters, target_of
from .plant import fit_plant
from ..models.transforms import base_model
from .procedures import default_fit_parameters, fit_friction, identify_heat
from .warm_up import identify_warm_up
from .provenance import stamped
from .result import FitResult
from ..validation import heldout_score
from ..unit_scale import model_unit_warnings

METHODS = ("plant", "base", "model-i", "model-ii", "heat", "warm-up")


#: The most starting points of the multi-start phase: each one simulates every fit experiment
MAX_STARTS = 10_000
#: The most model evaluations of a least-squares stage that max_evaluations may ask for
MAX_EVALUATIONS = 100_000


def _check_arguments(method, reference_temperature, rtol, starts, seed):
    if method not in METHODS:
        raise InputError(f"unknown method {shorten(method)} (one of: {', '.join(METHODS)})")
    _args.whole(starts, "starts", low=1, high=MAX_STARTS)
    _args.whole(seed, "seed", low=0)
    if not 0 < _args.number(rtol, "rtol") < 1:
        raise InputError(f"rtol must be between 0 and 1, got {shorten(rtol)}")
    if reference_temperature is not None:
        if method != "model-ii":
            raise InputError("reference_temperature applies to method 'model-ii' only")
        lo, hi = TEMPERATURE_RANGE
        if not lo <= _args.number(reference_temperature, "reference_temperature", "degC") <= hi:
            raise InputError(f"reference_temperature must be a temperature from {lo:g} to {hi:g} C, "
                             f"got {shorten(reference_temperature)}")


def _checked_laws(laws):
    """laws: {parameter name: a law kind, or a list of kinds to choose from by AICc} (model_i._laws_through)."""
    _args.instance(laws, dict, "laws", "a dict (parameter -> law kind)", none=True)
    for name, kind in (laws or {}).items():
        if not isinstance(name, str):
            _args.refuse("laws", "a dict keyed by parameter names; one key is", name)
        kinds = [kind] if isinstance(kind, str) else kind
        if not (isinstance(kinds, (list, tuple)) and kinds and all(k in FIT_LAW_KINDS for k in kinds)):
            _args.refuse(f"laws[{name!r}]", f"a law kind ({', '.join(FIT_LAW_KINDS)}) or a list of them", kind)


def _checked_types(data, method, init, friction, parameters, free, procedure, laws, refine, reference_temperature,
                   controller, rtol, progress, offset):
    """The argument types (_args.py), before any work; returns (parameters, free, rtol) as identify uses them."""
    _args.text(method, "method")  # the argument types (_args.py): before any work
    if not (init is None or isinstance(init, (Model, str, os.PathLike))):
        _args.refuse("init", "a Model, a model file or a preset name, or None", init)
    _args.text(friction, "friction", none=True)
    parameters = _args.names(parameters, "parameters", allow=Parameters)  # 'sigma0' is one name, not 5 letters
    free = free if isinstance(free, str) else (_args.names(free, "free") or ())  # (a string: "m_e,m")
    _args.text(procedure, "procedure")
    _checked_laws(laws)
    _args.flag(refine, "refine")
    _args.number(reference_temperature, "reference_temperature", "degC", none=True)
    if rtol is not None:  # the earlier spelling: tolerances are given by a StepSizeController everywhere
        warnings.warn("identify(rtol=...) is now identify(controller=StepSizeController(rtol=...))",
                      DeprecationWarning, stacklevel=5)  # (the user, past this and the two decorators)
        _args.number(rtol, "rtol")
        if controller is not None:
            raise InputError("give controller= (rtol= is its earlier spelling), not both")
        controller = StepSizeController(rtol=rtol)
    _args.instance(controller, StepSizeController, "controller", "a StepSizeController", none=True)
    rtol = 1e-8 if controller is None else controller.rtol
    _args.function(progress, "progress")
    if not isinstance(offset, (bool, str)):
        _args.refuse("offset", "\"shared\", \"per-experiment\", \"none\", True or False", offset)
    return parameters, free, rtol


@stamped  # the fitted model's name and provenance (provenance.py)
@one_blas_thread  # (optimiser.py) for the whole procedure, whose fits run side by side
def identify(data, method="model-i", init=None, *, friction=None, parameters=None, free=(), procedure="direct", laws=None,
             refine=True, reference_temperature=None, controller=None, starts=8, seed=0, progress=None, offset=True,
             max_evaluations=None, rtol=None, delay="auto",
             ripple_phase="auto") -> FitResult:
    """Identifies a model from a dataset's ``fit`` experiments.

    After the fit, every value it held (masses, fs, vs, sigma2, a law held whole) is tested against the data
    (identification/held.py: ``fit_quality["held"]``); a contradicted one makes the fit not adequate. What was
    measured (displacement, force, a drive's command) is the dataset's measurement (thermofriction.measurements):
    it forms the residuals and their offsets, and owns the steps particular to it: the initial model
    (``Measurement.initial_model``) and the result completed at the optimum (``Measurement.complete``).

    Parameters
    ----------
    data : Dataset
        The measurements (``load_dataset``); its ``fit`` experiments are fitted, its ``validate`` experiments
        held out and predicted by the fitted model.
    method : {"model-i", "plant", "base", "model-ii", "heat", "warm-up"}, default "model-i"
        "plant" (xi, wn, K from the experiments that record the stage displacement), "base" (one friction model
        for all experiments, no thermal model), "model-i" (temperature laws of the friction parameters),
        "model-ii" (a thermal friction term dF(T)), "heat" (a heat model's parameters) or "warm-up" (force
        data: Model I's laws and a heat path from warm-up records without a contact temperature,
        docs/self-heating.md#warm-up-without-a-contact-temperature).
    init : Model or str or os.PathLike, optional
        The initial model (its plant, masses and input are kept): a model, a model file or a preset name.
        Default: the paper's preset for the method. A file with a ``[plant]`` and no ``[friction]`` section
        starts LuGre from values taken from the data (measurements/displacement_start.py, force_start.py).
    friction : str, optional
        The friction model to identify (a name of ``FRICTION_MODELS``: lugre, coulomb, ...); default the
        initial model's. When it differs, the initial friction model is built from the initial model's values
        (``with_friction_model``).
    parameters : list of str or Parameters, optional
        The friction parameters to fit (any of the friction model's: fs, vs, sigma2, delta, z_ba, ...); one
        name is that name. Default the friction model's (LuGre: sigma0, sigma1, fc). "base" also takes a
        ``Parameters`` object; Model I fits each named one with its own law (any other with a law in the
        initial model keeps it, held); Model II fits them as its base parameters. fs is fitted as its excess
        over fc, in log space, so that fs >= fc holds by construction.
    free : list of str or str, default ()
        Plant parameters fitted too, in any method but "plant", one value shared by all experiments: "m_e",
        "m" (the masses, which the paper does not give), "xi", "wn", "K" (or "c", "k", "T_em" for a plant
        given in its physical form); a string may list them with commas ("m_e,m").
    procedure : {"direct", "paper", "both"}, default "direct"
        Model II's procedure: dF(T) fitted directly on all experiments, the paper's per-temperature steps, or
        both (the direct result, with the paper's in ``FitResult.alternatives["paper"]``).
    laws : dict, optional
        Model I law kinds per parameter, a kind or a list of kinds to choose from, e.g. ``{"sigma0": "exp"}``;
        default: each chosen by AICc.
    refine : bool, default True
        Model I and II: end with a joint refinement of every law coefficient on all experiments together.
    reference_temperature : float, optional
        Model II's reference temperature T_0 [C] (method "model-ii" only); default chosen from the data.
    controller : StepSizeController, optional
        The step-size controller whose relative tolerance the fit's simulations keep; default rtol 1e-8.
    starts : int, default 8
        The multi-start size: starting points screened before the local fits (1 to ``MAX_STARTS``).
    seed : int, default 0
        The seed of the multi-start's Latin hypercube: the same seed, the same fit.
    progress : callable, optional
        Called with one line of text at each stage (the command line shows them on standard error).
    offset : {True, "shared", "per-experiment", "none", False}, default True
        Force data only (docs/force-data.md): "shared" (True: one sensor offset [N or N m] fitted for all
        experiments), "per-experiment" (one per run: a sensor re-zeroed between runs) or "none" (or False: the
        initial model's ``[plant] sensor_offset`` held). Displacement data take each run's own zero.
    max_evaluations : int, optional
        The most model evaluations of each least-squares stage (1 to 100000); default the stages' own limits.
    rtol : float, optional
        Deprecated (DeprecationWarning): the earlier spelling of ``controller=StepSizeController(rtol=...)``.
    delay : str or float or tuple of float or None, default "auto"
        A drive's command data only: "auto" (searched over a range read off the data), None or "none" (0), a
        value held [s] (or a string with a unit, "5ms"), or a range searched, (min, max) [s] or "MIN:MAX".
    ripple_phase : {"auto", "recorded", "per-run"}, default "auto"
        Force data with a position ripple: "recorded" (the ripple at the recorded angle), "per-run" (a phase per
        run: positions relative to each run) or "auto" (per-run where every run starts at 0; the choice is said
        among the warnings).

    Returns
    -------
    FitResult
        The fitted model, its parameters with standard errors, 95 % intervals and correlations, the fit's
        quality against the noise estimated from the data, its warnings, and the held-out experiments'
        metrics.

    Raises
    ------
    InputError
        An argument of the wrong type or value, named (``starts must be ...``); a method that does not apply
        to the data's measurement; a dataset without ``fit`` experiments; an initial model that cannot be read.
    ComputationError
        The fit failed (its simulations or the least-squares solver); SolverError, a ComputationError, where
        an integrator stopped.

    Warns
    -----
    UnitWarning
        An experiment's record a power of 1000 off what the initial model predicts for it.

    Examples
    --------
    A Model I fit of data synthesised from the paper's actuator (a fit of some minutes):

    >>> import thermofriction as tf
    >>> truth = tf.load_model("li2009-model-i")
    >>> data = tf.synthesize(truth, [25, 30, 35, 40, 45], validate=[37.5])  # doctest: +SKIP
    >>> fit = tf.identify(data, method="model-i", init="li2009-base")  # doctest: +SKIP
    >>> print(fit.report())  # doctest: +SKIP
    """
    parameters, free, rtol = _checked_types(data, method, init, friction, parameters, free, procedure, laws, refine,
                                            reference_temperature, controller, rtol, progress, offset)
    _check_arguments(method, reference_temperature, rtol, starts, seed)
    max_nfev = _args.whole(max_evaluations, "max_evaluations", none=True, low=1, high=MAX_EVALUATIONS)
    _args.dataset(data, Dataset, experiments=True)  # after the options, whose messages name them first
    measurement = measurement_of(data, offset=offset, ripple_phase=ripple_phase)  # asked once: what, its offsets
    _delay_of(measurement, delay)
    if method not in measurement.methods:
        *most, last = measurement.methods
        raise InputError(f"method '{method}' does not apply to {measurement.name} data ({', '.join(most)} or {last})")
    experiments = list(getattr(data, "fit", data))
    if method == "warm-up":  # docs/self-heating.md#warm-up-without-a-contact-temperature
        opts = dict(rtol=rtol, starts=starts, seed=seed, **({"max_nfev": max_nfev} if max_nfev else {}))
        return _warm_up(data, experiments, init, measurement, friction, parameters, progress, opts)
    _no_warm_up_records(data, method)
    source = os.fspath(init) if isinstance(init, (str, os.PathLike)) else "the initial model"  # (a file: named)
    with counting() as screened:  # a start read off the data is screened by short fits: the fit spent those too
        init = measurement.initial_model(init, method, data, experiments, friction=friction, free=free,
                                         procedure=procedure, parameters=parameters)
    _ripple_checks(parameters, init, source, measurement, method)  # before the fit, not as its failure
    if not experiments:
        raise InputError("the dataset has no experiment with role 'fit'")
    if load_laws(init):  # laws of temperature and load (identification/load_identify.py)
        _no_multi_start_options(starts, seed, max_nfev)
        res = identify_with_load(experiments, init, measurement, method, parameters, laws, refine, progress)
        held = list(getattr(data, "validate", None) or [])
        return _with_generalisation(res, data, held, measurement) if held and res.fit_quality else res
    opts = dict(rtol=rtol, starts=starts, seed=seed)
    if max_nfev is not None:
        opts["max_nfev"] = max_nfev
    free = _plant_parameters(init, free, method)
    if method == "plant":
        return _identify_plant(getattr(data, "experiments", data), init)
    # every experiment's unit against the initial model's prediction, before the fit: said at once (unit_scale.py)
    units = model_unit_warnings(init, getattr(data, "experiments", experiments), measurement)
    if method == "heat":
        res = identify_heat(experiments, init, parameters, free=free, progress=progress, **opts)
        res.warnings[:0] = units
        return res
    res = _fit(method, experiments, init, parameters, free, procedure, reference_temperature, laws, refine, progress,
               measurement, opts)
    res.nfev, res.njev = res.nfev + screened.nfev, res.njev + screened.njev
    res = measurement.complete(res, experiments, init)
    held = list(getattr(data, "validate", None) or [])  # the held-out runs: the advice's refits are scored there too
    res = with_held_tests(res, experiments, measurement, rtol, data, held)  # the held values against the data (held.py)
    res = _with_generalisation(res, data, held, measurement) if held and res.fit_quality else res
    res = with_ripple_advice(res, experiments, held, measurement, rtol)  # a ripple the residuals hold, tried
    res.warnings += [f.message for f in load_findings(res.model, getattr(data, "experiments", data))]  # load-blind?
    res.warnings[:0] = units + _ripple_note(measurement, res.model)
    return res


def _no_warm_up_records(data, method):
    """Warm-up records have no contact temperature: only the warm-up fit reads them."""
    warm = [e.label for e in getattr(data, "experiments", data) if getattr(e, "warm_up", False)]
    if warm:
        raise InputError(f"{warm[0]} is a warm-up record (an ambient temperature, no contact temperature): method "
                         f"'{method}' needs the contact's temperature; fit it with method 'warm-up'")


def _warm_up(data, experiments, init, measurement, friction, parameters, progress, opts):
    """The warm-up fit (identification/warm_up.py) from the initial model's laws, or from laws fitted first on
    the dataset's soak runs (Model I) where the initial model has none."""
    if measurement.name != "force":
        raise InputError(f"method 'warm-up' takes friction (force or torque) records; these are {measurement.name} "
                         f"data")
    soak = [e for e in experiments if not e.warm_up]
    start = measurement.initial_model(init, "model-i", data, soak or experiments, friction=friction,
                                      parameters=parameters)
    if not start.laws:
        if len({round(e.temperature, 1) for e in soak}) < 2:
            raise InputError("the warm-up fit starts from the friction's temperature laws: give an initial Model I "
                             "model (init, --init) or soak runs at two temperatures or more in the dataset")
        start = identify_model_i(soak, start, progress=progress, measurement=measurement,
                                 parameters=parameters, **opts).model
    return identify_warm_up(experiments, start, parameters=parameters, progress=progress,
                            held_out=list(getattr(data, "validate", None) or []))


def _no_multi_start_options(starts, seed, max_nfev):
    """A fit with laws of the load (per-condition fits, the laws through them, a joint refinement) takes no
    multi-start and no evaluation limit: options given for them are refused by name, not ignored."""
    given = [n for n, v, default in (("starts", starts, 8), ("seed", seed, 0), ("max_evaluations", max_nfev, None))
             if v != default]
    if given:
        raise InputError(f"{', '.join(given)}: not an option of a fit with laws of the load (per-condition fits, the "
                         "laws through them, a joint refinement; docs/identification.md#laws-of-temperature-and-load)")


def _ripple_checks(parameters, init, source, measurement, method):
    """Ripple amplitudes need a period (needs_period); a phase per run needs an additive ripple (check_per_run)."""
    needs_period(list(parameters or ()), init.friction.values(), source)
    check_per_run(measurement, init, list(parameters or ()), method)


def _ripple_note(measurement, model) -> list:
    """How the ripple's phase was decided (ripple_phase "auto"), where the fitted model has a ripple."""
    note = getattr(measurement, "ripple_note", None)
    return [f"ripple phase: {note}"] if note and has_ripple(model) else []


def _delay_of(measurement, delay):
    """The delay option on the measurement of a drive's command (InputError naming delay; refused elsewhere)."""
    if delay != "auto" or measurement.name == "command":
        spec = parse_delay(delay)
        if measurement.name != "command" and spec.kind != "auto":
            raise InputError(f"delay applies to a drive's command data; these are {measurement.name} data")
        if measurement.name == "command":
            measurement.delay = spec


def _fit(method, experiments, init, parameters, free, procedure, reference_temperature, laws, refine, progress,
         measurement, opts):
    """The procedure of method "base", "model-i" or "model-ii" from the initial model."""
    if method == "base":
        model = base_model(init)
        if free:
            if isinstance(parameters, Parameters):
                raise InputError("free= adds plant parameters to the default ones; with a Parameters object, add "
                                 "them to it instead")
            parameters = list(parameters or default_fit_parameters(model)) + free
        res = fit_friction(experiments, model, parameters, method="base", progress=progress, measurement=measurement,
                           **opts)
    elif method == "model-i":
        if init.thermal is not None and not hasattr(init.thermal, "laws"):
            init = base_model(init)
        res = identify_model_i(experiments, init, laws=laws, refine=refine, progress=progress, free=free,
                               measurement=measurement, parameters=parameters, **opts)
    else:
        res = identify_model_ii(experiments, init, procedure=procedure, reference_temperature=reference_temperature,
                                refine=refine, progress=progress, free=free, measurement=measurement,
                                parameters=parameters, **opts)
    return res


#: held-out RMS over fit RMS above which a fit is said not to generalise
GENERALISATION_WARN = 1.5


def _with_generalisation(res, data, held, measurement):
    """The fit's held-out error where the dataset holds experiments out: the generalisation ratio (held-out RMS
    over fit RMS, each run's error as validate measures it, with the fit's offset policy) in
    ``fit_quality["generalisation"]``, and a warning where it is large. It says what the noise estimate
    cannot when the residuals are correlated."""
    try:  # (its findings are values here: the units were checked against the initial model)
        heldout, v = heldout_score(res.model, data, held, measurement)
    except ThermofrictionError as e:
        res.warnings.append(f"the held-out experiments could not be predicted: {e}")
        return res
    if not v.predictions:
        return res
    ratio = heldout / res.rmse if res.rmse > 0 else math.inf
    q = res.fit_quality
    gen = q["generalisation"] = {"heldout_rmse": heldout, "fit_rmse": res.rmse, "ratio": ratio,
                                 "heldout_files": [p.file for p in v.predictions]}
    base = model_free(measurement, list(data.fit), held)  # what a model-free map of the same runs does
    verdict = baseline_verdict(q, base, heldout, len(v.predictions), res.unit) if base else None
    if base:  # the baseline's own generalisation, and the model's held-out error against the baseline's
        gen.update(baseline_heldout_rmse=base["heldout_rmse"], baseline_fit_rmse=base["fit_rmse"],
                   baseline_ratio=q["baseline"]["ratio"])
    if ratio > GENERALISATION_WARN:
        than = "" if not base else (f"; a model-free map of the same runs: {amount(base['heldout_rmse'], res.unit)} "
                                    f"against {amount(base['fit_rmse'], res.unit)}")
        offset = "an offset re-zeroed per run: --offset per-experiment; " if measurement.offset == "shared" else ""
        at = 1 if res.warnings and res.warnings[0].startswith("the fit is not adequate") else 0
        res.warnings.insert(at, f"the model predicts the {len(v.predictions)} held-out experiment(s) {ratio:.3g} times "
                                f"worse than it fits the others (RMSE {amount(heldout, res.unit)} against "
                                f"{amount(res.rmse, res.unit)}{than}): it does not generalise; look for what differs "
                                f"between runs ({offset}the temperature; the motion)")
    if verdict:  # one verdict, first (replacing 'adequacy unknown')
        res.warnings[:] = [verdict] + [w for w in res.warnings if not w.startswith("adequacy unknown")]
    return res


def _plant_parameters(init, free, method) -> list:
    """The plant parameters to free, checked against the initial model's plant."""
    if isinstance(free, str):
        free = [f.strip() for f in free.split(",") if f.strip()]
    free = list(dict.fromkeys(free or ()))
    if free and method == "plant":
        raise InputError("free= applies to the friction methods; --method plant fits xi, wn and K itself")
    for name in free:
        if name not in PLANT_UNITS:
            raise InputError(f"'{name}' is not a plant parameter that can be freed "
                             f"(one of: {', '.join(PLANT_UNITS)})")
        target_of(init, name)  # the plant's form: modal plants free xi, wn, K; physical ones c, k, T_em
    return free


def _identify_plant(experiments, init):
    staged = [e for e in experiments if getattr(e, "stage_displacement", None) is not None]
    if not staged:
        raise InputError("no experiment records the stage displacement (a stage_displacement[um] column): "
                         "the plant fit needs it")
    exp = staged[0]
    pf = fit_plant(exp.time, exp.voltage, exp.stage_displacement)
    model = dataclasses.replace(init, plant=pf.plant(init.plant.mass, init.plant.end_effector_mass))
    n = len(pf.parameters)
    corr = np.asarray(pf.correlation, float)[:n, :n] if getattr(pf, "correlation", None) is not None \
        else np.full((n, n), np.nan)
    return FitResult("plant", model, pf.parameters, corr, pf.rmse ** 2 * pf.n_points, pf.rmse,
                     pf.n_points, 0, 0, 1, pf.wall_time, True, f"fitted on {run_label(exp)}",
                     experiments=[{"file": run_label(exp), "temperature": exp.temperature, "role": exp.role,
                                   "rmse": pf.rmse}],
                     warnings=list(getattr(pf, "warnings", [])) + (
                         [] if len(staged) == 1 else [f"fitted on {run_label(exp)}; {len(staged) - 1} more "
                                                      f"experiment(s) with a stage record were not used"]),
                     details={"note": "the equivalent masses m and m_e are kept from the initial model"})


__all__ = ["identify", "METHODS", "MAX_STARTS"]
