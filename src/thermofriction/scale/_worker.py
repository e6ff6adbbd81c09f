"""Preloaded by the local cluster's worker processes (Dask's ``preload``): they ignore SIGINT.

A terminal's Ctrl-C goes to every process of the job; the process that started the cluster
cancels the work and stops the workers itself, and a worker that took the signal too would only
print its own traceback."""

import signal
import threading


def dask_setup(worker):
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
