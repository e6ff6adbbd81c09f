"""Shared by the benchmark scripts: time the C integrator apart from simulate()'s Python around it."""

import contextlib
import sys
import time


@contextlib.contextmanager
def core_timer():
    """While active, every call of the C integrator (``thermofriction._core.simulate``, as the
    bridge calls it for ``simulate`` and identification) appends its wall time [s] to the yielded list."""
    tfs = sys.modules["thermofriction._core"]
    core_simulate = tfs.simulate
    times = []

    def timed(*args):
        t0 = time.perf_counter()
        try:
            return core_simulate(*args)
        finally:
            times.append(time.perf_counter() - t0)

    tfs.simulate = timed
    try:
        yield times
    finally:
        tfs.simulate = core_simulate
