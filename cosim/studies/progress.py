"""How a study shows where it is: runs done, failures, time left."""

from __future__ import annotations

import sys
import time
from typing import Protocol, TextIO

from cosim.studies.worker import Outcome


def _clock(seconds: float) -> str:
    """``1h02m03s``, ``2m03s`` or ``3s``."""
    whole = round(seconds)
    hours, rest = divmod(whole, 3600)
    minutes, secs = divmod(rest, 60)
    if hours:
        return f"{hours}h{minutes:02d}m{secs:02d}s"
    return f"{minutes}m{secs:02d}s" if minutes else f"{secs}s"


class StudyProgress(Protocol):
    """What :func:`run_study` reports to while it runs."""

    def begin(self, total: int, already_done: int) -> None:
        """The study has ``total`` runs, ``already_done`` of them finished earlier."""

    def __call__(self, outcome: Outcome) -> None:
        """One more run finished (``outcome.row["status"]`` tells how)."""


class Progress:
    """A progress bar with the time left; on a pipe, a plain line per tenth of the study.

    The time left is the mean wall time per run finished in this session times the runs
    still to do, so runs skipped on ``--resume`` count as done but not as fast.
    """

    WIDTH = 24

    def __init__(self, stream: TextIO | None = None) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.tty = self.stream.isatty()
        self.total = 0
        self.done = 0
        self.errors = 0
        self._session_done = 0
        self._start = time.perf_counter()
        self._last_tenth = -1

    def begin(self, total: int, already_done: int) -> None:
        """Start the clock; ``already_done`` runs finished before this session."""
        self.total = total
        self.done = already_done
        self._start = time.perf_counter()
        if already_done:
            self.stream.write(f"study: resuming, {already_done}/{total} runs already done\n")
            self.stream.flush()

    def __call__(self, outcome: Outcome) -> None:
        """Count one finished run and show where the study is."""
        self.done += 1
        self._session_done += 1
        self.errors += outcome.row.get("status") != "ok"
        elapsed = time.perf_counter() - self._start
        left = elapsed / self._session_done * (self.total - self.done)
        figures = (
            f"{self.done}/{self.total} runs, {self.errors} failed, "
            f"{_clock(elapsed)} elapsed, {_clock(left)} left"
        )
        if self.tty:
            filled = self.WIDTH * self.done // max(self.total, 1)
            bar = "#" * filled + "-" * (self.WIDTH - filled)
            self.stream.write(f"\rstudy [{bar}] {figures}\x1b[K")
            if self.done == self.total:
                self.stream.write("\n")
        else:
            tenth = self.done * 10 // max(self.total, 1)
            if tenth != self._last_tenth:
                self._last_tenth = tenth
                self.stream.write(f"study: {figures}\n")
        self.stream.flush()


__all__ = ["Progress", "StudyProgress"]
