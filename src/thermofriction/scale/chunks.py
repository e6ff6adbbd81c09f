"""Chunks of work: consecutive items per task, sized from the measured time of one item so that a task's
overhead (~2.5 ms on Dask, ~0.05 ms on threads) stays a small share of its work, the largest first and
shrinking towards the end, so that every worker gets several and the last ones finish together (guided
self-scheduling). Chunking does not change a result: every item is computed on its own."""

from __future__ import annotations

import math

#: a chunk's work [s] aimed at, at least: Dask's overhead is ~2.5 ms per task (scheduler, pickles, the
#: network), a thread pool's ~0.05 ms; both then stay below 3 % of the work (the target: < 10 %)
CHUNK_SECONDS = {"dask": 0.1, "threads": 0.02, "sequential": 0.02}
#: a chunk's work [s] at most: Ctrl-C waits for the running chunks of a thread pool, and a dead Dask
#: worker's chunk is run again
CHUNK_MAX_SECONDS = {"dask": 5.0, "threads": 1.0, "sequential": 1.0}


def batches(n: int, size: int):
    """(start, stop) of consecutive batches of ``size`` covering range(n)."""
    return [(i, min(i + size, n)) for i in range(0, n, size)]


def chunk_spans(n_items: int, n_workers: int, item_seconds=None, *, kind="dask", batch_size=None, largest=None,
                per_worker: int = 4):
    """(start, stop) of consecutive chunks covering range(n_items), in order.

    ``batch_size``: that many items each. Else guided self-scheduling: each chunk holds 1/(per_worker x
    workers) of the items still to hand out -- the first ones large (every worker gets ``per_worker``
    chunks or more), the last ones small, so that the workers finish together -- but at least
    CHUNK_SECONDS[kind] of work (so that a chunk's overhead stays a few per cent of it) and at most
    CHUNK_MAX_SECONDS[kind] (and ``largest`` items)."""
    if batch_size is not None:
        return batches(n_items, int(batch_size))
    if item_seconds is not None and item_seconds > 0 and math.isfinite(item_seconds):
        smallest = max(1, math.ceil(CHUNK_SECONDS[kind] / item_seconds))
        biggest = max(smallest, math.floor(CHUNK_MAX_SECONDS[kind] / item_seconds))
    else:  # nothing known: small chunks
        smallest, biggest = 1, n_items
    if largest is not None:
        smallest, biggest = min(smallest, largest), min(biggest, largest)
    spans, a = [], 0
    w = max(int(n_workers), 1)
    while a < n_items:
        size = min(max(math.ceil((n_items - a) / (per_worker * w)), smallest), biggest, n_items - a)
        spans.append((a, a + size))
        a += size
    return spans


__all__ = ["CHUNK_SECONDS", "CHUNK_MAX_SECONDS", "batches", "chunk_spans"]
