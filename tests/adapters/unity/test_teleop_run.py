"""`cosim run lab-room --unity` with the teleop driver: a scene drives robot_1 by Twist."""

from __future__ import annotations

import json
import math
import socket
import threading
import time
from pathlib import Path
from typing import Any

import pandas as pd
import pytest

from tests.conftest import cosim_main
from tests.cosim.recording.connector import Connector, twist_cdr

START = (0.6, 0.6)
"""robot_1's start in lab-room (m, map), facing +y with 2 m free ahead."""


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def _operator(port: int, seen: dict[str, Any]) -> None:
    """A scene's teleop: 0.3 m/s forward at 10 Hz for 1.5 s, a garbage Twist, then nothing."""
    scene = Connector(port)
    scene.read()  # the handshake
    scene.command(
        "__publish", {"topic": "/robot_1/cmd_vel", "message_name": "geometry_msgs/Twist",
                      "queue_size": 10, "latch": False},
    )  # fmt: skip
    for _ in range(15):
        scene.publish("/robot_1/cmd_vel", twist_cdr(0.3, 0.0))
        time.sleep(0.1)
    scene.publish("/robot_1/cmd_vel", twist_cdr(math.nan, 0.0))
    seen["garbage"] = json.loads(scene.until("__error"))["text"]
    scene.close()


@pytest.mark.slow
def test_a_unity_scene_drives_a_teleop_robot_and_its_garbage_twist_is_counted(
    tmp_path: Path,
) -> None:
    port = _free_port()
    seen: dict[str, Any] = {}

    def operator() -> None:
        try:
            _operator(port, seen)
        except Exception as error:  # reported by the assertions below
            seen["error"] = repr(error)

    thread = threading.Thread(target=operator, daemon=True)
    thread.start()
    done = cosim_main(
        "run", "lab-room", "--unity", "--unity-port", str(port), "--duration-s", "4",
        "--set", 'robots.driver="teleop"', "--out", str(tmp_path / "run"), "--bag", "none",
    )  # fmt: skip
    thread.join(timeout=5)
    assert "error" not in seen, seen.get("error")
    assert done.returncode == 0, done.stderr
    assert "/robot_1/cmd_vel" in seen["garbage"] and "expected finite" in seen["garbage"]
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["unity_twists"] == 15
    assert summary["unity_frames_rejected"] == 1
    assert summary["teleop_deadman_stops"] == 1
    poses = pd.read_parquet(tmp_path / "run" / "tables" / "poses.parquet")
    mine = poses[poses.robot == "robot_1"]
    last = mine.iloc[-1]
    assert abs(last.x_m - START[0]) < 0.05
    assert 0.2 < last.y_m - START[1] < 0.6  # about 0.3 m/s for 1.5 s, then stopped
    assert (mine.t_s.iloc[-1] - mine[mine.y_m < last.y_m - 1e-3].t_s.max()) > 1.0
    others = poses[poses.robot != "robot_1"].groupby("robot", observed=True)
    assert all(math.dist(*group[["x_m", "y_m"]].iloc[[0, -1]].to_numpy()) < 1e-6
               for _robot, group in others)  # fmt: skip
