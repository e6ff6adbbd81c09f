"""Signals for the command line: SIGINT, SIGTERM and SIGHUP become exceptions (so that temporaries are removed),
except inside a critical section -- a set of outputs being renamed into place, a temporary being removed -- after
which they take effect (:func:`critical`)."""

from __future__ import annotations

import contextlib
import signal

class Terminated(BaseException):
    """SIGTERM or SIGHUP arrived (raised by the handler :func:`install_signal_handlers` sets)."""

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum


_critical = 0        # > 0 while a set of renames runs: signals wait until it is done
_deferred = []       # signals that arrived meanwhile


def _handler(signum, frame):
    if _critical:
        _deferred.append(signum)
        return
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Terminated(signum)


def install_signal_handlers() -> dict:
    """SIGINT raises KeyboardInterrupt and SIGTERM/SIGHUP raise :class:`Terminated`, except while a
    set of outputs is being renamed into place (then they take effect right after it). Only the
    command line calls this (a library must not take over a program's signals); returns the
    previous handlers for :func:`restore_signal_handlers`."""
    previous = {}
    for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        with contextlib.suppress(ValueError, OSError):  # not the main thread
            old = signal.getsignal(s)
            if old is not signal.SIG_IGN:  # e.g. under nohup: keep ignoring
                signal.signal(s, _handler)
                previous[s] = old
    return previous


def restore_signal_handlers(previous: dict):
    for s, old in previous.items():
        with contextlib.suppress(ValueError, OSError, TypeError):
            signal.signal(s, old if old is not None else signal.SIG_DFL)


def raise_deferred():
    if _deferred:
        signum = _deferred[0]
        _deferred.clear()
        if signum == signal.SIGINT:
            raise KeyboardInterrupt
        raise Terminated(signum)




@contextlib.contextmanager
def critical(raise_after=True):
    """Signals wait while the block runs; with ``raise_after``, one that arrived meanwhile takes effect when it
    ends (not when the block is left by an exception, whose own handling comes first)."""
    global _critical
    _critical += 1
    try:
        yield
    finally:
        _critical -= 1
    if raise_after:
        raise_deferred()


__all__ = ["Terminated", "install_signal_handlers", "restore_signal_handlers", "critical", "raise_deferred"]
