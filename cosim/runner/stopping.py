"""Stopping a run on a signal and keeping what ran.

``cosim run`` takes SIGINT (Ctrl-C), SIGTERM (``kill``, a scheduler's timeout) and SIGHUP
(a closed terminal) alike (:func:`stop_on_signals`). While the kernel runs, a signal only
asks for a stop (:class:`StopRequest`); the runner stops at the next event boundary it
looks at (every 0.1 s of wall time), closes the bag, and writes the tables and a summary
of the simulated time reached, marked ``"stopped"``. Outside that window (loading, building
the world, waiting for a viewer) a signal stops at once. A second signal while the results
are written stops at once too. Either way :class:`RunStopped` is raised, a
``KeyboardInterrupt``, so that code stopping on Ctrl-C stops on it too.

While deferring, the handler raises nothing: an exception raised by a signal handler lands
wherever Python happened to be, and where that is a Python callback called from compiled code
(python-fcl's collision and distance callbacks, ``noexcept`` in Cython) it is printed as
"Exception ignored in" and dropped, and the signal with it. The runner looks at the request
between events instead, where nothing can drop it.

A signal the process was started to ignore (``nohup`` ignores SIGHUP) stays ignored.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Callable, Iterator
from types import FrameType
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from cosim.runner.result import RunResult

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
"""The signals that stop a run (and keep what ran)."""
CHECK_EVERY_S = 0.1
"""Wall-clock seconds between the runner's looks at a stop request."""


def signal_name(signum: int) -> str:
    """``SIGTERM`` for 15."""
    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"


class RunStopped(KeyboardInterrupt):
    """A run stopped by a signal.

    Attributes:
        signum: the signal.
        result: what ran (tables and summary up to the stop), when the run had started
            and its results were kept; None when it stopped before the kernel ran or while
            the results were written.
    """

    def __init__(self, signum: int, result: RunResult | None = None) -> None:
        self.signum = signum
        self.result = result
        super().__init__(f"stopped by {signal_name(signum)}")

    @property
    def exit_status(self) -> int:
        """The shell's status of a process ended by the signal (128 + its number)."""
        return 128 + self.signum


class StopRequest:
    """Whether a signal asked the run to stop, and which.

    The signal handler of :func:`stop_on_signals` sets it while :meth:`deferred`; outside,
    the handler raises at once.

    Args:
        stopped: the exception a stop raises, built from the signal's number
            (:class:`RunStopped`; a study's is :class:`~cosim.studies.lifeline.StudyStopped`).
    """

    def __init__(self, stopped: Callable[[int], KeyboardInterrupt] = RunStopped) -> None:
        self.signum: int | None = None
        self.stopped = stopped
        self._deferring = False

    @property
    def requested(self) -> bool:
        """Whether a stop was asked for."""
        return self.signum is not None

    def handle(self, signum: int, _frame: FrameType | None = None) -> None:
        """The signal handler: note the stop while deferring; stop at once otherwise.

        Raises:
            KeyboardInterrupt: ``stopped(signum)``, outside :meth:`deferred` or for a second
                signal.
        """
        if self._deferring and self.signum is None:
            self.signum = signum
            return
        if self.signum is None:
            self.signum = signum
        raise self.stopped(signum)

    def raise_if_requested(self) -> None:
        """Stop now if a stop was asked for (where a deferred stop is acted on).

        Raises:
            KeyboardInterrupt: ``stopped(signum)`` of the signal that asked.
        """
        if self.signum is not None:
            raise self.stopped(self.signum)

    @contextlib.contextmanager
    def deferred(self) -> Iterator[None]:
        """While inside, a first signal is only noted (the runner stops where it looks)."""
        previous, self._deferring = self._deferring, True
        try:
            yield
        finally:
            self._deferring = previous

    @contextlib.contextmanager
    def immediate(self) -> Iterator[None]:
        """While inside, a signal stops at once; a stop already asked for stops on entry.

        Raises:
            KeyboardInterrupt: ``stopped(signum)`` on entry, if a stop was asked for.
        """
        self.raise_if_requested()
        previous, self._deferring = self._deferring, False
        try:
            yield
        finally:
            self._deferring = previous


@contextlib.contextmanager
def stop_on_signals(
    signals: tuple[int, ...] = STOP_SIGNALS, request: StopRequest | None = None
) -> Iterator[StopRequest]:
    """While inside, ``signals`` stop the run through the :class:`StopRequest` yielded.

    Only the main thread can take signals; elsewhere the request is never set. A signal
    whose handler is ``SIG_IGN`` when entering (``nohup``) is left ignored.

    Args:
        signals: the signals that stop.
        request: the request they set (a new one raising :class:`RunStopped` by default).
    """
    request = request if request is not None else StopRequest()
    if threading.current_thread() is not threading.main_thread():
        yield request
        return
    previous = {}
    for sig in signals:
        if signal.getsignal(sig) is not signal.SIG_IGN:
            previous[sig] = signal.signal(sig, request.handle)
    try:
        yield request
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
