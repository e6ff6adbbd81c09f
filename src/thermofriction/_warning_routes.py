"""Warnings recorded per task when tasks run side by side on threads.

``warnings.catch_warnings`` changes the warnings module's global state (its filters and ``showwarning``): two
threads that enter and leave it out of turn lose warnings or see each other's (a fleet's held-out validations
swapped their lists). A Runner's pool threads are marked as routed (:func:`route_this_thread`) and, while the pool
works, :class:`RoutedWarnings` sends each such thread's warnings to the list of the innermost
:func:`recorded_warnings` block open in that thread; elsewhere :func:`recorded_warnings` is ``catch_warnings``.
Used by the simulation checks, validation and the scale layer (a low-level module: it imports nothing of ours)."""

from __future__ import annotations

import contextlib
import threading
import warnings

#: per thread: whether a Runner routes its warnings (``routed``), and the list of the block recording them
_local = threading.local()


def route_this_thread():
    """Marks the calling thread (a pool's initializer) as one whose warnings a RoutedWarnings routes."""
    _local.routed = True


@contextlib.contextmanager
def recorded_warnings():
    """The warnings raised in the block, as a list of ``warnings.WarningMessage``, without showing them: every one
    (``simplefilter("always")``), or, in a routed thread, every one the filters pass (RoutedWarnings makes them
    ``always`` where a pool's tasks record theirs). Blocks nest: an inner block's list is its own, and the outer
    one's is back after it."""
    if getattr(_local, "routed", False):
        caught, outer = [], getattr(_local, "sink", None)
        _local.sink = caught
        try:
            yield caught
        finally:
            _local.sink = outer
    else:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            yield caught


class RoutedWarnings:
    """While a thread pool works: a routed thread's warnings go into the list of the block recording them
    (recorded_warnings), elsewhere as before; with ``always``, every one is shown (as recorded_warnings asks:
    the same list as in sequential mode). On leaving, the warnings module is as it was, whatever the threads did
    to it."""

    def __init__(self, always: bool):
        self.always = always

    def __enter__(self):
        self._saved = warnings.catch_warnings()
        self._saved.__enter__()
        if self.always:
            warnings.simplefilter("always")
        self._show = warnings.showwarning
        warnings.showwarning = self._route
        return self

    def _route(self, message, category, filename, lineno, file=None, line=None):
        sink = getattr(_local, "sink", None) if getattr(_local, "routed", False) else None
        if sink is None:
            self._show(message, category, filename, lineno, file, line)
        else:
            sink.append(warnings.WarningMessage(message, category, filename, lineno, file, line))

    def __exit__(self, *exc):
        return self._saved.__exit__(*exc)


__all__ = ["recorded_warnings", "RoutedWarnings", "route_this_thread"]
