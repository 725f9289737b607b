"""A run's worker threads: per-robot work of one simulated instant on every core.

Within one simulated instant the robots' own work is independent: casting their lidars,
matching their scans against their own maps, planning their own paths. An adapter hands
such work to :class:`Workers` as a list of items; the items run on the run's threads and
their results come back **in the items' order**, so whatever the adapter does with them
next (publish, record, draw random numbers) happens in the same order for any number of
threads. Tables and bags are therefore identical for ``--threads 1`` and ``--threads 2``;
threads only change how long the instant takes.

Threads help where the work releases Python's global interpreter lock: cosim's numba
kernels are compiled with ``nogil=True`` and numpy releases it in its array loops. Python
code in the items still runs one thread at a time.

With one thread every item runs inline, in order, on the calling thread: today's serial
path, with no pool and no locks.
"""

from __future__ import annotations

import itertools
import os
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Protocol, TypeVar

T = TypeVar("T")
R = TypeVar("R")

MAX_THREADS = 64
"""The most threads a run takes (more than any machine cosim targets has cores)."""

SLICES_PER_THREAD = 4
"""Slices :meth:`Workers.chunks` cuts a batch into per thread (load balance vs overhead)."""


class Spread(Protocol):
    """Something that runs ``fn`` over ``items`` and returns the results in order.

    :meth:`Workers.map` is one (on the run's threads); :func:`in_turn` the plain one.
    """

    def __call__(self, fn: Callable[[T], R], items: Sequence[T], /) -> list[R]:
        """The results of ``fn`` over ``items``, in the items' order."""
        ...


def in_turn(fn: Callable[[T], R], items: Sequence[T], /) -> list[R]:
    """``[fn(item) for item in items]`` on the calling thread."""
    return [fn(item) for item in items]


def available_cores() -> int:
    """The cores this process may run on (its CPU affinity; ``os.cpu_count()`` elsewhere)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


class _Inside(threading.local):
    """Whether the current thread is running a batch's items (per thread)."""

    active = False


class Workers:
    """The run's threads for per-robot work within one simulated instant.

    The run's own thread is worker 0: it takes items like the others while a batch runs
    (a pool of ``threads - 1`` helpers joins it), so no core idles waiting for a handoff.
    Items are taken one at a time, in order, by whichever thread is free.

    Args:
        threads: how many threads run items at once (1: inline, on the calling thread).

    Raises:
        ValueError: ``threads`` not an int in ``[1, MAX_THREADS]``.
    """

    def __init__(self, threads: int = 1) -> None:
        if isinstance(threads, bool) or not isinstance(threads, int):
            raise ValueError(f"threads must be an int, got {threads!r}")
        if not 1 <= threads <= MAX_THREADS:
            raise ValueError(f"threads must be in [1, {MAX_THREADS}], got {threads}")
        self.threads = threads
        self._pool: ThreadPoolExecutor | None = None
        self._busy_s = [0.0] * threads
        self._inside = _Inside()
        self.batches = 0
        """Calls of :meth:`map` that spread more than one item over more than one thread."""

    # -- running work ------------------------------------------------------------------------
    def map(self, fn: Callable[[T], R], items: Sequence[T]) -> list[R]:
        """``[fn(item) for item in items]``, the items spread over the threads.

        Results come back in the items' order whatever ran first. An item that raises an
        ``Exception`` raises here, on the calling thread, once every item has finished (the
        first failure in the items' order; no thread carries on past a half-done instant).
        An interrupt on the calling thread (Ctrl-C, the watchdog) leaves at once.
        """
        count = len(items)
        if self._inside.active:  # an item's own batch (a nested map): inline, no deadlock
            return [fn(item) for item in items]
        helpers = min(self.threads, count) - 1
        if helpers <= 0:
            start = time.perf_counter()
            try:
                return [fn(item) for item in items]
            finally:
                self._busy_s[0] += time.perf_counter() - start
        self.batches += 1
        results: list[Any] = [None] * count
        failures: list[BaseException | None] = [None] * count
        taken = itertools.count()  # next() on it is atomic: each item is taken once

        inside = self._inside

        def drain(slot: int) -> None:
            start = time.perf_counter()
            inside.active = True
            try:
                for k in taken:
                    if k >= count:
                        break
                    try:
                        results[k] = fn(items[k])
                    except Exception as error:  # raised on the run's thread, in order
                        failures[k] = error
                    # anything else (an interrupt, a stop, the watchdog) leaves at once
            finally:
                inside.active = False
                self._busy_s[slot] += time.perf_counter() - start

        pool = self._executor()
        futures = [pool.submit(drain, slot) for slot in range(1, helpers + 1)]
        drain(0)
        for future in futures:
            future.result()
        for failure in failures:
            if failure is not None:
                raise failure
        return results

    def chunks(self, count: int, fn: Callable[[int, int], None], *, minimum: int = 1) -> None:
        """Call ``fn(start, stop)`` over ``range(count)`` cut into slices for the threads.

        For batch kernels that write each item's result into its own row of an output
        array: the rows are the same whatever the cut. The cut gives each thread
        :data:`SLICES_PER_THREAD` slices to take in turn, so that a thread whose slice was
        quick (robots in a narrow aisle cast short rays) takes the next one; slices hold
        at least ``minimum`` items, and fewer than ``2 * minimum`` items run as one slice.
        """
        parts = min(self.threads * SLICES_PER_THREAD, count // max(minimum, 1))
        if self.threads == 1 or parts <= 1:
            self.map(lambda bounds: fn(*bounds), [(0, count)])
            return
        edges = [count * k // parts for k in range(parts + 1)]
        self.map(lambda bounds: fn(*bounds), list(itertools.pairwise(edges)))

    # -- accounting ----------------------------------------------------------------------------
    def busy_s(self) -> list[float]:
        """Seconds each thread spent running items (thread 0: the run's own thread)."""
        return [round(s, 4) for s in self._busy_s]

    def summary(self, wall_s: float) -> dict[str, Any]:
        """The summary's ``threads`` and ``thread_busy`` (a record).

        ``thread_busy`` holds each thread's seconds running items (``busy_s``), their share
        of the run's wall time ``wall_s`` (``share_of_wall``; thread 0 is the run's own
        thread) and how many instants were spread over several threads (``batches``).
        """
        busy = self.busy_s()
        share = [round(b / wall_s, 3) if wall_s > 0 else 0.0 for b in busy]
        return {
            "threads": self.threads,
            "thread_busy": {"busy_s": busy, "share_of_wall": share, "batches": self.batches},
        }

    def close(self) -> None:
        """Let the helper threads go (they hold no work between instants).

        Not waited for: after a run that failed mid-batch (a plugin's item hung and the
        watchdog ended the run), a helper may still be inside that item.
        """
        if self._pool is not None:
            self._pool.shutdown(wait=False, cancel_futures=True)
            self._pool = None

    def _executor(self) -> ThreadPoolExecutor:
        if self._pool is None:
            self._pool = ThreadPoolExecutor(self.threads - 1, thread_name_prefix="cosim-worker")
        return self._pool


__all__ = ["MAX_THREADS", "Spread", "Workers", "available_cores", "in_turn"]
