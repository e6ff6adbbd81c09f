"""Force (torque) datasets made by the independent reference implementation (tests/reference), not by the C
core: a joint or a stage under a sine motion (optionally two, summed, through a sampled position), its friction
force from SciPy's solve_ivp, sampled with jitter, plus white noise and a constant sensor offset. Written as CSV
files by NumPy in the units asked for (deg, mN*m, ...), so that reading and unit conversion are tested too."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import tomli_w

sys.path.insert(0, str(Path(__file__).resolve().parent))
import reference as R  # noqa: E402

import thermofriction as tf  # noqa: E402

_SCALE = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "rad": 1.0, "deg": math.pi / 180, "N": 1.0, "mN": 1e-3,
          "N*m": 1.0, "mN*m": 1e-3, "m/s": 1.0, "mm/s": 1e-3, "rad/s": 1.0, "deg/s": math.pi / 180}


def jittered_times(n, duration, rng, jitter=0.3):
    """``n`` samples over ``duration``, each moved by up to ``jitter`` of the nominal interval (a logger's
    clock); strictly increasing, starting at 0."""
    dt = duration / (n - 1)
    t = np.arange(n) * dt + rng.uniform(-jitter, jitter, n) * dt
    t[0] = 0.0
    return np.maximum.accumulate(t)


def reference_run(model, t, amplitude, frequency, temperature):
    """(position, velocity, friction force) of ``model`` under ``amplitude sin(2 pi frequency t)``, by the
    reference integrator (rtol 1e-10)."""
    w = tf.Sine(amplitude=amplitude, frequency=frequency)
    res = R.reference_simulate_system(model, t, temperature=temperature, input=w, rtol=1e-10)
    v = amplitude * 2 * math.pi * frequency * np.cos(2 * math.pi * frequency * t)
    return amplitude * np.sin(2 * math.pi * frequency * t), v, np.asarray(res.friction_force)


def write_experiment(path, t, x, v, F, T=None, units=("rad", "rad/s", "N*m"), velocity=True, temperature_column=False):
    """Writes one experiment CSV in ``units`` (position, velocity, force)."""
    xu, vu, fu = units
    rotary = fu.endswith("*m")
    head = ["time[s]", f"position[{xu}]"]
    cols = [t, x / _SCALE[xu]]
    if velocity:
        head.append(f"velocity[{vu}]")
        cols.append(v / _SCALE[vu])
    head.append(f"friction_torque[{fu}]" if rotary else f"friction_force[{fu}]")
    cols.append(F / _SCALE[fu])
    if temperature_column:
        head.append("temperature[C]")
        cols.append(np.full_like(t, T))
    np.savetxt(path, np.column_stack(cols), delimiter=",", header=",".join(head), comments="", fmt="%.12g")


def make_dataset(folder, model, *, temperatures=(35.0,), validate=(), n=1200, duration=4.0, amplitude=0.5,
                 frequency=0.5, noise=0.01, offset=0.05, seed=0, units=("rad", "rad/s", "N*m"), velocity=True,
                 validate_offset=None):
    """A dataset folder of ``model``'s friction under sine motions (one run per temperature; ``validate``
    temperatures held out), with jitter, noise (a fraction of the force's range) and a sensor offset.
    ``validate_offset``: the held-out runs' sensor offset, when it differs (a sensor re-zeroed between runs).
    Returns the folder and the noise's standard deviation in SI units."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    entries, sd = [], None
    runs = [(T, "fit") for T in temperatures] + [(T, "validate") for T in validate]
    for k, (T, role) in enumerate(runs):
        t = jittered_times(n, duration, rng)
        x, v, F = reference_run(model, t, amplitude * (1 + 0.1 * k), frequency * (1 + 0.07 * k), T)
        sd = noise * float(np.ptp(F)) if sd is None else sd
        bias = validate_offset if role == "validate" and validate_offset is not None else offset
        F = F + bias + rng.normal(0.0, sd, F.size)
        name = f"run{k}-T{T:g}C{'-validate' if role == 'validate' else ''}.csv"
        write_experiment(folder / name, t, x, v, F, T, units, velocity)
        entries.append({"file": name, "temperature": float(T), "role": role})
    (folder / "dataset.toml").write_text(tomli_w.dumps({"name": "force-truth", "experiment": entries}))
    return folder, sd
