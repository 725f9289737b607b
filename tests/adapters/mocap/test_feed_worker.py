import ast
import json
import math
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from adapters.mocap import feed_worker
from adapters.mocap.feed import mock_bodies, quaternion_yaw
from adapters.mocap.feed_worker import frame_record, yaw_of

WORKER = Path(feed_worker.__file__)
BODIES = {"r1": (1.0, 2.0, 0.5), "r2": (3.0, 4.0, -1.0)}


def test_the_identity_quaternion_heads_along_x():
    assert yaw_of(1.0, 0.0, 0.0, 0.0) == 0.0


@given(st.floats(min_value=-math.pi + 1e-9, max_value=math.pi - 1e-9))
def test_the_yaw_of_a_turn_about_z_is_its_angle_in_libmotioncaptures_order(yaw):
    w, z = math.cos(yaw / 2), math.sin(yaw / 2)
    assert yaw_of(w, 0.0, 0.0, z) == pytest.approx(yaw, abs=1e-12)
    assert yaw_of(-w, 0.0, 0.0, -z) == pytest.approx(yaw, abs=1e-12)  # the same rotation
    assert yaw_of(w, 0.0, 0.0, z) == pytest.approx(quaternion_yaw(w, 0.0, 0.0, z), abs=1e-12)


def test_a_roll_or_pitch_alone_does_not_turn_the_heading():
    half = math.cos(0.3), math.sin(0.3)
    assert yaw_of(half[0], half[1], 0.0, 0.0) == pytest.approx(0.0)
    assert yaw_of(half[0], 0.0, half[1], 0.0) == pytest.approx(0.0)


def body(x: float, y: float, yaw: float, z: float = 0.7) -> Any:
    """A rigid body as libmotioncapture hands it over (position, rotation w x y z)."""
    rotation = SimpleNamespace(w=math.cos(yaw / 2), x=0.0, y=0.0, z=math.sin(yaw / 2))
    return SimpleNamespace(position=[x, y, z], rotation=rotation)


def test_a_frame_keeps_the_wanted_bodies_planar_poses_and_counts_the_occluded():
    rigid = {
        "r1": body(1.0, 2.0, 0.5),
        "stranger": body(5.0, 5.0, 0.0),
        "r2": body(math.nan, 4.0, 0.0),  # lost by the cameras
        "r3": body(3.0, -1.0, -2.0),
    }
    record = frame_record(rigid, {"r1", "r2", "r3", "absent"}, 1234)
    assert record["t"] == 1234 and record["occluded"] == 1
    assert [(name, x, y) for name, x, y, _ in record["poses"]] == [
        ("r1", 1.0, 2.0),
        ("r3", 3.0, -1.0),
    ]
    assert [yaw for *_, yaw in record["poses"]] == pytest.approx([0.5, -2.0])
    json.dumps(record)  # one line of the protocol


def test_an_empty_frame_is_a_line_without_poses():
    assert frame_record({}, {"r1"}, 5) == {"t": 5, "poses": [], "occluded": 0}


def test_the_worker_imports_nothing_but_the_standard_library_and_motioncapture():
    imported = set()
    for node in ast.walk(ast.parse(WORKER.read_text())):
        if isinstance(node, ast.Import):
            imported |= {alias.name.split(".")[0] for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            imported.add(node.module.split(".")[0])
    assert imported - set(sys.stdlib_module_names) == {"motioncapture"}


def worker(system: str, bodies: list[str], options: dict[str, str]) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [sys.executable, "-P", str(WORKER), system, "", json.dumps(bodies), json.dumps(options)],
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def lines(process: subprocess.Popen[str], count: int) -> list[dict[str, Any]]:
    assert process.stdout is not None
    return [json.loads(process.stdout.readline()) for _ in range(count)]


def test_the_worker_says_it_connected_then_writes_frames_of_the_wanted_bodies():
    before = time.time_ns()
    process = worker("mock", ["r1", "ghost"], {"rigid_bodies": mock_bodies(BODIES)})
    try:
        connected, *frames = lines(process, 4)
    finally:
        process.kill()
        process.wait()
    assert connected == {"connected": True}
    for frame in frames:
        assert before <= frame["t"] <= time.time_ns()  # wall clock, ns
        assert frame["occluded"] == 0
        [(name, x, y, yaw)] = frame["poses"]
        assert name == "r1"
        assert (x, y, yaw) == pytest.approx(BODIES["r1"], abs=1e-6)
    assert [f["t"] for f in frames] == sorted(f["t"] for f in frames)


def test_a_system_the_library_refuses_is_one_error_line_and_exit_status_3():
    process = worker("nosuch", ["r1"], {})
    out, _ = process.communicate(timeout=20)
    assert process.returncode == 3
    [line] = out.splitlines()
    assert set(json.loads(line)) == {"error"} and json.loads(line)["error"]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="signals of Linux")
def test_ctrl_c_does_not_end_the_worker_the_run_decides_when_it_ends():
    process = worker("mock", ["r1"], {"rigid_bodies": mock_bodies(BODIES)})
    try:
        lines(process, 2)
        process.send_signal(signal.SIGINT)
        after = lines(process, 2)
        assert all(frame["poses"] for frame in after)
        assert process.poll() is None
    finally:
        process.kill()
        process.wait()


PARENT = textwrap.dedent(
    """
    import subprocess, sys
    with open(sys.argv[1], "w") as out:  # not a pipe: the worker must not die of a closed one
        child = subprocess.Popen(sys.argv[2:], stdout=out, stderr=subprocess.DEVNULL)
    print(child.pid, flush=True)
    child.wait()
    """
)
"""Starts the worker ``argv[2:]`` writing to the file ``argv[1]``, says its pid, waits."""


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state not in ("Z", "X")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG is Linux's")
def test_the_worker_dies_with_the_run_that_started_it_even_killed_outright(tmp_path):
    said = tmp_path / "worker.jsonl"
    command = [sys.executable, "-P", str(WORKER), "mock", "", '["r1"]']
    command.append(json.dumps({"rigid_bodies": mock_bodies(BODIES)}))
    parent = subprocess.Popen(
        [sys.executable, "-c", PARENT, str(said), *command], stdout=subprocess.PIPE, text=True
    )
    assert parent.stdout is not None
    pid = int(parent.stdout.readline())
    deadline = time.monotonic() + 10.0
    while said.read_text().count("\n") < 2 and time.monotonic() < deadline:
        time.sleep(0.01)  # connected and framing: it asked to die with its parent before
    assert _alive(pid)
    parent.kill()
    parent.wait()
    deadline = time.monotonic() + 5.0
    while _alive(pid) and time.monotonic() < deadline:
        time.sleep(0.01)
    alive = _alive(pid)
    if alive:
        os.kill(pid, signal.SIGKILL)
    assert not alive
