"""Where the work runs: Dask's distributed scheduler (an embedded local cluster by default, or an
existing one), or in order in this process (``scheduler="sequential"``, the baseline).

Dask is imported here only, and only when a cluster is used, so that ``import thermofriction``
stays light. Every workload of this package is a list of independent tasks (a batch of sweep
points, one dataset, a batch of draws) whose result depends only on its arguments: the scheduler
may run them anywhere, in any order, and run one again when the worker holding it dies; the
results are put back in task order, so they equal a sequential run's.
"""

from __future__ import annotations

import asyncio
import contextlib
import logging
import math
import os
import pickle
import sys
import uuid

from ..errors import ComputationError, InputError, shorten

SEQUENTIAL = "sequential"


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
    """None, "sequential", an address (tcp://HOST:PORT, a host:port, a scheduler file) or a Client."""
    if scheduler is None or (isinstance(scheduler, str) and scheduler == SEQUENTIAL) or is_client(scheduler):
        return scheduler
    if isinstance(scheduler, (str, os.PathLike)) and str(scheduler).strip():
        return str(scheduler).strip()
    raise InputError(f"scheduler must be None (a local cluster), 'sequential', an address such as "
                     f"tcp://HOST:8786, or a distributed.Client; got {shorten(scheduler)}")


#: a Dask scheduler file is a few hundred bytes of JSON (dask scheduler --scheduler-file)
_SCHEDULER_FILE_LIMIT = 1 << 20
#: a Dask message's 8-byte length prefix beyond this is not a greeting (text read as a length: ~1e18)
_GREETING_LIMIT = 1 << 26


def read_scheduler_file(path) -> str:
    """The address in a scheduler file (JSON with an ``address``, as ``dask scheduler --scheduler-file``
    writes it), or one InputError naming the file: Dask's own reader fails on a damaged file with an
    AssertionError or a KeyError."""
    from .._reading import read_text

    what = "a Dask scheduler file (JSON with an \"address\", as 'dask scheduler --scheduler-file' writes)"
    try:
        if os.path.getsize(path) > _SCHEDULER_FILE_LIMIT:
            raise InputError(f"scheduler {path}: not {what}: {os.path.getsize(path)} bytes")
        text = read_text(path, "scheduler file")
    except OSError as e:
        raise InputError(f"scheduler {path}: cannot read ({e.strerror or e})") from None
    except UnicodeDecodeError:
        raise InputError(f"scheduler {path}: not {what}: not UTF-8 text") from None
    import json
    try:
        info = json.loads(text)
    except ValueError as e:
        raise InputError(f"scheduler {path}: not {what}: {e}") from None
    address = info.get("address") if isinstance(info, dict) else None
    if not isinstance(address, str) or not address.strip():
        raise InputError(f"scheduler {path}: not {what}: no \"address\" in it")
    return address.strip()


def _probe(address):
    """For a TCP address: when something answers there, that it greets as a Dask scheduler does (at once,
    with a message of a plausible length), so that an HTTP or SSH server is named as not a scheduler instead
    of Dask waiting forever or reading its text as a 3 EiB message ("out of memory"). Nothing listening, or
    another protocol (tls://, ucx://): left to Dask, which retries until its connect timeout."""
    import re
    import socket
    import struct

    m = re.fullmatch(r"(?:tcp://)?\[?([^\[\]/]+?)\]?:(\d+)/?", address)
    if m is None:
        return
    host, port = m.group(1), int(m.group(2))
    timeout = _connect_timeout()
    try:
        sock = socket.create_connection((host, port), timeout=timeout)
    except OSError:
        return  # Dask tries again until its timeout and then says so
    with sock:
        head = b""
        try:
            while len(head) < 8:
                chunk = sock.recv(8 - len(head))
                if not chunk:
                    break
                head += chunk
        except OSError:  # socket.timeout included
            pass
    if len(head) < 8:
        said = f"it sent {head!r} and closed the connection" if head else f"it said nothing within {timeout:g} s"
        raise InputError(f"scheduler {address}: not a Dask scheduler ({said}; a scheduler greets a client at once); "
                         f"start one with 'dask scheduler' (docs/scale.md)")
    (length,) = struct.unpack("<Q", head)
    if not 0 < length <= _GREETING_LIMIT:
        raise InputError(f"scheduler {address}: not a Dask scheduler (it answered {head!r}...); start one with "
                         f"'dask scheduler' (docs/scale.md)")


def _connect_timeout() -> float:
    """Dask's connect timeout [s] (distributed.comm.timeouts.connect), 30 s where it cannot be read."""
    try:
        import dask.config
        from dask.utils import parse_timedelta
        return float(parse_timedelta(dask.config.get("distributed.comm.timeouts.connect"), default="s"))
    except Exception:  # noqa: BLE001 - a hint only
        return 30.0


class Runner:
    """Runs tasks ``fn(*args)`` on the chosen scheduler and hands back their results in task order.

    ``with Runner(scheduler, workers) as r: results = r.map(fn, arg_tuples, progress=...)``.
    ``progress(done_weight)`` is called after each task with the sum of the finished tasks'
    weights. A task that raises stops the run (the task functions of this package catch the
    failures of single points and datasets themselves and return them as results)."""

    def __init__(self, scheduler=None, workers=None):
        self.scheduler = check_scheduler(scheduler)
        if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
            raise InputError(f"workers must be a positive whole number, got {shorten(workers)}")
        self.workers = workers
        self.client = self._cluster = None
        self._stack = contextlib.ExitStack()

    @property
    def sequential(self) -> bool:
        return self.scheduler == SEQUENTIAL

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
        distributed = _distributed()
        if is_client(self.scheduler):
            self.client = self.scheduler  # the caller's: used, not closed
            return
        if self.scheduler is None:
            # processes, one thread each: the C core releases the GIL, but a crash or a leak in one
            # worker must not take the others (or this process) with it
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
        _probe(address)
        try:
            # the wait is Dask's own (distributed.comm.timeouts.connect, 30 s unless configured)
            self.client = self._stack.enter_context(distributed.Client(address=address))
        except MemoryError:  # a reply whose first bytes, read as a length, ask for exabytes
            raise InputError(f"scheduler {address}: cannot connect (its reply is not Dask's protocol): not a Dask "
                             f"scheduler; start one with 'dask scheduler' (docs/scale.md)") from None
        except Exception as e:  # noqa: BLE001 - OSError, TimeoutError, and whatever Dask raises on a reply it
            # cannot read (an AssertionError): all mean that no scheduler can be used there
            raise InputError(f"scheduler {address}: cannot connect ({shorten(str(e) or type(e).__name__, 200)}); "
                             f"start one with 'dask scheduler' and 'dask worker ADDRESS' (docs/scale.md)") from None

    def __exit__(self, *exc):
        self._stack.close()
        return False

    def n_workers(self) -> int:
        """The workers available now (1 in sequential mode)."""
        if self.client is None:
            return 1
        try:
            return max(len(self.client.scheduler_info(n_workers=-1)["workers"]), 1)
        except TypeError:  # older distributed: no n_workers argument
            return max(len(self.client.scheduler_info()["workers"]), 1)
        except Exception:  # noqa: BLE001 - a hint for batch sizes only
            return 1

    def describe(self) -> str:
        if self.client is None:
            return "in this process, in order"
        where = "a local Dask cluster" if self._cluster is not None else f"Dask scheduler {self.client.scheduler.address}"
        return f"{where} ({self.n_workers()} workers)"

    def map(self, fn, arg_tuples, weights=None, progress=None, on_error=None) -> list:
        """``on_error(i, reason)``: the result of task i when the cluster could not run it (its
        worker died every time it ran it, e.g. a crash); without it such a task stops the run."""
        arg_tuples = list(arg_tuples)
        weights = list(weights) if weights is not None else [1] * len(arg_tuples)
        done = 0
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


def _call(fn, payload: bytes) -> bytes:
    """A task as the workers run it: arguments and result travel as pickles of our own, because
    Dask hands NumPy arrays over as read-only views of its network buffers, which the C core's
    binding refuses as outputs (and a model or dataset must come out as it went in)."""
    return pickle.dumps(fn(*pickle.loads(payload)), protocol=pickle.HIGHEST_PROTOCOL)


def batches(n: int, size: int):
    """(start, stop) of consecutive batches of ``size`` covering range(n)."""
    return [(i, min(i + size, n)) for i in range(0, n, size)]


def auto_batch_size(n_items: int, n_workers: int, per_worker: int = 8, largest: int = 500) -> int:
    """Enough tasks to keep every worker busy and to lose little when one dies (``per_worker``
    batches each), but many items per task so that the scheduler's overhead stays small."""
    return int(min(max(math.ceil(n_items / (per_worker * max(n_workers, 1))), 1), largest))


def progress_bar(total, label, enabled=True):
    """A rich progress bar on stderr (on a terminal only): returns (update(done), stop())."""
    if not enabled or not sys.stderr.isatty():
        return None, (lambda: None)
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn
    bar = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn(),
                   console=Console(stderr=True), transient=True)
    task = bar.add_task(label, total=total)
    bar.start()
    return (lambda done: bar.update(task, completed=done)), bar.stop


__all__ = ["Runner", "SEQUENTIAL", "check_scheduler", "read_scheduler_file", "batches", "auto_batch_size", "progress_bar", "is_client"]
