"""A study's processes live and stop with it.

Local workers fork from a fork server that the study process starts. Killed outright
(``kill -9``, the out-of-memory killer), the study can run no clean-up, and the fork server
and the workers (a run each, over a gigabyte together) would go on for good. So the fork
server asks Linux to kill it when the study dies (``prctl(PR_SET_PDEATHSIG)``), and each
worker to kill it when the fork server dies; where ``prctl`` does not exist, a worker thread
watches the study's process id instead.

SIGTERM (and SIGHUP, a closed terminal) stop a study the way Ctrl-C does
(:func:`stop_on_signals`): the runner keeps the finished runs and the folder resumable.
A run of the study process itself (one worker) only notes the signal while its kernel runs
and stops at the next event boundary (:class:`~cosim.runner.stopping.StopRequest`): raised
inside the run, the stop could land in a callback of compiled code (python-fcl's) that
drops exceptions, and the study would run on.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time
from collections.abc import Iterator

from adapters.processes import die_with_parent
from cosim.runner import stopping
from cosim.runner.stopping import StopRequest

STUDY_PID_VARIABLE = "COSIM_STUDY_PID"
"""Environment variable naming the study process, for its fork server."""
WATCH_PERIOD_S = 1.0
"""How often a worker without ``prctl`` checks that its study still runs (s)."""
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
"""The signals that stop a study (and keep its finished runs)."""


class StudyStopped(KeyboardInterrupt):
    """A study stopped by a signal (SIGINT, SIGTERM, SIGHUP), its finished runs kept.

    A ``KeyboardInterrupt``, so that the ``except Exception`` of a run does not take it for
    a failed run, and code that stops on Ctrl-C stops on it too.

    Attributes:
        signum: the signal.
        message: one line: what stopped and what was kept.
    """

    def __init__(self, signum: int, message: str = "") -> None:
        self.signum = signum
        self.message = message or f"stopped by {signal_name(signum)}"
        super().__init__(self.message)

    @property
    def exit_status(self) -> int:
        """The shell's status of a process ended by the signal (128 + its number)."""
        return 128 + self.signum


def signal_name(signum: int) -> str:
    """``SIGTERM`` for 15."""
    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"


@contextlib.contextmanager
def stop_on_signals() -> Iterator[StopRequest]:
    """While inside, Ctrl-C, SIGTERM and SIGHUP stop the study through the request yielded.

    Outside a run of this process, a signal raises :class:`StudyStopped` at once; inside
    one (:func:`~cosim.studies.runner.run_study` hands the request to it), the run ends at
    its next event boundary, then the request raises it. Only the main thread can take
    signals; elsewhere the request is never set. A signal ignored when entering (``nohup``)
    stays ignored.
    """
    with stopping.stop_on_signals(STOP_SIGNALS, StopRequest(StudyStopped)) as request:
        yield request


def alive(pid: int) -> bool:
    """Whether process ``pid`` exists."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # it exists, owned by someone else
        return True
    return True


def bind_fork_server() -> None:
    """In the fork server: die with the study that started it.

    The study names itself in :data:`STUDY_PID_VARIABLE`; if it died before the fork server
    got here, the fork server's parent is no longer it, and the fork server leaves at once.
    """
    die_with_parent()
    study = os.environ.get(STUDY_PID_VARIABLE, "")
    if study.isdigit() and os.getppid() != int(study):
        os._exit(0)


def bind_worker(study_pid: int) -> None:
    """In a worker (the pool's initializer): die with the fork server, or with the study.

    Args:
        study_pid: the study process; a worker without ``prctl`` watches it from a thread.
    """
    if not die_with_parent():
        threading.Thread(target=_watch, args=(study_pid,), daemon=True).start()
    if not alive(study_pid):
        os._exit(0)


def _watch(study_pid: int) -> None:
    while alive(study_pid):
        time.sleep(WATCH_PERIOD_S)
    os._exit(0)
