"""Progress of the command line's long work on standard error, one implementation for every command.

On a terminal: a bar for counted work (draws, points, datasets, experiments), a status line for work in
stages (identification, reading a file). On a pipe or a file -- a CI log, a scheduler's job, ``nohup`` --
plain lines instead, from a clock rather than from the work (a stage or a chunk may last minutes): at most
one every :func:`interval` seconds, each saying what is being done, how far and, for counted work once some
is done, about how long is left; work that ends within the interval prints nothing. The library itself
never prints: it calls ``progress`` back, and the command line hands it :meth:`Progress.count` or
:meth:`Progress.stage`.
"""

from __future__ import annotations

import math
import os
import sys
import threading
import time

from .errors import InputError

#: [s] on a pipe or a file, a progress line at most this often (and none for shorter work)
INTERVAL = 5.0
#: the environment variable that sets another interval (tests use a short one)
INTERVAL_ENV = "THERMOFRICTION_PROGRESS_INTERVAL"


def interval() -> float:
    """The seconds between plain progress lines: ``THERMOFRICTION_PROGRESS_INTERVAL`` when set, else INTERVAL."""
    text = os.environ.get(INTERVAL_ENV, "").strip()
    if not text:
        return INTERVAL
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (value > 0 and math.isfinite(value)):
        raise InputError(f"{INTERVAL_ENV}={text!r}: must be a positive number of seconds")
    return value


def duration(seconds: float) -> str:
    """'under 1 s', '42 s', '3 min 5 s', '2 h 10 min': a time as a person reads it in a log."""
    s = int(round(seconds))
    if s < 1:
        return "under 1 s"
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60} s"
    return f"{s // 3600} h {s % 3600 // 60} min"


def _left(seconds: float) -> str:
    return "under 1 s left" if seconds < 0.5 else f"about {duration(seconds)} left"


class Progress:
    """``label``'s progress: ``count(done)`` of ``total`` ``unit`` (counted work), or ``stage(message)``.

    A context manager; ``enabled=False`` (--quiet) shows nothing. ``stream`` and ``terminal`` are for tests
    (default: standard error, and whether it is a terminal)."""

    def __init__(self, label, total=None, unit="", *, enabled=True, stream=None, terminal=None):
        self.label, self.total, self.unit = label, total, unit
        self.done, self.message = 0, None
        self._stream = stream if stream is not None else sys.stderr
        self._bar = self._thread = None
        if not enabled:
            return
        if terminal if terminal is not None else _isatty(self._stream):
            self._bar = _RichBar(label, total)
            return
        self._every, self._t0 = interval(), time.monotonic()
        self._stopped = threading.Event()
        self._thread = threading.Thread(target=self._lines, name="thermofriction-progress", daemon=True)
        self._thread.start()

    def count(self, done):
        """``done`` of the total finished (the library's ``progress(done)``)."""
        self.done = done
        if self._bar is not None:
            self._bar.count(done)

    def stage(self, message):
        """What is being done now (identification's ``progress(message)``; "reading FILE")."""
        self.message = str(message)
        if self._bar is not None:
            self._bar.stage(self.message)

    def line(self, now=None) -> str:
        """The plain line for now: what, how far, how long so far and, where a count allows it, how long is left."""
        elapsed = (time.monotonic() if now is None else now) - self._t0
        what = f"thermofriction: {self.label}: " + (f"{self.message}; " if self.message else "")
        if self.total is None:
            return f"{what}{duration(elapsed)} so far"
        done, total = self.done, self.total
        pct = f" ({100 * done / total:.0f} %)" if total else ""
        left = (f", {_left(elapsed * (total - done) / done)}" if 0 < done < total
                else ", time left not known yet" if done == 0 else "")
        return f"{what}{done:,} of {total:,} {self.unit}{pct} in {duration(elapsed)}{left}"

    def _lines(self):
        while not self._stopped.wait(self._every):
            try:
                print(self.line(), file=self._stream, flush=True)
            except (OSError, ValueError):  # stderr closed or a broken pipe: the work goes on without lines
                return

    def stop(self):
        if self._thread is not None:
            self._stopped.set()
            self._thread.join()
            self._thread = None
        if self._bar is not None:
            self._bar.stop()
            self._bar = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop()


def _isatty(stream) -> bool:
    try:
        return stream.isatty()
    except (AttributeError, ValueError):  # a closed or a stand-in stream
        return False


class _RichBar:
    """rich (loaded only on a terminal): a transient bar with the time left for counted work, a status line
    for stages."""

    def __init__(self, label, total):
        from rich.console import Console
        from rich.progress import (BarColumn, MofNCompleteColumn, Progress, SpinnerColumn, TextColumn,
                                   TimeElapsedColumn, TimeRemainingColumn)
        counted = total is not None
        columns = ((TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeRemainingColumn())
                   if counted else (SpinnerColumn(), TextColumn("{task.description}"), TimeElapsedColumn()))
        self._label = label
        self._bar = Progress(*columns, console=Console(stderr=True), transient=True)
        self._task = self._bar.add_task(label, total=total)
        self._bar.start()

    def count(self, done):
        self._bar.update(self._task, completed=done)

    def stage(self, message):
        self._bar.update(self._task, description=f"{self._label}: {message}")

    def stop(self):
        self._bar.stop()


__all__ = ["Progress", "interval", "duration", "INTERVAL", "INTERVAL_ENV"]
