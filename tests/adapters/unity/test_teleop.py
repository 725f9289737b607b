"""Velocity commands from Unity: a Connector-like client against a kernel and bus."""

from __future__ import annotations

import json
import math
from collections.abc import Iterator

import pytest

from adapters.unity.server import UnityOptions, UnitySink
from cosim.core.bus import Bus
from cosim.core.kernel import Kernel
from cosim.core.messages import Message, Twist
from cosim.recording.schemas import channel_specs
from tests.cosim.recording.connector import Connector, goal_pose_cdr, twist_cdr

REGISTER = {"message_name": "geometry_msgs/Twist", "queue_size": 10, "latch": False}


class Teleop:
    """robot_1 takes teleop commands (its driver advertises them); robot_2 does not."""

    def __init__(self) -> None:
        self.kernel = Kernel()
        self.bus = Bus(self.kernel)
        for robot in ("robot_1", "robot_2"):
            self.bus.advertise(f"/{robot}/cmd_vel", Twist)
        self.bus.advertise("/robot_1/teleop/cmd_vel", Twist)
        self.commands: list[tuple[Message, str]] = []
        self.bus.monitor(
            "/robot_1/teleop/cmd_vel", lambda _t, m, src, _n: self.commands.append((m, src))
        )
        self.sink = UnitySink(UnityOptions(port=0), self.bus)
        self.sink.open(channel_specs(self.bus.advertised()))

    def client(self) -> Connector:
        client = Connector(self.sink.port)
        assert client.read()[0] == "__handshake"
        return client


@pytest.fixture
def teleop() -> Iterator[Teleop]:
    served = Teleop()
    yield served
    served.sink.close()


def _round_trip(client: Connector) -> dict[str, list[str]]:
    client.command("__topic_list", {})
    answer: dict[str, list[str]] = json.loads(client.until("__topic_list"))
    return answer


def test_a_twist_from_unity_is_published_as_the_robots_teleop_command(teleop: Teleop) -> None:
    client = teleop.client()
    listed = _round_trip(client)
    assert dict(zip(listed["topics"], listed["types"], strict=True))["/robot_1/cmd_vel"] == (
        "geometry_msgs/Twist"
    )
    client.command("__publish", {"topic": "/robot_1/cmd_vel", **REGISTER})
    client.publish("/robot_1/cmd_vel", twist_cdr(0.3, -0.5))
    _round_trip(client)
    teleop.kernel.run(100_000_000)
    assert teleop.commands == [(Twist(0.3, -0.5), "robot_1")]
    assert teleop.sink.summary()["unity_twists"] == 1


def test_garbage_twists_and_twists_for_robots_without_teleop_are_refused_and_counted(
    teleop: Teleop,
) -> None:
    client = teleop.client()
    client.command("__publish", {"topic": "/robot_2/cmd_vel", **REGISTER})
    refused = json.loads(client.until("__error"))["text"]
    assert "'robot_2' takes no velocity commands" in refused
    assert 'robots.driver = "teleop"' in refused
    client.command(
        "__publish", {"topic": "/robot_1/cmd_vel", "message_name": "geometry_msgs/PoseStamped"}
    )
    assert "takes geometry_msgs/Twist" in json.loads(client.until("__error"))["text"]
    client.command("__publish", {"topic": "/robot_1/cmd_vel", **REGISTER})
    bad = (
        b"\x00\x01\x00\x00short",
        twist_cdr(math.nan, 0.0),
        twist_cdr(0.1, math.inf),
        twist_cdr(0.1, 0.0, linear_y=-math.inf),
        goal_pose_cdr(1.0, 1.0),  # a pose on a Twist topic: rosbags finds the size wrong
    )
    for cdr in bad:
        client.publish("/robot_1/cmd_vel", cdr)
        assert "/robot_1/cmd_vel" in json.loads(client.until("__error"))["text"]
    client.publish("/robot_2/cmd_vel", twist_cdr(0.1, 0.0))  # never registered
    assert "not registered" in json.loads(client.until("__error"))["text"]
    _round_trip(client)
    teleop.kernel.run(100_000_000)
    assert teleop.commands == []
    summary = teleop.sink.summary()
    assert summary["unity_frames_rejected"] == 2 + len(bad) + 1
    assert summary["unity_twists"] == 0
