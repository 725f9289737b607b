"""The radio's process, seen from the run: start it, ask it, know when it died and why.

ns-3 reports what it finds wrong inside by aborting its process (its asserts are on in
the wheel), so the radio runs in a child process the run owns
(:mod:`adapters.network.ns3.child`): the child dies, the run does not. The run talks to it
over pipes, one request and one answer at a time; the child's standard error is read by a
thread into a bounded tail, whose ns-3 lines explain a death. The child ends with the
process that started it: its requests' pipe closes, and it exits (not Linux's
parent-death signal, which follows the starting *thread*: a study worker's thread pool
would kill radios its next runs could use).

Starting one takes 10-15 s (ns-3's import and its templates' compilation), so a process
keeps the radios its runs are done with (:func:`acquire`, :func:`release`): a study's
worker starts one radio and builds each run's network in it anew (building resets ns-3's
state, so a reused radio gives the records a fresh one would: checked byte for byte).
"""

from __future__ import annotations

import atexit
import collections
import contextlib
import os
import select
import signal
import subprocess
import sys
import threading
from typing import IO, Any

from adapters.network.ns3.wire import read_frame, write_frame
from cosim.core.errors import BridgeError

ANSWER_S = 600.0
"""Longest wait for one answer (s): a window of a large fleet takes well under a second."""


class RadioDiedError(BridgeError):
    """The radio's process ended: ns-3 aborted, or it was killed, or it stopped answering."""


class RadioRefusedError(BridgeError):
    """The radio refused a request (the process lives on)."""


_IDLE: list[RadioProcess] = []
"""Radios of this process that no run uses now, alive and answering."""


def acquire() -> RadioProcess:
    """A radio for a run: one this process kept, else a new one."""
    while _IDLE:
        process = _IDLE.pop()
        if process.alive():
            return process
    return RadioProcess()


def release(process: RadioProcess) -> None:
    """A run is done with ``process``: keep it for the next run if it still answers."""
    if not process.alive():
        process.close()
        return
    try:
        process.call("reasons")  # answers in turn: no request of the run left half-done
    except BridgeError:
        process.close()
        return
    _IDLE.append(process)


@atexit.register
def _close_idle() -> None:
    while _IDLE:
        _IDLE.pop().close()


class RadioProcess:
    """The radio's process: ``call(request, argument)`` until :meth:`close`.

    Args:
        stderr_lines: how many lines of the child's standard error to keep.
    """

    def __init__(self, stderr_lines: int = 200) -> None:
        self.tail: collections.deque[str] = collections.deque(maxlen=stderr_lines)
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "adapters.network.ns3.child"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            bufsize=0,
            close_fds=True,
            env={**os.environ, "PYTHONUNBUFFERED": "1"},
        )
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self._in: IO[bytes] = self.proc.stdin
        self._out: IO[bytes] = self.proc.stdout
        self._pump = threading.Thread(target=self._read_stderr, daemon=True)
        self._pump.start()

    def _read_stderr(self) -> None:
        assert self.proc.stderr is not None
        for line in iter(self.proc.stderr.readline, b""):
            self.tail.append(line.decode(errors="replace").rstrip("\n"))

    def call(self, request: str, argument: Any = None) -> Any:
        """Ask the radio; its answer.

        Raises:
            RadioDiedError: the process is gone (with ns-3's reason when it printed one).
            RadioRefusedError: the radio refused the request.
        """
        if self.proc.poll() is not None:
            raise self._died()
        try:
            write_frame(self._in, (request, argument))
            ready, _, _ = select.select([self._out], [], [], ANSWER_S)
            if not ready:
                self.proc.kill()
                raise self._died(f"no answer to {request!r} within {ANSWER_S:g} s")
            answer = read_frame(self._out)
        except (EOFError, BrokenPipeError, ConnectionResetError):
            raise self._died() from None
        if answer[0] == "ok":
            return answer[1]
        raise RadioRefusedError(f"the ns-3 radio refused {request!r}: {answer[1]}: {answer[2]}")

    def _died(self, why: str = "") -> RadioDiedError:
        try:
            code = self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            code = self.proc.wait()
        self._pump.join(timeout=2)
        if code < 0:
            try:
                how = f"killed by {signal.Signals(-code).name}"
            except ValueError:
                how = f"killed by signal {-code}"
        else:
            how = f"exit status {code}"
        said = [
            line.strip()
            for line in self.tail
            if any(k in line for k in ("NS_ASSERT", "NS_FATAL", "msg=", "terminate", "Error"))
        ]
        reason = "; ".join(s for s in (why, how, " | ".join(said[-2:])) if s)
        return RadioDiedError(f"the ns-3 radio's process ended ({reason})")

    def alive(self) -> bool:
        """Whether the process still runs."""
        return self.proc.poll() is None

    def close(self) -> None:
        """Ask the process to exit; kill it if it does not."""
        if self.proc.poll() is None:
            with contextlib.suppress(BridgeError):
                self.call("exit")
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        for pipe in (self._in, self._out):
            pipe.close()
