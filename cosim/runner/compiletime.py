"""Time spent compiling numba kernels, said apart from a run's real-time factor.

The models' kernels (:mod:`models.navigation`, :mod:`models.assignment`) are compiled by
numba on their first call and cached on disk (``cache=True``: ``__pycache__/*.nbi`` and
``*.nbc`` next to their modules). The first run on a machine compiles them (about 13 s);
every later run loads them in milliseconds. That is set-up, not the simulation's speed, so a
run measures it (:class:`CompileClock`) and reports the run loop's real-time factor without it
(:func:`speed_phrase`). ``make setup`` fills the cache ahead (:mod:`cosim.runner.warmup`).
"""

from __future__ import annotations

import threading
import time
from types import TracebackType
from typing import Any

from numba.core import event

COMPILE_EVENT = "numba:compile"
"""numba's event around compiling one kernel for one signature (not a cache load)."""


class _Listener(event.Listener):
    """Adds up the wall time between the outermost start and end of compile events."""

    def __init__(self, clock: CompileClock) -> None:
        self._clock = clock

    def on_start(self, _event: Any) -> None:
        self._clock._started()

    def on_end(self, _event: Any) -> None:
        self._clock._ended()


class CompileClock:
    """Wall-clock seconds numba spends compiling kernels while the clock is installed.

    Use as a context manager; :attr:`seconds` can be read at any time (a compile under way
    counts up to now). A kernel compiled inside another's compile counts once.

    ```python
    with CompileClock() as clock:
        run_the_kernel()
    clock.seconds  # 0.0 when every kernel came from the cache
    ```
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._depth = 0
        self._since = 0.0
        self._total_s = 0.0
        self._listener = _Listener(self)

    def __enter__(self) -> CompileClock:
        event.register(COMPILE_EVENT, self._listener)  # type: ignore[no-untyped-call]
        return self

    def __exit__(
        self,
        _type: type[BaseException] | None,
        _error: BaseException | None,
        _trace: TracebackType | None,
    ) -> None:
        event.unregister(COMPILE_EVENT, self._listener)  # type: ignore[no-untyped-call]

    @property
    def seconds(self) -> float:
        """Wall-clock seconds spent compiling so far (s)."""
        with self._lock:
            running = time.perf_counter() - self._since if self._depth > 0 else 0.0
            return self._total_s + running

    @property
    def compiling(self) -> bool:
        """Whether numba is compiling a kernel now."""
        return self._depth > 0

    def _started(self) -> None:
        with self._lock:
            if self._depth == 0:
                self._since = time.perf_counter()
            self._depth += 1

    def _ended(self) -> None:
        with self._lock:
            self._depth = max(self._depth - 1, 0)
            if self._depth == 0:
                self._total_s += time.perf_counter() - self._since


SAID_FROM_S = 0.05
"""Compile time below this (s) is not worth a word: the kernels came from the cache."""


def speed_phrase(sim_time_s: float, wall_time_s: float, compile_time_s: float = 0.0) -> str:
    """How fast a run went, with the kernels' compile time said apart.

    Args:
        sim_time_s: simulated time reached (s).
        wall_time_s: wall-clock time of the run loop, compiling excluded (s).
        compile_time_s: wall-clock time numba spent compiling kernels for the run (s).

    Returns:
        ``"120 s simulated in 1.02 s (117x real time)"``, followed by
        ``", plus 12.9 s compiling kernels on this first run (cached now)"`` when compiling
        took :data:`SAID_FROM_S` or more (later runs load the kernels from numba's cache).
    """
    factor = (
        f"{sim_time_s / wall_time_s:.3g}x real time"
        if wall_time_s > 0
        else "real-time factor unknown"
    )
    phrase = f"{sim_time_s:g} s simulated in {wall_time_s:.2f} s ({factor})"
    if compile_time_s >= SAID_FROM_S:
        phrase += f", plus {compile_time_s:.1f} s compiling kernels on this first run (cached now)"
    return phrase
