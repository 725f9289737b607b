"""A study's processes live and stop with it (cosim.studies.lifeline), in real processes."""

import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import psutil
import pytest

from cosim.studies.lifeline import STUDY_PID_VARIABLE, StudyStopped, signal_name, stop_on_signals
from tests.conftest import cosim_main
from tests.cosim.studies.busy import SHORT_RUN as BUSY_SHORT_RUN
from tests.cosim.studies.busy import busy_study
from tests.cosim.studies.small import finished, on_its_way, small_study

# two short runs, then two long ones: a signal sent once the short ones are written lands
# while both workers are inside a long run
SHORT_S, LONG_S = 20, 300
SHORT_RUNS = ["0000_s1", "0000_s2"]


def _study(tmp_path: Path) -> Path:
    grid = f'\n[grid]\n"scenario.duration_s" = [{SHORT_S}, {LONG_S}]\n'
    return small_study(tmp_path, seeds="[1, 2]", duration_s=None, extra=grid)


def _start(path: Path, out: Path) -> subprocess.Popen[str]:
    command = [sys.executable, "-m", "cosim", "study", str(path), "--out", str(out)]
    return subprocess.Popen(
        [*command, "--workers", "2", "--quiet"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _wait_for_runs(proc: subprocess.Popen[str], out: Path, runs: list[str]) -> None:
    deadline = time.monotonic() + 120
    while not set(runs) <= set(finished(out)):
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "the short runs did not finish in 2 minutes"
        time.sleep(0.05)


def _study_processes(pid: int) -> set[psutil.Process]:
    """The study's descendants, and every process that names it as its study."""
    found = set(psutil.Process(pid).children(recursive=True))
    for process in psutil.process_iter():
        try:
            if process.environ().get(STUDY_PID_VARIABLE) == str(pid):
                found.add(process)
        except (psutil.NoSuchProcess, psutil.AccessDenied, psutil.ZombieProcess):
            continue
    found.discard(psutil.Process(os.getpid()))
    return found


def _running(processes: set[psutil.Process]) -> list[psutil.Process]:
    alive = []
    for process in processes:
        try:
            if process.is_running() and process.status() != psutil.STATUS_ZOMBIE:
                alive.append(process)
        except psutil.NoSuchProcess:
            continue
    return alive


@pytest.mark.slow
def test_sigterm_stops_a_study_at_once_in_one_line_and_resume_completes_it(tmp_path):
    path, out = _study(tmp_path), tmp_path / "out"
    proc = _start(path, out)
    _wait_for_runs(proc, out, SHORT_RUNS)
    time.sleep(0.5)  # both workers are in a long run now
    workers = _study_processes(proc.pid)
    sent = time.monotonic()
    proc.send_signal(signal.SIGTERM)
    _, stderr = proc.communicate(timeout=120)
    stopped_in = time.monotonic() - sent
    assert proc.returncode == 143, stderr
    assert stderr == (
        f"cosim: small: stopped by SIGTERM; the 2 finished runs are kept in {out}: "
        "continue with --resume\n"
    )
    kept = pd.read_parquet(out / "results.parquet")
    assert list(kept["run_id"]) == SHORT_RUNS and set(kept["status"]) == {"ok"}
    assert finished(out) == SHORT_RUNS
    assert not [p for p in (out / "runs").iterdir() if on_its_way(p)]
    assert workers and not _running(workers)
    resumed = cosim_main("study", str(path), "--out", str(out), "--workers", "2", "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert "resuming, 2/4 runs already done" in resumed.stderr
    results = pd.read_parquet(out / "results.parquet")
    assert list(results["run_id"]) == [*SHORT_RUNS, "0001_s1", "0001_s2"]
    assert set(results["status"]) == {"ok"}
    # the runs under way were killed, not waited for (they take this long)
    long_run_s = results.loc[results["run_id"].str.startswith("0001"), "wall_time_s"].min()
    assert stopped_in < long_run_s / 2, f"stopped in {stopped_in:.1f} s, a run {long_run_s} s"


@pytest.mark.slow
def test_a_study_killed_outright_leaves_no_process_behind(tmp_path):
    path, out = _study(tmp_path), tmp_path / "out"
    proc = _start(path, out)
    _wait_for_runs(proc, out, SHORT_RUNS[:1])
    time.sleep(0.3)
    processes = _study_processes(proc.pid)
    # the fork server and the two workers at least (and multiprocessing's resource tracker)
    assert len(processes) >= 3, processes
    proc.kill()
    proc.wait(timeout=30)  # not communicate(): a process left behind would hold the pipes
    try:
        deadline = time.monotonic() + 5
        while _running(processes) and time.monotonic() < deadline:
            time.sleep(0.1)
        left = _running(processes)
        assert not left, [p.cmdline()[-1][:60] for p in left]
    finally:
        for process in _running(processes):  # a failed test cleans up after itself
            process.kill()
        proc.stdout.close()
        proc.stderr.close()


def test_a_study_stopped_by_a_signal_exits_with_128_plus_its_number():
    assert StudyStopped(signal.SIGTERM).exit_status == 143
    assert StudyStopped(signal.SIGHUP).message == "stopped by SIGHUP"
    assert isinstance(StudyStopped(signal.SIGTERM), KeyboardInterrupt)
    assert signal_name(signal.SIGINT) == "SIGINT" and signal_name(999) == "signal 999"


def test_sigterm_inside_stop_on_signals_raises_study_stopped_and_the_handler_comes_back():
    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(StudyStopped) as stopped, stop_on_signals():
        signal.raise_signal(signal.SIGTERM)
        time.sleep(1)  # the handler runs at the next bytecode
    assert stopped.value.signum == signal.SIGTERM
    assert signal.getsignal(signal.SIGTERM) is before


@pytest.mark.slow
@pytest.mark.parametrize(("study", "stays"), [("parent", True), ("other", False)])
def test_a_fork_server_whose_study_is_gone_leaves_at_once(study, stays):
    pid = os.getpid() if study == "parent" else 1
    code = (
        "from cosim.studies.lifeline import bind_fork_server; bind_fork_server(); print('stayed')"
    )
    done = subprocess.run(
        [sys.executable, "-c", code],
        env={**os.environ, STUDY_PID_VARIABLE: str(pid)},
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    assert (done.stdout == "stayed\n") is stays


TRIALS = 30
"""Studies stopped by SIGTERM, each while its long run measures clearances with FCL."""


@pytest.mark.slow
def test_sigterm_at_any_moment_of_collision_checking_stops_the_study_every_time(tmp_path):
    """A signal that lands inside FCL's callbacks is never lost (it was one time in three)."""
    study = busy_study(tmp_path)
    proc = subprocess.Popen(
        [sys.executable, "-m", "tests.cosim.studies.busy", str(study), str(tmp_path), str(TRIALS)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stdout is not None
    moments = random.Random(43)
    outcomes = []
    try:
        for trial in range(TRIALS):
            started = proc.stdout.readline().split()
            assert started[:2] == ["start", str(trial)], (started, proc.stderr.read())
            out = Path(started[2])
            deadline = time.monotonic() + 60
            while BUSY_SHORT_RUN not in finished(out):  # the long run starts now
                assert time.monotonic() < deadline, "the short run did not finish in 60 s"
                time.sleep(0.005)
            time.sleep(moments.uniform(0.15, 0.6))  # the long run is in its steps by then
            proc.send_signal(signal.SIGTERM)
            outcomes.append((out, json.loads(proc.stdout.readline())))
    finally:
        proc.kill()
        proc.communicate()
    lost = [done["trial"] for _out, done in outcomes if done["status"] != 143]
    swallowed = [done["trial"] for _out, done in outcomes if "Exception ignored" in done["stderr"]]
    assert not lost, f"{len(lost)} of {TRIALS} signals lost: trials {lost} ({swallowed} by FCL)"
    for out, done in outcomes:
        assert done["stderr"] == (
            f"cosim: busy: stopped by SIGTERM; the 1 finished runs are kept in {out}: "
            "continue with --resume\n"
        )
        kept = pd.read_parquet(out / "results.parquet")
        assert list(kept["run_id"]) == [BUSY_SHORT_RUN] and list(kept["status"]) == ["ok"]
        assert finished(out) == [BUSY_SHORT_RUN]
        assert not [p for p in (out / "runs").iterdir() if on_its_way(p)]


def test_inside_a_run_of_the_study_process_a_signal_is_noted_and_raised_where_it_is_looked_for():
    with stop_on_signals() as request:
        with request.deferred():  # as while a run's kernel goes
            signal.raise_signal(signal.SIGTERM)
            time.sleep(0.01)  # the handler has run: nothing was raised
            assert request.signum == signal.SIGTERM
        with pytest.raises(StudyStopped) as stopped:
            request.raise_if_requested()
    assert stopped.value.signum == signal.SIGTERM


def test_ctrl_c_stops_a_study_as_sigterm_does():
    with pytest.raises(StudyStopped) as stopped, stop_on_signals():
        signal.raise_signal(signal.SIGINT)
        time.sleep(1)
    assert stopped.value.signum == signal.SIGINT and stopped.value.exit_status == 130
