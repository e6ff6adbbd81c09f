import subprocess
import sys

import pytest

import thermofriction as tf


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
