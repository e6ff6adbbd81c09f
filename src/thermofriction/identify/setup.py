"""What identification does per measurement, before and after the fit (the procedures' front door): the initial
model each measurement starts from (a preset, a file, or values read off the data), and what its result gains
afterwards (force data: the sensor offset estimated at the optimum, the units of a rotary joint).
:data:`SETUP` maps a measurement's name to its two steps."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .._lazy import lazy
from ..errors import InputError
from ..models import LuGre, Model, PrescribedMotion, StickSlipPlant, load_model
from ..measurements.force import FD_RTOL
from ..models.plants import rotary_unit
from .parameters import get_value
from .problem import Problem, make_traces
from .start import force_start, lugre_start, with_friction_model

stats = lazy("scipy.stats")

#: each method's default initial model on displacement data (the paper's presets)
PRESET_OF_METHOD = {"plant": "li2009-base", "base": "li2009-base", "model-i": "li2009-model-i",
                    "model-ii": "li2009-model-ii", "heat": "li2009-self-heating"}


def displacement_initial(init, method, data, experiments, *, friction=None, free=(), procedure="direct"):
    """The initial model for displacement data: the method's preset by default; a file with only a [plant]
    (and [input]) starts LuGre from values taken from the data."""
    if init is None:
        init = PRESET_OF_METHOD[method]
    if not isinstance(init, Model):
        init = load_model(init, friction_from=lambda plant, inp, model="lugre": _start_of(
            model, plant, lugre_start(plant, experiments, inp)))
    if not isinstance(init.plant, StickSlipPlant):
        raise InputError(f"identification works on the stick-slip actuator (datasets record its voltage and "
                         f"displacement); a '{init.plant.type}' plant can be simulated but not identified yet")
    if friction is not None and method != "plant":
        init = with_friction_model(init, friction)
    return init


def _start_of(kind, plant, lugre_section) -> dict:
    """A [friction] section of ``kind`` from LuGre starting values (a file naming only its friction model)."""
    if kind == "lugre":
        return lugre_section
    return with_friction_model(Model(plant, LuGre.from_dict(lugre_section)), kind).friction.to_dict()


def force_initial(init, method, data, experiments, *, friction=None, free=(), procedure="direct"):
    """The initial model for force data: a prescribed-motion model of the data's kind (linear or rotary); a
    plant-only file (or one naming only the friction model), or none, gets its friction values from the data."""
    if free:
        raise InputError("free= frees plant parameters; a prescribed-motion model has none to fit")
    if method == "model-ii" and procedure != "direct":
        raise InputError("Model II's paper procedure reads stick-slip displacements; force data use the direct one")
    if not experiments:
        raise InputError("the dataset has no experiment with role 'fit'")
    rotary = _rotary(getattr(data, "experiments", experiments))
    init = _from_plant_only(init, experiments, rotary)
    if init.plant.type != "prescribed":
        raise InputError(f"force data are fitted with a prescribed-motion model ([plant] type = \"prescribed\"); "
                         f"the initial model's plant is '{init.plant.type}'")
    if init.plant.rotary != rotary:
        want = "rotary" if rotary else "linear"
        raise InputError(f"the data are {want} ({'rad, N m' if rotary else 'm, N'}) but the initial model's motion is "
                         f"{init.plant.motion}: set motion = \"{want}\" in its [plant]")
    if friction is not None:
        init = with_friction_model(init, friction)
    if init.heat is not None:
        raise InputError("a self-heating model ([heat]) cannot be fitted to force data yet")
    return init


def _rotary(experiments) -> bool:
    """True for rotary experiments (rad, N m), False for linear ones; a mix is an error."""
    exps = list(experiments)
    kinds = {e.rotary for e in exps}
    if len(kinds) > 1:
        rot = next(e.file for e in exps if e.rotary)
        lin = next(e.file for e in exps if not e.rotary)
        raise InputError(f"the dataset mixes rotary ({rot}) and linear ({lin}) experiments: one joint or one "
                         f"stage per dataset")
    return kinds == {True}


def _from_plant_only(init, experiments, rotary):
    def start(plant, inp, model="lugre"):
        if plant.type != "prescribed":
            raise InputError("force data are fitted with a prescribed-motion model: [plant] type = \"prescribed\"")
        return force_start(experiments, model, plant)

    if init is None:
        plant = PrescribedMotion(motion="rotary" if rotary else "linear")
        return Model(plant, LuGre.from_dict(force_start(experiments, "lugre", plant)))
    if isinstance(init, Model):
        return init
    return load_model(init, friction_from=start)


def force_finish(res, experiments, init, measurement):
    """The fit completed for force data: the sensor offset estimated at the optimum ("shared": one, written into
    the fitted model; "per-experiment": one per run, their mean written into the model; "none": the initial
    model's); a rotary joint's parameters in its units."""
    traces = make_traces(experiments, res.model, measurement)
    unit = traces[0].unit
    names = [p.name for p in res.parameters.varying] if res.n_points else []
    inflation = res.statistics.get("variance_inflation", 1.0)
    if measurement.offset == "shared":
        est = estimate_offset(res.model, names, traces, inflation)
    elif measurement.offset == "per-experiment":
        runs = [dict(estimate_offset(res.model, names, [tr], inflation), file=tr.name) for tr in traces]
        est = {"value": float(np.mean([r["value"] for r in runs])), "stderr": None, "ci95": None,
               "per_experiment": runs}
    else:
        est = {"value": init.plant.sensor_offset, "stderr": 0.0, "ci95": (init.plant.sensor_offset,) * 2}
    model = dataclasses.replace(res.model, plant=dataclasses.replace(res.model.plant, sensor_offset=est["value"]))
    est.update(unit=unit, fitted=measurement.offset != "none", policy=measurement.offset)
    if unit == "N m":  # the equations are the same, the numbers mean angles and torques
        for p in res.parameters.values():
            if p.unit and "C" != p.unit:
                p.unit = rotary_unit(p.unit)
    for e in res.experiments:
        q = e.get("fit_quality") or {}
        e["rmse"] = q.get("rmse", e.get("rmse_offset_removed"))
        e["unit"] = unit
    return dataclasses.replace(res, model=model, sensor_offset=est, unit=unit)


def estimate_offset(model: Model, names, traces, variance_inflation=1.0) -> dict:
    """The shared offset at ``model`` (``names`` the fitted parameters): the mean of ``F_meas - F_sim`` over
    all traces, and its standard error from the Jacobian augmented with the offset's column of ones (so that
    the parameters' uncertainty is in it)."""
    plain_measurement = type(traces[0].measurement)("none")
    plain = [dataclasses.replace(tr, measurement=plain_measurement, held_offset=0.0) for tr in traces]
    problem = Problem(model, names, plain, rtol=FD_RTOL, parallel=len(plain) > 1)
    theta = np.array([get_value(model, n) for n in names], float)
    r, J = problem.evaluate(theta, jac=bool(names))
    if r is None:
        return {"value": math.nan, "stderr": math.nan, "ci95": (math.nan, math.nan)}
    offset = -float(r.mean())
    res = r + offset
    A = np.column_stack([J, np.ones(r.size)]) if names else np.ones((r.size, 1))
    dof = max(r.size - A.shape[1], 1)
    s2 = float(res @ res) / dof * variance_inflation
    col = np.linalg.norm(A, axis=0)
    col[col == 0] = 1.0
    cov = np.linalg.pinv((A / col).T @ (A / col), rcond=1e-12) / np.outer(col, col) * s2
    se = math.sqrt(max(float(cov[-1, -1]), 0.0))
    tq = float(stats.t.ppf(0.975, dof))
    return {"value": offset, "stderr": se, "ci95": (offset - tq * se, offset + tq * se)}


def _no_finish(res, experiments, init, measurement):
    return res


#: measurement name -> (the initial model, the result's completion)
SETUP = {"displacement": (displacement_initial, _no_finish), "force": (force_initial, force_finish)}

__all__ = ["SETUP", "PRESET_OF_METHOD", "displacement_initial", "force_initial", "force_finish", "estimate_offset"]
