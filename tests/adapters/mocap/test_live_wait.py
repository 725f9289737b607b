"""A live mocap source never blocks the run: no server, no frame, no body end it in one line."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from adapters.mocap.feed import MotionCaptureFeed
from tests.conftest import cosim_main

LIVE = (
    "--duration-s",
    "5",
    "--quiet",
    "--set",
    "mocap.source=motioncapture",
    "--set",
    'mocap.bodies=[["robot_1","jackal"]]',
)
"""lab-room, robot_1 tracked as rigid body 'jackal' by a live system."""


def live_run(tmp_path: Path, system: str, host: str, timeout_s: float):
    return cosim_main(
        "run",
        "lab-room",
        *LIVE,
        "--set",
        f"mocap.system={system}",
        "--set",
        f"mocap.hostname={host}",
        "--set",
        f"mocap.connect_timeout_s={timeout_s}",
        "--out",
        str(tmp_path / "run"),
    )


def workers(parent: int | None = None) -> list[str]:
    """Command lines of feed workers still running (any run's, or ``parent``'s children)."""
    found = []
    for proc in Path("/proc").iterdir():
        try:
            cmdline = (proc / "cmdline").read_bytes().replace(b"\0", b" ").decode()
            ppid = int((proc / "stat").read_text().rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            continue
        if "feed_worker.py" in cmdline and parent in (None, ppid):
            found.append(cmdline)
    return found


@pytest.mark.slow
def test_a_vicon_server_that_refuses_the_connection_ends_the_run_naming_system_host_and_wait(
    tmp_path: Path,
):
    started = time.monotonic()
    done = live_run(tmp_path, "vicon", "127.0.0.1", 0.5)
    assert time.monotonic() - started < 4.0  # not the 5 s of the run, never forever
    assert done.returncode == 2
    assert done.stderr == (
        "cosim: error: the vicon motion capture at '127.0.0.1' did not answer within 0.5 s "
        "(no connection); expected a pose of every tracked robot within "
        "mocap.connect_timeout_s = 0.5 s (see mocap.system, mocap.hostname and mocap.bodies); "
        f"the results of the 0.5 s simulated are in {tmp_path / 'run'}/ "
        '(summary.json says "failed")\n'
    )
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["failed"].startswith("the vicon motion capture at '127.0.0.1'")
    assert (tmp_path / "run" / "tables" / "events.parquet").is_file()
    assert not [w for w in workers() if "127.0.0.1" in w and "vicon" in w]


@pytest.mark.slow
def test_a_system_that_never_shows_the_robots_body_names_the_robot_the_body_and_the_host(
    tmp_path: Path,
):
    # VRPN "connects" to a host with no server and hands out empty frames
    done = live_run(tmp_path, "vrpn", "127.0.0.1", 2.0)
    assert done.returncode == 2
    line = done.stderr.removeprefix("cosim: error: ")
    assert line.startswith(
        "no pose of robot_1 within 2 s from the vrpn motion capture at '127.0.0.1': listened "
        "for rigid body 'jackal' ("
    )
    assert "frames came, none with it); expected a pose of every tracked robot" in line
    assert line.count("\n") == 1


@pytest.mark.slow
def test_a_system_the_library_refuses_ends_the_run_at_once_with_the_librarys_words(
    tmp_path: Path,
):
    started = time.monotonic()
    done = live_run(tmp_path, "qualisys", "127.0.0.1", 30.0)
    assert time.monotonic() - started < 5.0  # long before the 30 s allowed
    assert done.returncode == 2
    assert done.stderr.startswith(
        "cosim: error: the qualisys motion capture at '127.0.0.1': Error connecting QTM on "
        "address: 127.0.0.1:22222; expected"
    )


def test_closing_a_feed_whose_system_never_answers_kills_its_worker_at_once():
    feed = MotionCaptureFeed("vicon", hostname="127.0.0.1", bodies=["jackal"])
    time.sleep(0.1)
    assert not feed.connected and feed.failure() is None
    started = time.monotonic()
    feed.close()
    assert time.monotonic() - started < 0.3
    assert feed._process.returncode is not None
    assert not feed._thread.is_alive()


@pytest.mark.slow
def test_ctrl_c_while_waiting_for_a_mocap_server_stops_the_run_at_once_keeping_what_ran(
    tmp_path: Path,
):
    out = tmp_path / "run"
    command = [sys.executable, "-m", "cosim", "run", "lab-room", *LIVE[2:]]
    command += ["--set", "mocap.system=vicon", "--set", "mocap.hostname=127.0.0.1"]
    command += ["--out", str(out)]
    process = subprocess.Popen(command, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 20.0
    # the run is waiting on the system (other tests' runs may have workers of their own)
    while not workers(process.pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert workers(process.pid)
    time.sleep(0.5)
    process.send_signal(signal.SIGINT)
    stopped = time.monotonic()
    try:
        _, err = process.communicate(timeout=10.0)
    finally:
        if process.poll() is None:
            os.kill(process.pid, signal.SIGKILL)
    assert time.monotonic() - stopped < 3.0  # not the 10 s connect timeout
    assert process.returncode == 130, err
    assert err.startswith("cosim: stopped by SIGINT at ") and err.count("\n") == 1
    assert (out / "tables" / "mocap.parquet").is_file()
    assert not [w for w in workers() if "127.0.0.1" in w]


@pytest.mark.slow
def test_a_run_shorter_than_the_timeout_that_never_connects_fails_in_one_line_keeping_results(
    tmp_path: Path,
):
    out = tmp_path / "run"
    done = cosim_main(
        "run", "lab-room", "--duration-s", "1", "--quiet",
        "--set", "mocap.source=motioncapture", "--set", 'mocap.bodies=[["robot_1","jackal"]]',
        "--set", "mocap.system=vicon", "--set", "mocap.hostname=127.0.0.1",
        "--out", str(out),
    )  # fmt: skip
    assert done.returncode == 2  # as when the timeout passes: a live run without poses failed
    failed = (
        "the vicon motion capture at '127.0.0.1' did not answer within 1 s (no connection); the "
        "run ended at 1 s, within mocap.connect_timeout_s = 10 s: expected a pose of every "
        "tracked robot before the run ends (see mocap.system, mocap.hostname and mocap.bodies)"
    )
    summary = json.loads((out / "summary.json").read_text())
    assert done.stderr == (
        f"cosim: error: {failed}; the results of the {summary['sim_time_s']:g} s simulated are "
        f'in {out}/ (summary.json says "failed")\n'
    )
    assert summary["failed"] == failed and summary["failure"] == {"kind": "external"}
    assert summary["mocap_connected"] is False and summary["mocap_poses"] == 0
    assert 0.9 <= summary["sim_time_s"] < 1.0  # its last poll
    assert (out / "tables" / "mocap.parquet").is_file()
