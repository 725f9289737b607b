"""``mocap.source = "unity"``: poses a Connector-like client publishes become the twin's pose."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pytest

import cosim
from adapters.unity.server import UnityOptions, UnitySink
from cosim.core.errors import ConfigError
from cosim.core.timebase import s_to_ns
from cosim.recording.schemas import channel_specs
from cosim.runner.assembly import assemble
from models.fleet.kinematics import FleetState
from tests.conftest import cosim_main
from tests.cosim.recording.connector import Connector, goal_pose_cdr

UNITY = {"mocap.source": "unity", "mocap.bodies": [["robot_1", "/robot_1/pose"]]}
REGISTER = {"message_name": "geometry_msgs/PoseStamped", "queue_size": 10, "latch": False}


def _sent(client: Connector) -> None:
    """Wait until the server has handled every frame sent so far."""
    client.command("__topic_list", {})
    client.until("__topic_list")


@pytest.mark.slow
def test_a_unity_pose_stream_becomes_the_twins_pose_and_a_jump_is_rejected() -> None:
    scenario = cosim.load_scenario("lab-room", overrides=UNITY)
    assembly = assemble(scenario)
    run = assembly.run
    sink = UnitySink(UnityOptions(port=0), run.bus)
    sink.open(channel_specs(run.bus.advertised()))
    run.provide(sink)  # as the runner offers it
    for _name, adapter in assembly.adapters:
        adapter.start(run)
    fleet = run.service(FleetState)
    client = Connector(sink.port)
    try:
        assert client.read()[0] == "__handshake"
        client.command("__topic_list", {})
        listed = json.loads(client.until("__topic_list"))
        assert "/robot_1/pose" in listed["topics"]
        client.command("__publish", {"topic": "/robot_1/pose", **REGISTER})
        steps = [(0.6, 0.65), (0.6, 0.7), (3.0, 6.0), (0.6, 0.75)]  # the third one jumps
        for k, (x, y) in enumerate(steps):
            client.publish("/robot_1/pose", goal_pose_cdr(x, y, yaw=math.pi / 2))
            _sent(client)
            run.kernel.run(s_to_ns(0.1 * (k + 1)))
            if k != 2:
                assert (fleet.x[0], fleet.y[0]) == pytest.approx((x, y), abs=1e-6)
            else:
                assert (fleet.x[0], fleet.y[0]) == pytest.approx(steps[1], abs=1e-6)
        client.publish("/robot_1/pose", goal_pose_cdr(0.6, 0.8, frame_id="odom"))
        assert "expected 'map'" in json.loads(client.until("__error"))["text"]
    finally:
        client.close()
        sink.close()
    summary = {k: v for _n, a in assembly.adapters for k, v in a.finish(run).items()}
    assert summary["mocap_poses"] == 3
    assert summary["mocap_rejected_jumps"] == 1
    assert summary["mocap_unity_poses"] == 4
    assert sink.summary()["unity_poses"] == 4
    assert sink.summary()["unity_frames_rejected"] == 1


def test_a_unity_source_needs_a_topic_per_robot() -> None:
    with pytest.raises(ConfigError) as refused:
        cosim.load_scenario(
            "lab-room",
            overrides={**UNITY, "mocap.bodies": [], "mocap.topic_pattern": "/tracked/pose"},
        )
    assert str(refused.value) == (
        "--set mocap.topic_pattern: [mocap] topic_pattern = '/tracked/pose': expected a "
        "pattern containing {robot}"
    )


UNITY_FLAGS = ("--set", "mocap.source=unity", "--set", 'mocap.bodies=[["robot_1","/robot_1/pose"]]')


@pytest.mark.slow
def test_a_run_shorter_than_the_timeout_no_scene_publishes_to_fails_naming_the_endpoint(
    tmp_path: Path,
) -> None:
    out = tmp_path / "run"
    done = cosim_main(
        "run", "lab-room", "--duration-s", "1", "--quiet", "--unity", "--unity-port", "0",
        *UNITY_FLAGS, "--out", str(out),
    )  # fmt: skip
    assert done.returncode == 2
    summary = json.loads((out / "summary.json").read_text())
    port = re.search(r"ROS-TCP-Endpoint at 127\.0\.0\.1:(\d+) ", done.stderr)
    assert port is not None, done.stderr
    failed = (
        "no pose of robot_1 within 1 s: listened for geometry_msgs/PoseStamped in 'map' on "
        f"/robot_1/pose from Unity scenes on the ROS-TCP-Endpoint at 127.0.0.1:{port[1]} "
        "(0 connections; a scene registers the topic with __publish, then publishes); the run "
        "ended at 1 s, within mocap.connect_timeout_s = 10 s: expected a pose of every tracked "
        "robot before the run ends (see mocap.bodies or mocap.topic_pattern, and cosim run "
        "--unity)"
    )
    assert done.stderr == (
        f"cosim: error: {failed}; the results of the {summary['sim_time_s']:g} s simulated are "
        f'in {out}/ (summary.json says "failed")\n'
    )
    assert summary["failed"] == failed and summary["mocap_connected"] is False
    assert summary["unity_clients"] == 0 and summary["mocap_unity_poses"] == 0


def test_a_unity_source_in_a_run_serving_no_scene_ends_it_as_it_starts(tmp_path: Path) -> None:
    out = tmp_path / "run"
    done = cosim_main("run", "lab-room", "--quiet", *UNITY_FLAGS, "--out", str(out))
    assert done.returncode == 2
    assert done.stderr == (
        "cosim: error: mocap.source = 'unity': no pose of robot_1 can come (on /robot_1/pose): "
        "this run serves no Unity scene; expected cosim run --unity (from Python: "
        "cosim.run(..., unity=UnityOptions())); the results of the 0 s simulated are in "
        f'{out}/ (summary.json says "failed")\n'
    )
