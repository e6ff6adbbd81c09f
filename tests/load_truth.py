"""A joint whose LuGre friction levels follow interacting laws of temperature and load, written here (not with
thermofriction's laws): runs at several (temperature, load) integrated by SciPy (tests/lookalike.py's LSODA), with
per-run sensor offsets and AR(1) noise, read as a dataset's force experiments would be (a load_torque[N*m] column)."""

from __future__ import annotations

import math

import numpy as np

from thermofriction.data.experiments import Dataset
from thermofriction.data.force import force_experiment
from lookalike import Truth, ar1, sample_times, true_friction

NOISE = 0.01      # [N m] AR(1) stationary standard deviation
RHO = 0.6         # its lag-one correlation
SIGMA0, SIGMA1, SIGMA2, VS = 100.0, 0.5, 0.10, 0.08


def fc_true(T, L):
    """Coulomb level [N m]: (0.40 - 0.003 T)(1 + 0.02 |L|) + 1e-4 T |L| (a product with interaction)."""
    return (0.40 - 0.003 * T) * (1.0 + 0.02 * abs(L)) + 1e-4 * T * abs(L)


def fs_true(T, L):
    """Static level [N m]: 0.55 - 0.004 T + 0.012 |L| (a gear's part affine in the load, summed)."""
    return 0.55 - 0.004 * T + 0.012 * abs(L)


def truth_at(T, L) -> Truth:
    fc, fs = fc_true(T, L), fs_true(T, L)
    return Truth(fc_pos=fc, fc_neg=fc, fs_pos=fs, fs_neg=fs, vs=VS, sigma0=SIGMA0, sigma1=SIGMA1, sigma2=SIGMA2,
                 ripple=0.0)


def runs(conditions, seed=0, roles=None, rate=100.0, duration=8.0, load_free=False):
    """A Dataset of one run per (temperature, load) in ``conditions``, and the true offsets; ``load_free``: the
    friction at zero load whatever the recorded load (a truth that does not depend on it)."""
    rng = np.random.default_rng(seed)
    exps, offsets = [], []
    for k, (T, L) in enumerate(conditions):
        n = int(duration * rate) + 1
        t = sample_times(n, rate, 0.05, rng)
        A, f = 0.6 * (1 + 0.1 * (k % 3)), 0.25 * (1 + 0.07 * (k % 4))
        x, _, F = true_friction(truth_at(T, 0.0 if load_free else L), t, A, f)
        offset = float(rng.uniform(-0.03, 0.03))
        offsets.append(offset)
        force = F + offset + ar1(n, RHO, NOISE, rng)
        load = L + rng.normal(0.0, 0.002 * max(abs(L), 1.0), n)  # a load cell's small noise around a constant load
        columns = {"time": t, "position": np.round(x / 1e-5) * 1e-5, "force": force, "load_torque": load,
                   "rotary": True, "headers": {"time": "time[s]", "position": "position[rad]",
                                               "force": "friction_torque[N*m]", "load_torque": "load_torque[N*m]"}}
        role = "fit" if roles is None else roles[k]
        exps.append(force_experiment(f"run{k}", f"run{k}.csv", temperature=float(T), role=role, description="",
                                     from_zero=lambda t, i: (t, i), columns=columns))
    return Dataset(name="load-truth", experiments=exps), offsets


# -- a preloaded linear stage -------------------------------------------------------------------------------------
#: the stage's AR(1) force noise [N], its lag-one correlation, and the encoder's step [m]
STAGE_NOISE, STAGE_RHO, STAGE_ENCODER = 0.05, 0.7, 1e-7
STAGE_SIGMA0, STAGE_SIGMA1, STAGE_SIGMA2, STAGE_VS = 2e5, 80.0, 40.0, 0.003  # N/m, N s/m, N s/m, m/s


def stage_fc(T, N):
    """Coulomb level [N] of the stage: 1.5 - 0.01 T + 0.05 |N| - 2e-4 T |N| (a preload's part summed to the
    unloaded level, its coefficient falling with temperature: an interaction)."""
    return 1.5 - 0.01 * T + 0.05 * abs(N) - 2e-4 * T * abs(N)


def stage_fs(T, N):
    """Static level [N]: (2.0 - 0.008 T)(1 + 0.03 |N|) (a product with the load)."""
    return (2.0 - 0.008 * T) * (1.0 + 0.03 * abs(N))


def stage_truth(T, N) -> Truth:
    fc, fs = stage_fc(T, N), stage_fs(T, N)
    return Truth(fc_pos=fc, fc_neg=fc, fs_pos=fs, fs_neg=fs, vs=STAGE_VS, sigma0=STAGE_SIGMA0, sigma1=STAGE_SIGMA1,
                 sigma2=STAGE_SIGMA2, ripple=0.0)


def stage_runs(conditions, seed=0, roles=None, rate=200.0, duration=6.0):
    """A Dataset of a preloaded linear stage, one run per (temperature, normal force) in ``conditions``, integrated
    by SciPy's LSODA (lookalike.true_friction, the truth's levels from stage_fc and stage_fs), with a per-run
    offset up to 0.2 N, AR(1) noise (STAGE_NOISE, STAGE_RHO), a position quantised to STAGE_ENCODER and a
    normal_force[N] column with a load cell's noise; and the true offsets."""
    rng = np.random.default_rng(seed)
    exps, offsets = [], []
    for k, (T, N) in enumerate(conditions):
        n = int(duration * rate) + 1
        t = sample_times(n, rate, 0.05, rng)
        A, f = 0.005 * (1 + 0.1 * (k % 3)), 0.5 * (1 + 0.07 * (k % 4))
        x, _, F = true_friction(stage_truth(T, N), t, A, f)
        offset = float(rng.uniform(-0.2, 0.2))
        offsets.append(offset)
        force = F + offset + ar1(n, STAGE_RHO, STAGE_NOISE, rng)
        load = N + rng.normal(0.0, 0.002 * abs(N), n)
        columns = {"time": t, "position": np.round(x / STAGE_ENCODER) * STAGE_ENCODER, "force": force,
                   "normal_force": load, "rotary": False,
                   "headers": {"time": "time[s]", "position": "position[m]", "force": "friction_force[N]",
                               "normal_force": "normal_force[N]"}}
        role = "fit" if roles is None else roles[k]
        exps.append(force_experiment(f"stage{k}", f"stage{k}.csv", temperature=float(T), role=role, description="",
                                     from_zero=lambda t, i: (t, i), columns=columns))
    return Dataset(name="stage-truth", experiments=exps), offsets


def write_stage(folder, dataset) -> str:
    """``dataset`` (stage_runs') written as a dataset folder: one CSV per run (time[s], position[m],
    friction_force[N], normal_force[N]) and dataset.toml; returns the folder."""
    import tomli_w
    from pathlib import Path
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    entries = []
    for e in dataset.experiments:
        load = np.full(len(e.time), float(e.load))
        np.savetxt(folder / e.file, np.column_stack([e.time, e.displacement, e.force, load]), delimiter=",",
                   header="time[s],position[m],friction_force[N],normal_force[N]", comments="", fmt="%.12g")
        entries.append({"file": e.file, "temperature": float(e.temperature), "role": e.role})
    (folder / "dataset.toml").write_text(tomli_w.dumps({"name": "stage", "experiment": entries}))
    return str(folder)


STAGE_MODEL = """[plant]
type = "prescribed"
motion = "linear"

[friction]
model = "lugre"
sigma0 = 2e5
sigma1 = 80.0
sigma2 = 30.0
vs = 0.003

[thermal]
model = "I"
fc = { law = "linear", a = -0.005, b = 1.2, load = { law = "affine", k = 0.03 } }
fs = { law = "linear", a = -0.0002, b = 0.1, load = { law = "proportional" } }
"""
