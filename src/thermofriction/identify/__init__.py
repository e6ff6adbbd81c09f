"""Identification: fit friction models and their thermal extensions to measured displacements.

    fit = tf.identify(data, method="model-i", init=model)
    fit.model, fit.report(), fit.to_json()
"""

from __future__ import annotations

import dataclasses
import numbers
import os

from .. import _args
from ..data.experiments import Dataset

from ..errors import InputError, shorten
from ..models import Model, StickSlipPlant, load_model
from .engine import fit, make_traces, one_blas_thread, uncertainty
from .parameters import PLANT_UNITS, Parameter, Parameters, target_of
from .laws import fit_law, segmented_fit
from .model_ii import identify_model_ii
from .procedures import base_model, default_fit_parameters, fit_friction, identify_heat, identify_model_i
from .plant import PlantFit, fit_plant, step_response
from .result import FitResult, stamped
from .start import lugre_start

METHODS = ("plant", "base", "model-i", "model-ii", "heat")


#: The most starting points of the multi-start phase: each one simulates every fit experiment
MAX_STARTS = 10_000


def _check_arguments(method, reference_temperature, rtol, starts, seed):
    from ..data.experiments import TEMPERATURE_RANGE

    def whole(v):
        return isinstance(v, numbers.Integral) and not isinstance(v, bool)

    if not whole(starts) or not 1 <= starts <= MAX_STARTS:
        raise InputError(f"starts must be a whole number from 1 to {MAX_STARTS}, got {shorten(starts)}")
    if not whole(seed) or seed < 0:
        raise InputError(f"seed must be a whole number, 0 or more, got {shorten(seed)}")
    if isinstance(rtol, bool) or not isinstance(rtol, numbers.Real) or not 0 < rtol < 1:
        raise InputError(f"rtol must be between 0 and 1, got {shorten(rtol)}")
    if reference_temperature is not None:
        if method != "model-ii":
            raise InputError("reference_temperature applies to method 'model-ii' only")
        lo, hi = TEMPERATURE_RANGE
        if (isinstance(reference_temperature, bool) or not isinstance(reference_temperature, numbers.Real)
                or not lo <= reference_temperature <= hi):
            raise InputError(f"reference_temperature must be a temperature from {lo:g} to {hi:g} C, "
                             f"got {shorten(reference_temperature)}")


def with_friction_model(model: Model, kind: str) -> Model:
    """``model`` with a ``kind`` friction model (docs/identification.md#friction-models), built from
    its own friction's values where the two share a parameter (a Model I law goes with its
    parameter; laws of parameters the new model lacks are dropped). What the new model requires
    and the old one lacks is derived from the level fc and the presliding stiffness sigma0 (a GMS
    model's sum of k_i; else fc over 1 um): sigma1 = 1e-6 s x sigma0, z_ba = fc / (2 sigma0),
    C = 1e4 /s x fc, and GMS elements k_i proportional to 1/i summing to sigma0, w_i = 1/4 (four
    elements breaking loose one after the other)."""
    from ..models import FRICTION_MODELS, ModelI

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


@stamped  # the fitted model's name and provenance (result.py)
@one_blas_thread  # (engine.py) for the whole procedure, whose fits run side by side
def identify(data, method="model-i", init=None, *, friction=None, parameters=None, free=(), procedure="direct", laws=None,
             refine=True, reference_temperature=None, rtol=1e-8, starts=8, seed=0, progress=None, offset=True) -> FitResult:
    """Identifies a model from a dataset's ``fit`` experiments.

    method: "plant" (xi, wn, K from the experiments that record the stage displacement), "base"
        (one friction model for all experiments, no thermal model), "model-i" or "model-ii".
    init: the initial model (its plant, masses and input are kept); a model, a file or a preset
        name. Default: the paper's preset for the method. A file with a [plant] and no [friction]
        section starts LuGre from values taken from the data (identify/start.py).
    friction: the friction model to identify (lugre, dahl, elastoplastic, gms, stribeck, coulomb);
        default the initial model's. When it differs, the initial friction model is built from the
        initial model's values (:func:`with_friction_model`).
    parameters: names (or a Parameters object) to fit for "base"; default the friction model's
        (procedures.FRICTION_FIT_PARAMETERS; LuGre: sigma0, sigma1, fc).
    procedure: Model II's "direct" (default), "paper" or "both".
    free: plant parameters fitted too, in any method but "plant", one value shared by all experiments:
        "m_e", "m" (the masses, which the paper does not give), "xi", "wn", "K" (or "c", "k", "T_em" for a
        plant given in its physical form).
    laws: Model I law kinds per parameter, e.g. {"sigma0": "exp"}; default: chosen by AICc.
    rtol: the simulations' relative tolerance during the fit; starts: the multi-start size.
    offset: force data only (docs/force-data.md): fit the force sensor's offset, one for all experiments
        (default), or hold it at the initial model's ``[plant] sensor_offset``.
    """
    _args.text(method, "method")  # the argument types (_args.py): before any work
    if not (init is None or isinstance(init, (Model, str, os.PathLike))):
        _args.refuse("init", "a Model, a model file or a preset name, or None", init)
    _args.text(friction, "friction", none=True)
    parameters = _args.names(parameters, "parameters", allow=Parameters)  # 'sigma0' is one name, not 5 letters
    free = free if isinstance(free, str) else (_args.names(free, "free") or ())  # (a string: "m_e,m")
    _args.text(procedure, "procedure")
    _args.instance(laws, dict, "laws", "a dict (parameter -> law kind)", none=True)
    _args.flag(refine, "refine")
    _args.number(reference_temperature, "reference_temperature", "degC", none=True)
    _args.number(rtol, "rtol")
    _args.function(progress, "progress")
    _args.flag(offset, "offset")
    if method not in METHODS:
        raise InputError(f"unknown method {shorten(method)} (one of: {', '.join(METHODS)})")
    _check_arguments(method, reference_temperature, rtol, starts, seed)
    _args.dataset(data, Dataset, experiments=True)
    from ..data.force import is_force_data
    if is_force_data(getattr(data, "experiments", data)):  # measured force under measured motion
        from .force import identify_force
        return identify_force(data, method, init, friction=friction,
                              parameters=parameters, free=free, procedure=procedure, laws=laws, refine=refine,
                              reference_temperature=reference_temperature, offset=offset, rtol=rtol, starts=starts,
                              seed=seed, progress=progress)
    if not offset:
        raise InputError("offset=False (--no-offset) applies to force data; displacement data remove each "
                         "experiment's zero")
    if init is None:
        init = {"plant": "li2009-base", "base": "li2009-base", "model-i": "li2009-model-i", "model-ii": "li2009-model-ii",
                "heat": "li2009-self-heating"}[method]
    experiments = getattr(data, "fit", data)
    if not isinstance(init, Model):
        # a file with only a [plant] (and [input]): a LuGre start taken from the data
        init = load_model(init, friction_from=lambda plant, inp, model="lugre": _start_of(
            model, plant, lugre_start(plant, experiments, inp)))
    if not isinstance(init.plant, StickSlipPlant):
        raise InputError(f"identification works on the stick-slip actuator (datasets record its voltage and "
                         f"displacement); a '{init.plant.type}' plant can be simulated but not identified yet")
    if friction is not None and method != "plant":
        init = with_friction_model(init, friction)
    if not experiments:
        raise InputError("the dataset has no experiment with role 'fit'")
    opts = dict(rtol=rtol, starts=starts, seed=seed)
    free = _plant_parameters(init, free, method)
    if method == "plant":
        return _identify_plant(getattr(data, "experiments", data), init)
    if method == "heat":
        return identify_heat(experiments, init, parameters, free=free, progress=progress, **opts)
    if method == "base":
        model = base_model(init)
        if free:
            if isinstance(parameters, Parameters):
                raise InputError("free= adds plant parameters to the default ones; with a Parameters object, add "
                                 "them to it instead")
            parameters = list(parameters or default_fit_parameters(model)) + free
        return fit_friction(experiments, model, parameters, method="base", progress=progress, **opts)
    if method == "model-i":
        if init.thermal is not None and not hasattr(init.thermal, "laws"):
            init = base_model(init)
        return identify_model_i(experiments, init, laws=laws, refine=refine, progress=progress, free=free, **opts)
    return identify_model_ii(experiments, init, procedure=procedure, reference_temperature=reference_temperature,
                             refine=refine, progress=progress, free=free, **opts)


def _start_of(kind, plant, lugre_section) -> dict:
    """A [friction] section of ``kind`` from LuGre starting values (a file naming only its friction model)."""
    from ..models import LuGre
    if kind == "lugre":
        return lugre_section
    return with_friction_model(Model(plant, LuGre.from_dict(lugre_section)), kind).friction.to_dict()


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
    import numpy as np

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
                     pf.n_points, 0, 0, 1, pf.wall_time, True, f"fitted on {exp.file}",
                     experiments=[{"file": exp.file, "temperature": exp.temperature, "role": exp.role,
                                   "rmse": pf.rmse}],
                     warnings=list(getattr(pf, "warnings", [])) + (
                         [] if len(staged) == 1 else [f"fitted on {exp.file}; {len(staged) - 1} more "
                                                      f"experiment(s) with a stage record were not used"]),
                     details={"note": "the equivalent masses m and m_e are kept from the initial model"})


__all__ = ["with_friction_model", "fit_plant", "PlantFit", "step_response", "identify", "FitResult", "Parameter",
           "Parameters", "fit", "fit_friction", "fit_law", "segmented_fit", "identify_model_i", "identify_model_ii",
           "identify_heat", "base_model", "make_traces", "uncertainty", "METHODS", "MAX_STARTS"]
