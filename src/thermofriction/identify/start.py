"""Starting values from the data, for an initial model that gives only its plant (a model file with a
[plant] section and no [friction]).

A stick-slip actuator slips when the stage's acceleration times the end-effector mass exceeds the
friction level, so the friction level is of the order of ``m_e`` times the stage's acceleration. That
scale comes from the plant alone (the stage driven by the recorded input, nothing on it); a scan of the
friction level over four decades around it, each with bristles whose steady deflection is a tenth of the
stage's stroke and lightly damped, picks the start with the lowest misfit. The fit then starts from
there with its multi-start spanning a decade either way of each parameter.
"""

from __future__ import annotations

import math

import numpy as np

from ..drive import experiment_waveform
from ..errors import InputError
from ..models import Coulomb, LuGre, Model
from ..simulate import simulate
from .engine import Problem, make_traces

#: the scan, in units of m_e times the stage's acceleration scale
SCAN = np.logspace(-3, 1, 13)
DEFLECTION = 0.1   # steady bristle deflection fc/sigma0, as a fraction of the stage's stroke
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
    best, scan = None, []
    for f in SCAN:
        fc = float(f * m_e * a_scale)
        sigma0 = fc / (DEFLECTION * stroke)
        sigma1 = DAMPING * 2.0 * math.sqrt(sigma0 * m_e)
        model = Model(plant, LuGre(sigma0=sigma0, sigma1=sigma1, fc=fc), input=input)
        problem = Problem(model, ["fc"], make_traces([exp], model), rtol=1e-6, parallel=False)
        r, _ = problem.evaluate(np.array([fc]))
        cost = math.inf if r is None else float(r @ r)
        scan.append((fc, cost))
        if best is None or cost < best[0]:
            best = (cost, {"model": "lugre", "sigma0": sigma0, "sigma1": sigma1, "fc": fc})
    if not math.isfinite(best[0]):
        raise InputError(f"{exp.file}: no friction level between {SCAN[0]:g} and {SCAN[-1]:g} x m_e x the stage's "
                         f"acceleration could be simulated: check the plant")
    return best[1]


__all__ = ["lugre_start"]
