"""Shared by the benchmark scripts: time the C integrator apart from simulate()'s Python around it."""

import contextlib
import sys
import time


@contextlib.contextmanager
def core_timer(clock=time.perf_counter):
    """While active, every call of the C integrator (``thermofriction._core.simulate``, as the
    bridge calls it for ``simulate`` and identification) appends its time [s] by ``clock`` (wall time
    by default; ``time.thread_time`` for the CPU time of the calling thread, which the core runs on)
    to the yielded list."""
    tfs = sys.modules["thermofriction._core"]
    core_simulate = tfs.simulate
    times = []

    def timed(*args):
        t0 = clock()
        try:
            return core_simulate(*args)
        finally:
            times.append(clock() - t0)

    tfs.simulate = timed
    try:
        yield times
    finally:
        tfs.simulate = core_simulate
