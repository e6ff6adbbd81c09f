"""Where the work runs: threads in this process (the default: the C core releases the GIL while it
integrates), in order in this process (``scheduler="sequential"``, the baseline), an embedded local
Dask cluster of worker processes (``scheduler="processes"``), or an existing Dask cluster (an
address or a ``distributed.Client``).

Dask is imported here only, and only when a cluster is used, so that ``import thermofriction``
stays light. Every workload of this package is a list of independent tasks (a chunk of sweep
points, one dataset, a chunk of draws) whose result depends only on its arguments: the scheduler
may run them anywhere, in any order, and run one again when the worker holding it dies; the
results are put back in task order, so they equal a sequential run's to the last bit.

Chunks (:func:`chunk_spans`): consecutive items per task, sized from the measured time of one item
so that a task's overhead (~2.5 ms on Dask, ~0.05 ms on threads) stays a small share of its work,
largest first and shrinking towards the end, so that every worker gets several and the last ones
finish together (guided self-scheduling).
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import contextlib
import gc
import logging
import os
import pickle
import sys
import time
import uuid

from .. import _args
from .._warning_routes import RoutedWarnings, recorded_warnings, route_this_thread
from ..errors import ComputationError, InputError, shorten
from .chunks import CHUNK_SECONDS, chunk_spans
from .connect import probe, read_scheduler_file

SEQUENTIAL = "sequential"
THREADS = "threads"
PROCESSES = "processes"
#: the scheduler=/--scheduler values that name a way of running here rather than a cluster's address
LOCAL = (SEQUENTIAL, THREADS, PROCESSES)

def _distributed():
    try:
        import distributed
    except ImportError:  # pragma: no cover - a runtime dependency; only a broken install lacks it
        raise InputError("running on a cluster needs Dask's distributed scheduler: pip install 'dask[distributed]' "
                         "(or scheduler='sequential' to run in this process)") from None
    return distributed


def is_client(obj) -> bool:
    mod = sys.modules.get("distributed")
    return mod is not None and isinstance(obj, mod.Client)


def check_scheduler(scheduler):
    """None (threads in this process), "sequential", "threads", "processes" (a local Dask cluster), an
    address (tcp://HOST:PORT, a host:port, a scheduler file) or a Client."""
    if scheduler is None or (isinstance(scheduler, str) and scheduler in LOCAL) or is_client(scheduler):
        return scheduler
    if isinstance(scheduler, (str, os.PathLike)) and str(scheduler).strip():
        return str(scheduler).strip()
    raise InputError(f"scheduler must be None (threads in this process), 'sequential', 'threads', 'processes' "
                     f"(a local Dask cluster), an address such as tcp://HOST:8786, or a distributed.Client; "
                     f"got {shorten(scheduler)}")


def check_options(scheduler=None, workers=None, batch_size=None, progress=None):
    """The options of where and how the work runs, as sweep, propagate and identify_fleet take them,
    checked before any work: one InputError naming the argument."""
    check_scheduler(scheduler)
    _args.whole(workers, "workers", none=True, low=1)
    _args.whole(batch_size, "batch_size", none=True, low=1)
    _args.function(progress, "progress")


class Runner:
    """Runs tasks ``fn(*args)`` on the chosen scheduler and hands back their results in task order.

    ``with Runner(scheduler, workers) as r: results = r.map(fn, arg_tuples, progress=...)``, or
    ``spans, results = r.map_chunks(fn, n_items, args_of, ...)`` for items cut into chunks here.
    ``progress(done_weight)`` is called after each task with the sum of the finished tasks'
    weights. A task that raises stops the run (the task functions of this package catch the
    failures of single points and datasets themselves and return them as results).

    Parameters
    ----------
    scheduler : str or distributed.Client, optional
        None or "threads", "sequential", "processes", an address (``tcp://HOST:8786``, a scheduler file) or a
        ``distributed.Client``, as for ``sweep``.
    workers : int, optional
        The threads or processes; default one per core.

    Raises
    ------
    InputError
        A scheduler or a number of workers that is not one, named.
    """

    def __init__(self, scheduler=None, workers=None):
        check_options(scheduler, workers)
        self.scheduler = check_scheduler(scheduler)
        self.workers = workers
        self.client = self._cluster = self._pool = None
        self._failing = False
        self._stack = contextlib.ExitStack()

    @property
    def sequential(self) -> bool:
        return self.scheduler == SEQUENTIAL

    @property
    def kind(self) -> str:
        """"sequential", "threads" or "dask"."""
        if self.sequential:
            return "sequential"
        return "threads" if self.scheduler in (None, THREADS) else "dask"

    def __enter__(self):
        if self.sequential:
            return self
        try:
            self._start()
        except BaseException:
            self._stack.close()
            raise
        return self

    def _start(self):
        if self.kind == "threads":
            # the C core releases the GIL while it integrates: threads of this process use every core,
            # with nothing to start, to pickle or to send
            self._threads = self.workers or os.cpu_count() or 1
            self._pool = concurrent.futures.ThreadPoolExecutor(
                max_workers=self._threads, thread_name_prefix="thermofriction-scale", initializer=route_this_thread)
            self._stack.callback(self._stop_pool)
            return
        distributed = _distributed()
        if is_client(self.scheduler):
            self.client = self.scheduler  # the caller's: used, not closed
            return
        if self.scheduler == PROCESSES:
            # processes, one thread each: a crash or a leak in one worker does not take the others (or
            # this process) with it
            n = self.workers or os.cpu_count() or 1
            # the workers ignore Ctrl-C (scale/_worker.py): this process stops them
            self._cluster = self._stack.enter_context(distributed.LocalCluster(
                n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                silence_logs=logging.CRITICAL, preload=["thermofriction.scale._worker"]))
            self.client = self._stack.enter_context(distributed.Client(self._cluster))
            return
        address = self.scheduler
        if os.path.exists(address):  # a scheduler file: read here, so that a damaged one is one message
            address = read_scheduler_file(address)
        probe(address)
        try:
            # the wait is Dask's own (distributed.comm.timeouts.connect, 30 s unless configured)
            self.client = self._stack.enter_context(distributed.Client(address=address))
            return
        except MemoryError:  # a reply whose first bytes, read as a length, ask for exabytes
            failure = "cannot connect (its reply is not Dask's protocol): not a Dask scheduler; start one with " \
                      "'dask scheduler' (docs/scale.md)"
        except Exception as e:  # noqa: BLE001 - OSError, TimeoutError, and whatever Dask raises on a reply it
            # cannot read (an AssertionError): all mean that no scheduler can be used there
            failure = (f"cannot connect ({shorten(str(e) or type(e).__name__, 200)}); start one with 'dask scheduler' "
                       f"and 'dask worker ADDRESS' (docs/scale.md)")
        # The Client that failed to start is garbage in a reference cycle (through the exception's frames), with
        # its IO loop running. Collected here, outside the except block, its __del__ closes it now; left to a
        # later collection, that close may run inside the next Client's start, which holds the lock of Dask's
        # loop runners that the close takes too: the next run hangs for ever (issue 41).
        gc.collect()
        raise InputError(f"scheduler {address}: {failure}")

    def _stop_pool(self):
        # after Ctrl-C or a failed task: the chunks not started are dropped, the running ones end by
        # themselves (a chunk is at most about CHUNK_MAX_SECONDS of work)
        self._pool.shutdown(wait=not self._failing, cancel_futures=True)

    def __exit__(self, *exc):
        self._failing = exc[0] is not None
        self._stack.close()
        return False

    def n_workers(self) -> int:
        """The workers available now (1 in sequential mode)."""
        if self._pool is not None:
            return self._threads
        if self.client is None:
            return 1
        try:
            return max(len(self.client.scheduler_info(n_workers=-1)["workers"]), 1)
        except TypeError:  # older distributed: no n_workers argument
            return max(len(self.client.scheduler_info()["workers"]), 1)
        except Exception:  # noqa: BLE001 - a hint for chunk sizes only
            return 1

    def describe(self) -> str:
        if self._pool is not None:
            return f"{self.n_workers()} threads in this process"
        if self.client is None:
            return "in this process, in order"
        where = ("a local Dask cluster" if self._cluster is not None
                 else f"Dask scheduler {self.client.scheduler.address}")
        return f"{where} ({self.n_workers()} workers)"

    def map_chunks(self, fn, n_items: int, args_of, *, batch_size=None, item_seconds=None, largest=None,
                   progress=None, on_error=None, records_warnings=False):
        """``fn(*args_of(a, b))`` for consecutive chunks [a, b) covering range(n_items): (spans, results),
        both in item order. Chunk sizes: ``batch_size`` items each when given; else from ``item_seconds``
        (one item's time [s]), or, when it is not known, from timing the first items here (which are
        then the first chunks: none runs twice) -- see :func:`chunk_spans`. ``largest``: items per chunk at
        most. ``on_error(span, reason)``: the result of a chunk the cluster could not run.
        ``records_warnings``: ``fn`` records its warnings (recorded_warnings), every one."""
        spans, results = [], []
        first = progress_offset = 0
        if batch_size is None and item_seconds is None and n_items > 0:
            # the first items here, one chunk of 1, 2, 4, ... until ~CHUNK_SECONDS of work: their time per item
            t0, size = time.perf_counter(), 1
            limit = max(1, n_items // 50)
            while first < min(limit, n_items) and time.perf_counter() - t0 < CHUNK_SECONDS[self.kind]:
                b = min(first + size, limit, first + (largest or size))
                results.append(fn(*args_of(first, b)))
                spans.append((first, b))
                first, size = b, 2 * size
                if progress:
                    progress(first)
            item_seconds = (time.perf_counter() - t0) / first
            progress_offset = first
        rest = chunk_spans(n_items - first, self.n_workers(), item_seconds, kind=self.kind, batch_size=batch_size,
                           largest=largest)
        rest = [(a + first, b + first) for a, b in rest]
        report = (lambda done: progress(progress_offset + done)) if progress else None
        lost = (lambda i, reason: on_error(rest[i], reason)) if on_error else None
        results += self.map(fn, [args_of(a, b) for a, b in rest], weights=[b - a for a, b in rest], progress=report,
                            on_error=lost, records_warnings=records_warnings)
        return spans + rest, results

    def map(self, fn, arg_tuples, weights=None, progress=None, on_error=None, records_warnings=False) -> list:
        """``on_error(i, reason)``: the result of task i when the cluster could not run it (its
        worker died every time it ran it, e.g. a crash); without it such a task stops the run.
        ``records_warnings``: the tasks record their warnings (recorded_warnings), every one."""
        arg_tuples = list(arg_tuples)
        weights = list(weights) if weights is not None else [1] * len(arg_tuples)
        done = 0
        if self._pool is not None:
            return self._map_threads(fn, arg_tuples, weights, progress, records_warnings)
        if self.client is None:
            results = []
            for args, w in zip(arg_tuples, weights):
                results.append(fn(*args))
                done += w
                if progress:
                    progress(done)
            return results
        distributed = _distributed()
        # one unique key per task: pure=False would also do, but named keys read well in the dashboard
        tag = uuid.uuid4().hex[:12]
        name = getattr(fn, "__name__", "task").lstrip("_")
        futures = [self.client.submit(_call, fn, pickle.dumps(args, protocol=pickle.HIGHEST_PROTOCOL),
                                      key=f"thermofriction-{name}-{tag}-{i}", pure=False)
                   for i, args in enumerate(arg_tuples)]
        index = {f.key: i for i, f in enumerate(futures)}
        results = [None] * len(futures)
        try:
            for fut in distributed.as_completed(futures):
                i = index[fut.key]
                try:
                    results[i] = pickle.loads(fut.result())
                except (Exception, asyncio.CancelledError) as e:  # a killed worker, a lost scheduler
                    reason = ("its worker died each time it ran (a crash or out of memory?)"
                              if type(e).__name__ == "KilledWorker" else
                              f"the cluster could not run it ({type(e).__name__}: {e})")
                    if on_error is None or isinstance(e, asyncio.CancelledError):
                        raise ComputationError(reason) from None
                    results[i] = on_error(i, reason)
                fut.release()
                done += weights[i]
                if progress:
                    progress(done)
        except BaseException:  # Ctrl-C, a lost scheduler: drop the rest, keep nothing
            with contextlib.suppress(Exception):
                self.client.cancel(futures)
            raise
        return results

    def _map_threads(self, fn, arg_tuples, weights, progress, records_warnings) -> list:
        """The tasks on the pool's threads, the arguments as they are (nothing is pickled: a task must not
        change its arguments, and the package's task functions do not). A task that raises stops the run,
        as in sequential mode."""
        results = [None] * len(arg_tuples)
        done = 0
        with RoutedWarnings(always=records_warnings):
            futures = {self._pool.submit(fn, *args): i for i, args in enumerate(arg_tuples)}
            try:
                for fut in concurrent.futures.as_completed(futures):
                    i = futures[fut]
                    results[i] = fut.result()
                    done += weights[i]
                    if progress:
                        progress(done)
            except BaseException:  # Ctrl-C, a task that raised: drop the chunks not started
                for fut in futures:
                    fut.cancel()
                raise
        return results


def _call(fn, payload: bytes) -> bytes:
    """A task as the workers run it: arguments and result travel as pickles of our own, because
    Dask hands NumPy arrays over as read-only views of its network buffers, which the C core's
    binding refuses as outputs (and a model or dataset must come out as it went in)."""
    return pickle.dumps(fn(*pickle.loads(payload)), protocol=pickle.HIGHEST_PROTOCOL)


__all__ = ["Runner", "SEQUENTIAL", "THREADS", "PROCESSES", "check_scheduler", "check_options", "read_scheduler_file",
           "chunk_spans", "is_client", "recorded_warnings"]
