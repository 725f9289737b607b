"""The Unity endpoint's sink on loopback: a Connector-like client against a kernel and bus."""

from __future__ import annotations

import json
import math
import socket
import struct
import threading
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from adapters.unity import framing
from adapters.unity.inbound import UnityGoal
from adapters.unity.server import UnityOptions, UnitySink
from cosim.core.bus import Bus, TopicQos
from cosim.core.errors import BridgeError
from cosim.core.hosts import HostId
from cosim.core.kernel import Kernel
from cosim.core.messages import LaserScan, Message, NavGoal
from cosim.recording.schemas import channel_specs, typestore
from tests.cosim.recording.connector import Connector, connector_string, goal_pose_cdr


class Served:
    """A bus with a robot's scan, goal and a latched topic, served to Unity."""

    def __init__(self) -> None:
        self.kernel = Kernel()
        self.bus = Bus(self.kernel)
        self.bus.advertise("/robot_1/scan", LaserScan, TopicQos.SENSOR)
        self.bus.advertise("/robot_1/nav/goal", NavGoal)
        self.bus.advertise("/goals_latched", NavGoal, TopicQos.LATCHED)
        self.goals: list[Message] = []
        self.bus.monitor("/robot_1/nav/goal", lambda _t, m, _s, _n: self.goals.append(m))
        self.sink = UnitySink(UnityOptions(port=0), self.bus)
        self.sink.open(channel_specs(self.bus.advertised()))

    def client(self) -> Connector:
        client = Connector(self.sink.port)
        destination, _payload = client.read()
        assert destination == "__handshake"
        return client


@pytest.fixture
def served() -> Iterator[Served]:
    served = Served()
    yield served
    served.sink.close()


def _scan() -> LaserScan:
    ranges = np.array([1.0, 2.5, np.inf], dtype=np.float32)
    return LaserScan(7, "robot_1/laser", -0.5, 0.5, 0.1, 10.0, 0.1, ranges)


def _round_trip(client: Connector) -> dict[str, Any]:
    """Ask for the topic list: every frame sent before it has been handled once it answers."""
    client.command("__topic_list", {})
    answer: dict[str, Any] = json.loads(client.until("__topic_list"))
    return answer


def test_the_first_frame_of_a_connection_is_the_ros2_handshake(served: Served) -> None:
    client = Connector(served.sink.port)
    destination, payload = client.read()
    handshake = json.loads(payload)
    assert destination == "__handshake"
    assert handshake["version"] == "v0.7.0"
    assert json.loads(handshake["metadata"]) == {"protocol": "ROS2"}
    client.close()


def test_a_subscribed_topic_arrives_with_the_bags_bytes_and_others_do_not(
    served: Served,
) -> None:
    client = served.client()
    client.command(
        "__subscribe", {"topic": "/robot_1/scan", "message_name": "sensor_msgs/LaserScan"}
    )
    _round_trip(client)
    scan = _scan()
    served.sink.write(1, 7, NavGoal(7, 1, 1.0, 2.0).to_cdr(), "robot_1")  # not subscribed
    served.sink.write(0, 7, scan.to_cdr(), "robot_1")
    destination, payload = client.read()
    assert destination == "/robot_1/scan"
    decoded = typestore().deserialize_cdr(payload, "sensor_msgs/msg/LaserScan")
    assert payload == bytes(typestore().serialize_cdr(decoded, "sensor_msgs/msg/LaserScan"))
    assert payload == scan.to_cdr()
    assert list(decoded.ranges[:2]) == [1.0, 2.5]


def test_the_topic_list_names_served_and_goal_topics_with_unitys_type_names(
    served: Served,
) -> None:
    answer = _round_trip(served.client())
    listed = dict(zip(answer["topics"], answer["types"], strict=True))
    assert listed["/robot_1/scan"] == "sensor_msgs/LaserScan"
    assert listed["/robot_1/goal_pose"] == "geometry_msgs/PoseStamped"


def test_a_late_subscriber_to_a_latched_topic_gets_its_last_message(served: Served) -> None:
    data = NavGoal(3, 4, 1.0, 2.0).to_cdr()
    served.sink.write(2, 3, data, "fleet")
    client = served.client()
    client.command("__subscribe", {"topic": "/goals_latched", "message_name": "cosim_msgs/NavGoal"})
    assert client.until("/goals_latched") == data


def test_a_goal_pose_from_unity_becomes_the_robots_nav_goal_on_the_bus(served: Served) -> None:
    client = served.client()
    client.command(
        "__publish",
        {"topic": "/robot_1/goal_pose", "message_name": "geometry_msgs/PoseStamped",
         "queue_size": 10, "latch": False},
    )  # fmt: skip
    client.publish("/robot_1/goal_pose", goal_pose_cdr(1.5, 2.0, yaw=math.pi / 2))
    _round_trip(client)
    served.kernel.run(100_000_000)
    assert len(served.goals) == 1
    goal = served.goals[0]
    assert isinstance(goal, NavGoal)
    assert (goal.x_m, goal.y_m) == (1.5, 2.0)
    assert goal.yaw_rad == pytest.approx(math.pi / 2)
    assert served.sink.summary()["unity_goals"] == 1


BAD_FRAMES = [
    ("__subscribe", b"{not json\x00"),
    ("__subscribe", b'{"topic": "/nowhere", "message_name": "std_msgs/String"}\x00'),
    ("__subscribe", b'{"topic": "/robot_1/scan", "message_name": "std_msgs/String"}\x00'),
    ("__publish", b'{"topic": "/robot_1/cmd_vel", "message_name": "geometry_msgs/Twist"}\x00'),
    ("__publish", b"[1, 2]\x00"),
    ("__ros_service", b'{"topic": "/spawn", "message_name": "x/Spawn"}\x00'),
    ("__eval", b'{"code": "import os"}\x00'),
    ("/robot_1/goal_pose", goal_pose_cdr(1.0, 1.0)),  # not registered on this connection
]


def test_refused_frames_are_answered_with_an_error_counted_and_the_connection_goes_on(
    served: Served,
) -> None:
    client = served.client()
    for destination, payload in BAD_FRAMES:
        client.sock.sendall(connector_string(destination) + struct.pack("<I", len(payload)))
        client.sock.sendall(payload)
        assert json.loads(client.until("__error"))["text"].startswith("cosim: ")
    client.command(
        "__publish", {"topic": "/robot_1/goal_pose", "message_name": "geometry_msgs/PoseStamped"}
    )
    for cdr in (b"\x00\x01\x00\x00garbage", goal_pose_cdr(1.0, 1.0, frame_id="odom"),
                goal_pose_cdr(math.nan, 1.0)):  # fmt: skip
        client.publish("/robot_1/goal_pose", cdr)
        assert "goal_pose" in json.loads(client.until("__error"))["text"]
    _round_trip(client)
    assert served.sink.summary()["unity_frames_rejected"] == len(BAD_FRAMES) + 3
    served.kernel.run(100_000_000)
    assert served.goals == []


def test_a_frame_longer_than_allowed_ends_that_connection_only(served: Served) -> None:
    client = served.client()
    client.sock.sendall(struct.pack("<I", 0xFFFFFFFF) + b"xx")
    assert "closing the connection" in json.loads(client.until("__error"))["text"]
    with pytest.raises((ConnectionError, OSError)):
        client.read()
    assert served.sink.summary()["unity_frames_rejected"] == 1
    assert _round_trip(served.client())["topics"]  # the server still serves


def test_a_connection_dropped_and_opened_again_registers_afresh(served: Served) -> None:
    client = served.client()
    client.command(
        "__subscribe", {"topic": "/robot_1/scan", "message_name": "sensor_msgs/LaserScan"}
    )
    client.reconnect()
    assert client.read()[0] == "__handshake"
    _round_trip(client)
    served.sink.write(0, 7, _scan().to_cdr(), "robot_1")
    assert client.until("/robot_1/scan") == _scan().to_cdr()
    assert served.sink.summary()["unity_clients"] == 2


@pytest.mark.slow
def test_an_idle_connection_gets_a_keepalive_within_the_connectors_timeout(
    served: Served,
) -> None:
    client = served.client()
    client.sock.settimeout(2.0)  # the Connector's network timeout
    assert client.read() == ("", b"")


def test_a_port_in_use_is_refused_naming_unity_port() -> None:
    kernel = Kernel()
    with socket.create_server(("127.0.0.1", 0)) as taken:
        port = taken.getsockname()[1]
        sink = UnitySink(UnityOptions(port=port), Bus(kernel))
        with pytest.raises(BridgeError, match=f"^--unity-port {port}: .*in use"):
            sink.open([])


def test_goals_from_unity_keep_the_hosts_robot_as_source(served: Served) -> None:
    sources: list[HostId] = []
    served.bus.monitor("/robot_1/nav/goal", lambda _t, _m, src, _n: sources.append(src))
    served.sink.goals.put(UnityGoal("robot_1", 1.0, 1.0, 0.0))
    served.kernel.run(100_000_000)
    assert sources == [HostId("robot_1")]


DESTINATIONS = st.one_of(
    st.sampled_from(
        [
            "__subscribe",
            "__publish",
            "__topic_list",
            "__request",
            "__ros_service",
            "__remove_subscriber",
            "/robot_1/goal_pose",
            "/robot_1/scan",
            "/tf",
            "",
        ]
    ),
    st.text(max_size=40),
)
PAYLOADS = st.one_of(
    st.binary(max_size=200),
    st.dictionaries(
        st.sampled_from(["topic", "message_name", "srv_id", "latch"]),
        st.one_of(st.text(max_size=20), st.integers(), st.none()),
        max_size=4,
    ).map(lambda d: json.dumps(d).encode() + b"\x00"),
)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(DESTINATIONS, PAYLOADS), min_size=1, max_size=6))
def test_any_well_framed_garbage_is_answered_or_counted_and_the_server_serves_on(
    frames: list[tuple[str, bytes]],
) -> None:
    served = Served()
    try:
        client = served.client()
        for destination, payload in frames:
            client.sock.sendall(connector_string(destination) + struct.pack("<I", len(payload)))
            client.sock.sendall(payload)
        answer = _round_trip(served.client())  # a second scene is served whatever the first sent
        assert "/robot_1/scan" in answer["topics"]
        served.kernel.run(100_000_000)
        # a goal gets in only when it was a valid pose: finite, in the map frame
        assert all(math.isfinite(getattr(goal, "x_m", math.nan)) for goal in served.goals)
    finally:
        served.sink.close()


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.binary(min_size=1, max_size=300))
def test_bytes_that_break_the_framing_close_that_connection_only(raw: bytes) -> None:
    served = Served()
    try:
        client = served.client()
        client.sock.sendall(raw)
        assert _round_trip(served.client())["topics"]  # another scene is served as before
    finally:
        served.sink.close()


def test_a_deeply_nested_subscribe_is_refused_in_one_line_and_the_connection_goes_on(
    served: Served, caplog: pytest.LogCaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    died: list[Any] = []
    monkeypatch.setattr(threading, "excepthook", died.append)
    client = served.client()
    nested = b'{"topic": ' * 30_000 + b'"/robot_1/scan"' + b"}" * 30_000
    client.sock.sendall(connector_string("__subscribe") + struct.pack("<I", len(nested)))
    client.sock.sendall(nested)
    text = json.loads(client.until("__error"))["text"]
    assert text == (
        "cosim: __subscribe: a JSON payload of 330015 bytes; expected at most 65536 "
        "(a command is a small flat object)"
    )
    deep = b"[" * 20_000 + b"]" * 20_000  # under the size limit, past Python's parser
    client.sock.sendall(connector_string("__subscribe") + struct.pack("<I", len(deep)) + deep)
    text = json.loads(client.until("__error"))["text"]
    assert text == (
        "cosim: __subscribe: JSON nested 20000 levels deep; expected at most 32 "
        "(a command is a flat object)"
    )
    assert "/robot_1/scan" in _round_trip(client)["topics"]  # the same connection serves on
    peer = f"127.0.0.1:{client.sock.getsockname()[1]}"
    assert caplog.messages[-1] == (
        f"unity: refused a frame from {peer}: __subscribe: JSON nested 20000 levels deep; "
        "expected at most 32 (a command is a flat object)"
    )
    assert served.sink.summary()["unity_frames_rejected"] == 2 and died == []


NESTED = st.builds(
    lambda depth, opener, closed: opener * depth + (b"]" * depth if closed else b""),
    st.integers(1, 40_000),
    st.sampled_from([b"[", b'{"topic":', b'[{"a": "]"}, ', b'{"a": [']),
    st.booleans(),
)
JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=12),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner),
    max_leaves=20,
).map(lambda v: json.dumps(v).encode())
INBOUND = st.one_of(st.binary(max_size=300), NESTED, JSON_VALUES, PAYLOADS)
COMMANDS = ["__subscribe", "__publish", "__topic_list", "__remove_subscriber",
            "__remove_publisher", "__ros_service", "__request", "__response"]  # fmt: skip


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.lists(
        st.tuples(
            st.one_of(st.sampled_from([*COMMANDS, "/robot_1/goal_pose"]), st.text(max_size=30)),
            INBOUND,
        ),
        min_size=1,
        max_size=6,
    )
)
def test_whatever_a_scene_sends_in_well_formed_frames_its_connection_is_answered_and_served_on(
    frames: list[tuple[str, bytes]],
) -> None:
    """Random bytes and JSON nested at random depths, to commands and to a goal topic."""
    died: list[Any] = []
    before, threading.excepthook = threading.excepthook, died.append
    served = Served()
    try:
        client = served.client()
        client.command(
            "__publish",
            {"topic": "/robot_1/goal_pose", "message_name": "geometry_msgs/PoseStamped"},
        )
        for destination, payload in frames:
            client.sock.sendall(connector_string(destination) + struct.pack("<I", len(payload)))
            client.sock.sendall(payload + framing.KEEPALIVE)  # what __request takes as its own
        assert "/robot_1/scan" in _round_trip(client)["topics"]  # this connection still serves
        assert died == []
        served.kernel.run(100_000_000)
        assert all(math.isfinite(getattr(goal, "x_m", math.nan)) for goal in served.goals)
    finally:
        threading.excepthook = before
        served.sink.close()
