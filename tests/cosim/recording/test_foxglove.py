"""The live view: a WebSocket client on loopback against `cosim run --live` in another process."""

import json
import socket
import struct
import subprocess
import sys
import time
from pathlib import Path

import pytest
from websockets.exceptions import InvalidStatus
from websockets.sync.client import ClientConnection, connect

from cosim.recording.schemas import typestore
from tests.cosim.cli.test_cli import SMALL

SUBPROTOCOL = "foxglove.sdk.v1"
MESSAGE_DATA = 0x01
"""Opcode of a binary message-data frame: uint32 subscription id, uint64 log time, payload."""

pytestmark = pytest.mark.slow


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def _start(port: int, out: Path, *extra: str) -> subprocess.Popen[str]:
    command = [
        sys.executable, "-m", "cosim", "run", "warehouse-random", *SMALL,
        "--duration-s", "20", "--out", str(out), "--bag", "none",
        "--live", "--live-port", str(port), "--live-rate", "4", *extra,
    ]  # fmt: skip
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _connect(port: int, process: subprocess.Popen[str]) -> ClientConnection:
    deadline = time.monotonic() + 60
    while True:
        try:
            return connect(f"ws://127.0.0.1:{port}", subprotocols=[SUBPROTOCOL], open_timeout=5)
        except (OSError, InvalidStatus):
            if process.poll() is not None or time.monotonic() > deadline:
                raise AssertionError(f"no live view: {process.communicate()[1]}") from None
            time.sleep(0.2)


def _channels(ws: ClientConnection) -> dict[str, dict]:
    channels: dict[str, dict] = {}
    while "/robot_1/scan" not in channels or "/map" not in channels:
        frame = ws.recv(timeout=30)
        if isinstance(frame, str):
            message = json.loads(frame)
            if message["op"] == "advertise":
                channels.update({c["topic"]: c for c in message["channels"]})
    return channels


def _next_data(ws: ClientConnection, subscription: int) -> tuple[int, bytes]:
    while True:
        frame = ws.recv(timeout=30)
        if isinstance(frame, bytes) and frame[0] == MESSAGE_DATA:
            sub, log_ns = struct.unpack_from("<IQ", frame, 1)
            if sub == subscription:
                return log_ns, frame[13:]


@pytest.mark.slow
def test_a_viewer_sees_the_channels_subscribes_to_a_scan_and_decodes_a_laser_scan(tmp_path):
    port = _free_port()
    process = _start(port, tmp_path / "run", "--live-wait")
    try:
        with _connect(port, process) as ws:
            assert ws.subprotocol == SUBPROTOCOL
            channels = _channels(ws)
            scan = channels["/robot_1/scan"]
            assert scan["schemaName"] == "sensor_msgs/msg/LaserScan"
            assert (scan["encoding"], scan["schemaEncoding"]) == ("cdr", "ros2msg")
            assert "float32[] ranges" in scan["schema"]
            assert channels["/fleet/tasks"]["schemaName"] == "cosim_msgs/msg/TaskSet"
            ws.send(
                json.dumps(
                    {"op": "subscribe", "subscriptions": [{"id": 7, "channelId": scan["id"]}]}
                )
            )
            log_ns, payload = _next_data(ws, 7)
            message = typestore().deserialize_cdr(payload, "sensor_msgs/msg/LaserScan")
            assert message.header.frame_id == "robot_1/laser"
            assert len(message.ranges) == 90
            stamp = message.header.stamp
            assert stamp.sec * 10**9 + stamp.nanosec == log_ns
            # /map was published once, at the start: a late subscriber still gets it
            ws.send(
                json.dumps(
                    {
                        "op": "subscribe",
                        "subscriptions": [{"id": 8, "channelId": channels["/map"]["id"]}],
                    }
                )
            )
            _, grid = _next_data(ws, 8)
            occupancy = typestore().deserialize_cdr(grid, "nav_msgs/msg/OccupancyGrid")
            assert occupancy.info.width * occupancy.info.height == len(occupancy.data) > 0
    finally:
        process.terminate()
        process.communicate(timeout=30)


@pytest.mark.slow
def test_the_run_is_paced_at_the_live_rate(tmp_path):
    port = _free_port()
    process = _start(port, tmp_path / "run")
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 0, stderr
    assert f"live view: ws://127.0.0.1:{port}" in stdout
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    # 20 s simulated at 4x real time cannot take less than 5 s of wall time
    assert summary["wall_time_s"] >= 0.95 * 20 / 4


@pytest.mark.slow
def test_a_taken_port_is_one_line_and_exit_2_before_anything_is_written(tmp_path):
    with socket.socket() as holder:
        holder.bind(("127.0.0.1", 0))
        holder.listen()
        port = int(holder.getsockname()[1])
        out = tmp_path / "run"
        out.mkdir()
        (out / "keep.txt").write_text("earlier results")
        process = _start(port, out, "--force")
        _, stderr = process.communicate(timeout=120)
    assert process.returncode == 2
    assert stderr.count("\n") == 1 and f"--live-port {port}" in stderr
    assert "Traceback" not in stderr
    assert sorted(p.name for p in out.iterdir()) == ["keep.txt"]


@pytest.mark.slow
def test_a_viewer_sees_the_people_sumo_moves_as_markers(tmp_path):
    port = _free_port()
    command = [
        sys.executable, "-m", "cosim", "run", "warehouse-humans", "--set", "humans.workers=4",
        "--duration-s", "20", "--out", str(tmp_path / "run"), "--bag", "none",
        "--live", "--live-port", str(port), "--live-rate", "4", "--live-wait",
    ]  # fmt: skip
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        with _connect(port, process) as ws:
            channels = _channels(ws)
            while "/humans/markers" not in channels:
                frame = ws.recv(timeout=30)
                if isinstance(frame, str) and json.loads(frame)["op"] == "advertise":
                    channels.update({c["topic"]: c for c in json.loads(frame)["channels"]})
            people = channels["/humans/markers"]
            assert people["schemaName"] == "visualization_msgs/msg/MarkerArray"
            ws.send(
                json.dumps(
                    {"op": "subscribe", "subscriptions": [{"id": 9, "channelId": people["id"]}]}
                )
            )
            shown = []
            while len(shown) < 4:  # nobody before SUMO's first step
                _, payload = _next_data(ws, 9)
                message = typestore().deserialize_cdr(payload, "visualization_msgs/msg/MarkerArray")
                shown = [m for m in message.markers if m.action == 0]
            assert {m.ns for m in shown} == {"humans"}
            assert all(m.header.frame_id == "map" for m in shown)
    finally:
        process.terminate()
        process.communicate(timeout=30)
