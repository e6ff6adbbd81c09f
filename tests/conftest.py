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
