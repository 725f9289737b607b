"""How a study shows where it is: a bar on a terminal, a line per tenth on a pipe, time left."""

from __future__ import annotations

import io
from types import SimpleNamespace

import pytest

from cosim.studies import progress as progress_module
from cosim.studies.progress import Progress
from cosim.studies.worker import Outcome


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def _outcome(status: str) -> Outcome:
    return Outcome(row={"run_id": "r", "status": status}, summary={}, scenario_toml="", tables={})


@pytest.fixture
def clock(monkeypatch: pytest.MonkeyPatch) -> list[float]:
    """The wall clock the progress reads (s): set its only element to move it."""
    now = [0.0]
    monkeypatch.setattr(progress_module, "time", SimpleNamespace(perf_counter=lambda: now[0]))
    return now


def test_the_progress_bar_counts_resumed_runs_and_failures_and_ends_the_line():
    terminal = _Terminal()
    progress = Progress(terminal)
    progress.begin(total=4, already_done=2)
    progress(_outcome("ok"))
    progress(_outcome("error"))
    text = terminal.getvalue()
    assert "resuming, 2/4 runs already done" in text
    assert "[##################------] 3/4 runs, 0 failed" in text
    assert "[########################] 4/4 runs, 1 failed" in text
    assert text.endswith("\n")


def test_progress_on_a_pipe_writes_a_line_per_tenth_of_the_study():
    pipe = io.StringIO()
    progress = Progress(pipe)
    progress.begin(total=100, already_done=0)
    for _ in range(100):
        progress(_outcome("ok"))
    lines = pipe.getvalue().splitlines()
    assert len(lines) == 11  # the first run, then every tenth
    assert lines[-1].startswith("study: 100/100 runs, 0 failed")


def test_the_time_left_is_the_mean_time_of_this_session_s_runs_times_the_runs_to_do(clock):
    pipe = io.StringIO()
    progress = Progress(pipe)
    progress.begin(total=10, already_done=6)  # resumed: done, but not timed
    clock[0] = 30.0
    progress(_outcome("ok"))  # 30 s a run, 3 runs to do
    assert pipe.getvalue().splitlines()[-1] == (
        "study: 7/10 runs, 0 failed, 30s elapsed, 1m30s left"
    )


def test_long_times_read_in_hours_minutes_and_seconds(clock):
    pipe = io.StringIO()
    progress = Progress(pipe)
    progress.begin(total=3, already_done=0)
    clock[0] = 3723.4  # 1 h 2 min 3 s
    progress(_outcome("ok"))
    assert pipe.getvalue() == "study: 1/3 runs, 0 failed, 1h02m03s elapsed, 2h04m07s left\n"


def test_a_resumed_study_says_so_only_when_runs_were_done_before():
    pipe = io.StringIO()
    Progress(pipe).begin(total=5, already_done=0)
    assert pipe.getvalue() == ""


def test_a_terminal_line_is_rewritten_in_place_and_ended_only_when_all_are_done(clock):
    terminal = _Terminal()
    progress = Progress(terminal)
    progress.begin(total=2, already_done=0)
    progress(_outcome("failed"))
    first = terminal.getvalue()
    assert first.startswith("\rstudy [############------------] 1/2 runs, 1 failed")
    assert first.endswith("\x1b[K") and "\n" not in first  # the rest of the line erased
    progress(_outcome("ok"))
    assert terminal.getvalue().endswith("0s left\x1b[K\n")
