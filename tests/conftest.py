import os
import subprocess
import sys

import pytest

import thermofriction as tf

# run_cli's subprocesses may run in another folder (cwd=tmp_path): a relative PYTHONPATH such as
# PYTHONPATH=src must still find the same package the tests import
if os.environ.get("PYTHONPATH"):
    os.environ["PYTHONPATH"] = os.pathsep.join(os.path.abspath(p) for p in os.environ["PYTHONPATH"].split(os.pathsep)
                                               if p)


@pytest.fixture(scope="session")
def model_i():
    return tf.load_model("li2009-model-i")


@pytest.fixture(scope="session")
def model_ii():
    return tf.load_model("li2009-model-ii")


def run_cli(*args, cwd=None):
    """Runs the command line in a fresh interpreter, as a user would."""
    return subprocess.run([sys.executable, "-m", "thermofriction", *map(str, args)], capture_output=True,
                          text=True, cwd=cwd, timeout=300)


def synthetic_experiments(model, temperatures, *, noise=0.0, duration=1.0, sample_rate=10_000.0, seed=0,
                          rtol=1e-10):
    """Measured runs made by simulation plus white noise: a stand-in for a dataset's experiments."""
    import types

    import numpy as np

    rng = np.random.default_rng(seed)
    exps = []
    for T in temperatures:
        res = tf.simulate(model, duration, temperature=T, sample_rate=sample_rate,
                          controller=tf.StepSizeController(rtol=rtol))
        exps.append(types.SimpleNamespace(
            file=f"T{T:g}.csv", time=res.time, voltage=res.input, temperature=float(T), role="fit",
            displacement=res.displacement + noise * rng.standard_normal(res.time.size)))
    return exps


# The Canudas de Wit et al. (1995) friction set, and every friction model with those values where it
# has the parameter (tests of the heat model and of the real-time API)
CANUDAS = dict(sigma0=1e5, sigma1=1e5 ** 0.5, sigma2=0.4, fc=1.0, fs=1.5, vs=1e-3)


def every_friction_model():
    """name -> friction model object, one per kind (GMS with 3 elements)."""
    import thermofriction as tf
    return {
        "coulomb": tf.Coulomb(fc=1.0, sigma2=0.4, v_smooth=1e-4),
        "stribeck": tf.Stribeck(fc=1.0, fs=1.5, vs=1e-3, sigma2=0.4, v_smooth=1e-4),
        "dahl": tf.Dahl(sigma0=1e5, fc=1.0),
        "lugre": tf.LuGre(**CANUDAS),
        "elastoplastic": tf.ElastoPlastic(**CANUDAS, z_ba=3e-6),
        "gms": tf.GMS(k=[5e4, 3e4, 2e4], w=[0.3, 0.3, 0.4], C=20.0, fc=1.0, fs=1.5, vs=1e-3, sigma2=0.4),
    }
