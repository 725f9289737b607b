"""`cosim run --unity`: Connector-like clients attached to a real-time lab-room run."""

from __future__ import annotations

import json
import math
import socket
import threading
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

from cosim.recording.schemas import typestore
from tests.conftest import cosim_main
from tests.cosim.recording.connector import Connector, goal_pose_cdr

GOAL = (1.2, 2.0)
"""robot_1 starts at (0.6, 0.6) facing +y; its goal from Unity (m, map)."""


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def _same_as_rosbags(payload: bytes, msgtype: str) -> Any:
    """The message decoded by rosbags, after checking rosbags writes the very same bytes."""
    store = typestore()
    message = store.deserialize_cdr(payload, msgtype)
    assert payload[:4] == b"\x00\x01\x00\x00"
    assert bytes(store.serialize_cdr(message, msgtype)) == payload
    return message


def _scene(port: int, seen: dict[str, Any]) -> None:
    """What a Unity scene does: subscribe, list, reconnect, steer robot_1; a second one too."""
    scene = Connector(port)
    seen["first"] = scene.read()[0]
    scene.command("__subscribe", {"topic": "/tf", "message_name": "tf2_msgs/TFMessage"})
    scene.command(
        "__subscribe", {"topic": "/robot_1/scan", "message_name": "sensor_msgs/LaserScan"}
    )
    seen["tf"] = _same_as_rosbags(scene.until("/tf"), "tf2_msgs/msg/TFMessage")
    seen["scan"] = _same_as_rosbags(scene.until("/robot_1/scan"), "sensor_msgs/msg/LaserScan")
    scene.command("__topic_list", {})
    seen["topics"] = json.loads(scene.until("__topic_list"))
    other = Connector(port)  # a second scene at the same time, its own subscriptions
    seen["other_first"] = other.read()[0]
    other.command(
        "__subscribe", {"topic": "/robot_2/scan", "message_name": "sensor_msgs/LaserScan"}
    )
    seen["other_scan"] = _same_as_rosbags(other.until("/robot_2/scan"), "sensor_msgs/msg/LaserScan")
    garbage = Connector(port)
    garbage.sock.sendall(b"\xff\xff\xff\xffnot a frame at all")
    seen["garbage"] = json.loads(garbage.until("__error"))["text"]
    scene.reconnect()
    seen["again"] = scene.read()[0]
    seen["tf_again"] = _same_as_rosbags(scene.until("/tf"), "tf2_msgs/msg/TFMessage")
    scene.command(
        "__publish", {"topic": "/robot_1/goal_pose", "message_name": "geometry_msgs/PoseStamped",
                      "queue_size": 10, "latch": False},
    )  # fmt: skip
    scene.publish("/robot_1/goal_pose", goal_pose_cdr(*GOAL))
    scene.command("__topic_list", {})
    scene.until("__topic_list")
    for client in (scene, other, garbage):
        client.close()


@pytest.mark.slow
def test_unity_scenes_watch_a_lab_room_run_and_send_robot_1_to_a_goal(tmp_path: Path) -> None:
    port = _free_port()
    seen: dict[str, Any] = {}

    def scene() -> None:
        try:
            _scene(port, seen)
        except Exception as error:  # reported by the assertions below
            seen["error"] = repr(error)

    thread = threading.Thread(target=scene, daemon=True)
    thread.start()
    done = cosim_main(
        "run", "lab-room", "--unity", "--unity-port", str(port), "--duration-s", "7",
        "--out", str(tmp_path / "run"), "--bag", "none",
    )  # fmt: skip
    thread.join(timeout=5)
    assert "error" not in seen, seen.get("error")
    assert done.returncode == 0, done.stderr
    assert f"unity: ROS-TCP-Endpoint on 127.0.0.1:{port}" in done.stdout
    assert seen["first"] == seen["again"] == seen["other_first"] == "__handshake"
    transforms = seen["tf"].transforms
    assert transforms and all(t.header.frame_id and t.child_frame_id for t in transforms)
    assert len(seen["scan"].ranges) == 360 and len(seen["other_scan"].ranges) == 360
    listed = dict(zip(seen["topics"]["topics"], seen["topics"]["types"], strict=True))
    assert listed["/tf"] == "tf2_msgs/TFMessage"
    assert listed["/robot_1/goal_pose"] == "geometry_msgs/PoseStamped"
    assert "closing the connection" in seen["garbage"]
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["unity_clients"] == 4
    assert summary["unity_goals"] == 1
    assert summary["unity_frames_rejected"] == 1
    navigation = pd.read_parquet(tmp_path / "run" / "tables" / "navigation.parquet")
    mine = navigation[(navigation.robot == "robot_1") & (navigation.event == "goal")]
    assert ((mine.goal_x_m == GOAL[0]) & (mine.goal_y_m == GOAL[1])).any()
    poses = pd.read_parquet(tmp_path / "run" / "tables" / "poses.parquet")
    last = poses[poses.robot == "robot_1"].iloc[-1]
    assert math.dist((last.x_m, last.y_m), GOAL) < 0.35


def test_a_unity_port_in_use_is_one_line_naming_it(tmp_path: Path) -> None:
    with socket.create_server(("127.0.0.1", 0)) as taken:
        port = taken.getsockname()[1]
        done = cosim_main(
            "run", "lab-room", "--unity", "--unity-port", str(port), "--duration-s", "0.1",
            "--out", str(tmp_path / "run"),
        )  # fmt: skip
    assert done.returncode == 2
    assert done.stderr.count("\n") == 1
    assert done.stderr.startswith(f"cosim: error: --unity-port {port}: cannot serve Unity")
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize(
    ("host", "expected"),
    [("192.0.2.1", "--unity-host '192.0.2.1': cannot listen"), ("999.1.1.1", "--unity-host")],
)
def test_a_bad_unity_host_is_one_line_naming_it(host: str, expected: str, tmp_path: Path) -> None:
    done = cosim_main("run", "lab-room", "--unity", "--unity-host", host, "--out", str(tmp_path))
    assert done.returncode == 2
    assert expected in done.stderr
    assert "Traceback" not in done.stderr


def test_one_port_for_the_live_view_and_unity_is_one_line_naming_both_flags(
    tmp_path: Path,
) -> None:
    with socket.create_server(("127.0.0.1", 0)) as probe:
        port = probe.getsockname()[1]  # free once closed: nothing else is blamed
    done = cosim_main(
        "run", "lab-room", "--live", "--unity", "--live-port", str(port), "--unity-port",
        str(port), "--duration-s", "0.1", "--out", str(tmp_path / "run"),
    )  # fmt: skip
    assert done.returncode == 2
    assert done.stderr == (
        f"cosim: error: --live-port {port} and --unity-port {port} name the same port: the "
        "live view and the Unity endpoint cannot both listen on it (on 127.0.0.1); expected "
        "two different ports (0: any free one)\n"
    )
    assert not (tmp_path / "run").exists()
