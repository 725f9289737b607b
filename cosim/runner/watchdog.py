"""The watchdog: code that runs past a deadline without returning is stopped as hung.

While a run goes, the runner beats the watchdog before each adapter's ``start`` and
``finish`` and the kernel beats it every few hundred events (:meth:`Watchdog.beat`, one
store of a float). A thread of its own looks every tenth of the deadline: when no beat
came for ``scenario.hang_timeout_s`` seconds of wall-clock time, and numba is not
compiling, it raises :class:`~cosim.runner.faults.Hung` in the running thread. On the main
thread that is a signal (``SIGALRM``), so a plugin asleep in ``time.sleep`` or blocked in a
socket is stopped too; on another thread (a Dask worker's) it is an asynchronous exception,
which stops Python code but not a blocking call. The runner then names the code that was
running (:func:`~cosim.runner.faults.fault_of`) and keeps what ran.
"""

from __future__ import annotations

import ctypes
import signal
import threading
import time
from collections.abc import Callable
from types import FrameType, TracebackType

from cosim.runner.faults import Hung


class Watchdog:
    """Stops the running thread when it goes ``timeout_s`` without a beat.

    Use as a context manager around the code to watch; ``timeout_s <= 0`` watches nothing.

    Args:
        timeout_s: wall-clock seconds without a beat before the thread is stopped (s).
        busy: while it says True (numba compiling), time passes without counting.
    """

    def __init__(self, timeout_s: float, busy: Callable[[], bool] | None = None) -> None:
        self.timeout_s = timeout_s
        self._busy = busy
        self._last = time.monotonic()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._target = threading.get_ident()
        self._previous: object = None
        self._main = False
        self.fired = False

    @property
    def active(self) -> bool:
        """Whether it watches (a positive deadline)."""
        return self.timeout_s > 0

    def beat(self) -> None:
        """The code running is alive: the deadline starts again."""
        self._last = time.monotonic()

    def __enter__(self) -> Watchdog:
        if not self.active:
            return self
        self._target = threading.get_ident()
        self._main = threading.current_thread() is threading.main_thread()
        if self._main:
            self._previous = signal.signal(signal.SIGALRM, self._on_signal)
        self.beat()
        self._stop.clear()
        self._thread = threading.Thread(target=self._watch, name="cosim-watchdog", daemon=True)
        self._thread.start()
        return self

    def __exit__(
        self,
        _type: type[BaseException] | None,
        _error: BaseException | None,
        _trace: TracebackType | None,
    ) -> None:
        if self._thread is None:
            return
        self._stop.set()
        self._thread.join()
        self._thread = None
        if self._main:
            previous = self._previous if self._previous is not None else signal.SIG_DFL
            signal.signal(signal.SIGALRM, previous)  # type: ignore[arg-type]
            self._main, self._previous = False, None

    def _watch(self) -> None:
        step = min(1.0, self.timeout_s / 10)
        while not self._stop.wait(step):
            now = time.monotonic()
            if self._busy is not None and self._busy():
                self._last = now  # compiling is not hanging
                continue
            if now - self._last >= self.timeout_s:
                self.fired = True
                self._interrupt()
                return

    def _interrupt(self) -> None:
        if self._main:  # a signal stops even a sleep
            signal.pthread_kill(self._target, signal.SIGALRM)
            return
        _ASYNC_TIMEOUT[0] = self.timeout_s
        ctypes.pythonapi.PyThreadState_SetAsyncExc(
            ctypes.c_ulong(self._target), ctypes.py_object(_AsyncHung)
        )

    def _on_signal(self, _signum: int, _frame: FrameType | None) -> None:
        if self.fired and not self._stop.is_set():
            raise Hung(self.timeout_s)


class _AsyncHung(Hung):
    """The :class:`Hung` raised in another thread (an exception class, not an instance)."""

    def __init__(self) -> None:
        super().__init__(_ASYNC_TIMEOUT[0])


_ASYNC_TIMEOUT = [0.0]
"""The deadline an asynchronous :class:`Hung` reports (set when the watchdog fires)."""
