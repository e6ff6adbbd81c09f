"""Displacement data's initial model (``Displacement.initial_model``): the method's preset, or a model file's
plant with a LuGre start read off the data (:func:`lugre_start`).

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

import math

import numpy as np

from ..drive import experiment_waveform
from ..errors import ComputationError, InputError
from ..fitting.optimiser import fit
from ..fitting.parameters import Parameters
from ..fitting.problem import Problem
from ..models import Coulomb, LuGre, Model, StickSlipPlant, load_model
from ..models.transforms import with_friction_model
from ..simulation import simulate

#: the scan, in units of m_e times the stage's acceleration scale
SCAN = np.logspace(-3, 1, 13)
DEFLECTIONS = (0.03, 0.1, 0.3, 1.0, 3.0)   # steady bristle deflection fc/sigma0, in units of the stage's stroke
DAMPING = 0.01     # sigma1 as a fraction of 2 sqrt(sigma0 m_e) (critical damping of the stuck end effector)


def lugre_start(plant, experiments, input=None, *, measurement) -> dict:
    """A [friction] section (LuGre) with starting values from ``experiments`` for ``plant``; ``measurement``
    (the displacement measurement) makes the traces."""
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
        problem = Problem(model, ["fc"], [measurement.make_trace(exp, model)], rtol=1e-6, parallel=False)
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
            outcome = fit(model, params, [measurement.make_trace(exp, model)], rtol=1e-6, starts=1, max_nfev=15)
        except (ComputationError, InputError):  # a start whose fit cannot run is simply not chosen
            continue
        cost = float(outcome.r @ outcome.r)
        if best is None or cost < best[0]:
            best = (cost, dict(zip(start, (float(v) for v in outcome.theta))))
    values = best[1] if best is not None else scan[0][1]
    return {"model": "lugre", **values}


#: each method's default initial model on displacement data (the paper's presets)
PRESET_OF_METHOD = {"plant": "li2009-base", "base": "li2009-base", "model-i": "li2009-model-i",
                    "model-ii": "li2009-model-ii", "heat": "li2009-self-heating"}


def displacement_initial(init, method, data, experiments, *, measurement, friction=None, free=(), procedure="direct"):
    """The initial model for displacement data (``measurement``'s: Displacement.initial_model): the method's preset
    by default; a file with only a [plant] (and [input]) starts LuGre from values taken from the data."""
    if init is None:
        init = PRESET_OF_METHOD[method]
    if not isinstance(init, Model):
        init = load_model(init, friction_from=lambda plant, inp, model="lugre": _start_of(
            model, plant, lugre_start(plant, experiments, inp, measurement=measurement)))
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


__all__ = ["PRESET_OF_METHOD", "lugre_start", "displacement_initial"]
