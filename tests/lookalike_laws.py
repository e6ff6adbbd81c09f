"""Look-alike joint logs at several temperatures (issue 40 item 1): the friction of :mod:`lookalike` (LuGre with a
Stribeck curve and viscous friction, integrated by SciPy outside the package) whose levels follow temperature laws,
logged as a 17-bit encoder and a firmware velocity 10 ms late, with a sensor re-zeroed per run and AR(1) noise.

The truth (symmetric, no ripple) [N m, rad, s]: ``fc(T)``, ``fs(T)`` and ``sigma2(T)`` linear in T (a lubricant
thinning as it warms: every level falls), ``vs``, ``sigma0``, ``sigma1`` constant. ``truth_at(T)`` is the
:class:`lookalike.Truth` at T; ``law_runs(...)`` one run per temperature; ``law_experiments(...)`` those runs as a
thermofriction Dataset in memory (loaded as a folder would be); ``write_dataset`` (from :mod:`lookalike`) writes
them.
"""

from __future__ import annotations

import math

from lookalike import Truth, lookalike_runs

#: five temperatures of one joint [C]
TEMPERATURES = (20.0, 30.0, 40.0, 50.0, 60.0)
#: (value at 20 C, value at 60 C) of each law; linear between
LAWS = {"fc": (0.90, 0.70), "fs": (1.30, 0.95), "sigma2": (0.30, 0.20)}
CONSTANTS = {"vs": 0.1, "sigma0": 300.0, "sigma1": 0.6}
#: a 17-bit encoder's position step [rad]
ENCODER_17 = 2 * math.pi / 2 ** 17
#: per-run sensor offsets [N m] (re-zeroed between runs)
OFFSETS = (0.03, -0.04, 0.05, -0.02, 0.01)


def law_value(name, T) -> float:
    """The truth's ``name`` at temperature ``T`` [C] (a constant or the line of :data:`LAWS`)."""
    if name in CONSTANTS:
        return CONSTANTS[name]
    a, b = LAWS[name]
    return a + (b - a) * (float(T) - TEMPERATURES[0]) / (TEMPERATURES[-1] - TEMPERATURES[0])


def truth_at(T) -> Truth:
    """The look-alike truth at temperature ``T``: symmetric levels, no ripple."""
    fc, fs = law_value("fc", T), law_value("fs", T)
    return Truth(fc_pos=fc, fc_neg=fc, fs_pos=fs, fs_neg=fs, vs=CONSTANTS["vs"], sigma0=CONSTANTS["sigma0"],
                 sigma1=CONSTANTS["sigma1"], sigma2=law_value("sigma2", T), ripple=0.0)


def law_runs(*, temperatures=TEMPERATURES, offsets=None, seed=0, duration=8.0, lag=0.010,
             position_step=ENCODER_17, noise=0.02, rho=0.5, **params) -> list:
    """One look-alike run per temperature (all role "fit"), its own offset (default :data:`OFFSETS`), its own
    amplitude and frequency (run k: 0.6 (1 + 0.15 k) rad at 0.25 (1 + 0.1 k) Hz), its own noise seed; other
    ``params`` as :func:`lookalike.lookalike_runs`."""
    offsets = OFFSETS[:len(temperatures)] if offsets is None else offsets
    runs = []
    for k, (T, off) in enumerate(zip(temperatures, offsets)):
        run, = lookalike_runs(truth=truth_at(T), offsets=(off,), roles=["fit"], temperatures=[T],
                              duration=duration, lag=lag, position_step=position_step, noise=noise, rho=rho,
                              amplitude=0.6 * (1 + 0.15 * k), frequency=0.25 * (1 + 0.1 * k),
                              seed=1000 * seed + k, **params)
        runs.append(run)
    return runs


def law_experiments(*, motion="auto", **params):
    """(a thermofriction Dataset of the :func:`law_runs` in memory, the runs)."""
    from thermofriction.data.experiments import Dataset
    from thermofriction.data.force import force_experiment

    runs = law_runs(**params)
    exps = []
    for k, r in enumerate(runs):
        columns = {"time": r.time, "position": r.position, "velocity": r.velocity, "force": r.force,
                   "rotary": True, "headers": {"time": "time[s]", "position": "position[rad]",
                                               "velocity": "velocity[rad/s]", "force": "friction_torque[N*m]"}}
        exps.append(force_experiment(f"joint run{k}", f"run{k}.csv", temperature=r.temperature, role=r.role,
                                     description="look-alike (tests/lookalike_laws.py)",
                                     from_zero=lambda t, i: (t, i), motion=motion, flip_sign=False, columns=columns))
    return Dataset(name="joint", experiments=exps), runs


def true_values(T) -> dict:
    """Every truth parameter at ``T`` as the package names them."""
    return {n: law_value(n, T) for n in ("sigma0", "sigma1", "fc", "fs", "vs", "sigma2")}


__all__ = ["TEMPERATURES", "LAWS", "CONSTANTS", "ENCODER_17", "OFFSETS", "law_value", "truth_at", "law_runs",
           "law_experiments", "true_values", "np"]
