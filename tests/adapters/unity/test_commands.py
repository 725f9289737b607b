"""What a connection does with each frame: on a small endpoint and peer of the protocols."""

from __future__ import annotations

import json
import queue
from dataclasses import dataclass, field

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from adapters.unity import framing
from adapters.unity.commands import handle
from adapters.unity.inbound import UnityGoal, UnityPose, UnityTwist
from tests.cosim.recording.connector import goal_pose_cdr, twist_cdr

SCAN = "sensor_msgs/msg/LaserScan"


@dataclass(frozen=True)
class Channel:
    topic: str
    msgtype: str


class Endpoint:
    """Serves robot_1's scan and a latched map; takes robot_1's goals and teleop, a body's pose."""

    def __init__(self) -> None:
        self.channels = [
            Channel("/robot_1/scan", SCAN),
            Channel("/map", "nav_msgs/msg/OccupancyGrid"),
        ]
        self.by_topic = {c.topic: i for i, c in enumerate(self.channels)}
        self.goal_topics = {"/robot_1/goal_pose": "robot_1"}
        self.teleop_topics = {"/robot_1/cmd_vel": "robot_1"}
        self.pose_topics = {"/body_1/pose": "/unity/body_1/pose"}
        self.goals: queue.SimpleQueue[UnityGoal] = queue.SimpleQueue()
        self.twists: queue.SimpleQueue[UnityTwist] = queue.SimpleQueue()
        self.poses: list[UnityPose] = []
        self.last_map = [framing.frame("/map", b"grid")]

    def latched(self, topic: str) -> list[bytes]:
        return self.last_map if topic == "/map" else []

    def topic_list(self) -> dict[str, list[str]]:
        return {"topics": ["/robot_1/scan"], "types": ["sensor_msgs/LaserScan"]}

    def take_pose(self, pose: UnityPose) -> None:
        self.poses.append(pose)


@dataclass
class Peer:
    """One connection: what it registered, what it was sent, the frames that follow."""

    sink: Endpoint = field(default_factory=Endpoint)
    subscriptions: frozenset[str] = frozenset()
    publishes: dict[str, str] = field(default_factory=dict)
    sent: list[bytes] = field(default_factory=list)
    following: list[bytes] = field(default_factory=list)

    def send(self, data: bytes) -> None:
        self.sent.append(data)

    def read_next(self) -> bytes:
        return self.following.pop(0)


def _command(peer: Peer, name: str, **params: object) -> None:
    handle(peer, name, json.dumps(params).encode() + b"\x00")


def _registered(topic: str, message_name: str) -> Peer:
    peer = Peer()
    _command(peer, "__publish", topic=topic, message_name=message_name)
    return peer


def test_a_keepalive_does_nothing():
    peer = Peer()
    handle(peer, "", b"")
    assert peer.sent == [] and peer.subscriptions == frozenset() and peer.publishes == {}


def test_a_subscription_to_a_served_topic_is_kept_in_either_spelling_of_its_type():
    peer = Peer()
    _command(peer, "__subscribe", topic="/robot_1/scan", message_name="sensor_msgs/LaserScan")
    assert peer.subscriptions == {"/robot_1/scan"}
    _command(peer, "__subscribe", topic="/robot_1/scan", message_name=SCAN)
    assert peer.subscriptions == {"/robot_1/scan"} and peer.sent == []


def test_a_late_subscriber_to_a_latched_topic_is_sent_its_last_message():
    peer = Peer()
    _command(peer, "__subscribe", topic="/map", message_name="nav_msgs/OccupancyGrid")
    assert peer.sent == [framing.frame("/map", b"grid")]


def test_a_subscription_to_a_topic_the_run_does_not_serve_is_refused_saying_how_many_are():
    with pytest.raises(ValueError) as refused:
        _command(Peer(), "__subscribe", topic="/robot_9/scan", message_name="sensor_msgs/LaserScan")
    assert str(refused.value) == (
        "__subscribe: '/robot_9/scan' is not a topic of this run; expected one of "
        "__topic_list's topics (2 served)"
    )


def test_a_subscription_with_another_type_is_refused_naming_the_topics_type():
    peer = Peer()
    with pytest.raises(ValueError) as refused:
        _command(peer, "__subscribe", topic="/robot_1/scan", message_name="std_msgs/String")
    assert str(refused.value) == (
        "__subscribe: /robot_1/scan carries sensor_msgs/LaserScan, not 'std_msgs/String'"
    )
    assert peer.subscriptions == frozenset()


def test_a_subscription_without_a_type_is_refused_naming_the_key():
    with pytest.raises(ValueError, match="__subscribe: 'message_name' is None; expected a non-"):
        _command(Peer(), "__subscribe", topic="/robot_1/scan")


def test_a_removed_subscriber_gets_nothing_more():
    peer = Peer()
    _command(peer, "__subscribe", topic="/robot_1/scan", message_name=SCAN)
    _command(peer, "__remove_subscriber", topic="/robot_1/scan")
    assert peer.subscriptions == frozenset()


def test_the_topic_list_is_the_endpoints_answer():
    peer = Peer()
    _command(peer, "__topic_list")
    assert peer.sent == [framing.command("__topic_list", peer.sink.topic_list())]


def test_a_goal_published_after_registering_becomes_the_robots_goal():
    peer = _registered("/robot_1/goal_pose", "geometry_msgs/PoseStamped")
    assert peer.publishes == {"/robot_1/goal_pose": "robot_1"}
    handle(peer, "/robot_1/goal_pose", goal_pose_cdr(3.0, 4.0))
    goal = peer.sink.goals.get_nowait()
    assert (goal.robot, goal.x_m, goal.y_m, goal.yaw_rad) == ("robot_1", 3.0, 4.0, 0.0)


def test_a_twist_published_after_registering_becomes_the_robots_teleop_command():
    peer = _registered("/robot_1/cmd_vel", "geometry_msgs/msg/Twist")
    handle(peer, "/robot_1/cmd_vel", twist_cdr(0.5, 0.25))
    assert peer.sink.twists.get_nowait() == UnityTwist("robot_1", 0.5, 0.25)
    assert peer.sink.goals.empty()


def test_a_tracked_pose_published_after_registering_is_kept_under_its_bus_topic():
    peer = _registered("/body_1/pose", "geometry_msgs/PoseStamped")
    assert peer.publishes == {"/body_1/pose": "/unity/body_1/pose"}
    handle(peer, "/body_1/pose", goal_pose_cdr(1.0, 2.0))
    assert peer.sink.poses == [UnityPose("/unity/body_1/pose", 1.0, 2.0, 0.0)]


def test_a_publication_not_registered_on_this_connection_is_refused():
    with pytest.raises(ValueError, match=r"'/robot_1/goal_pose' is not registered for publishing"):
        handle(Peer(), "/robot_1/goal_pose", goal_pose_cdr(1.0, 1.0))


def test_a_removed_publisher_may_publish_no_more():
    peer = _registered("/robot_1/goal_pose", "geometry_msgs/PoseStamped")
    _command(peer, "__remove_publisher", topic="/robot_1/goal_pose")
    assert peer.publishes == {}
    with pytest.raises(ValueError, match="is not registered for publishing"):
        handle(peer, "/robot_1/goal_pose", goal_pose_cdr(1.0, 1.0))


def test_a_goal_that_does_not_decode_is_refused_and_not_queued():
    peer = _registered("/robot_1/goal_pose", "geometry_msgs/PoseStamped")
    with pytest.raises(ValueError, match=r"^/robot_1/goal_pose: 4 bytes are not a CDR"):
        handle(peer, "/robot_1/goal_pose", b"\x00\x01\x00\x00")
    assert peer.sink.goals.empty()


def test_a_publisher_of_the_wrong_type_is_refused_naming_the_type_taken():
    with pytest.raises(ValueError) as refused:
        _registered("/robot_1/goal_pose", "geometry_msgs/Twist")
    assert str(refused.value) == (
        "__publish: /robot_1/goal_pose takes geometry_msgs/PoseStamped, not 'geometry_msgs/Twist'"
    )


def test_velocity_commands_for_a_robot_without_teleoperation_are_refused_saying_why():
    with pytest.raises(ValueError) as refused:
        _registered("/robot_2/cmd_vel", "geometry_msgs/Twist")
    message = str(refused.value)
    assert message.startswith("__publish: /robot_2/cmd_vel: 'robot_2' takes no velocity commands")
    assert 'robots.driver = "teleop"' in message


def test_a_topic_cosim_does_not_take_is_refused_with_what_it_takes():
    with pytest.raises(ValueError) as refused:
        _registered("/robot_1/initialpose", "geometry_msgs/PoseStamped")
    assert str(refused.value) == (
        "__publish: cosim takes no '/robot_1/initialpose' from Unity; expected a goal "
        "/<robot>/goal_pose, a teleop /<robot>/cmd_vel or a tracked pose (/robot_1/goal_pose, "
        "/robot_1/cmd_vel, /body_1/pose)"
    )


def test_a_run_that_takes_nothing_says_so():
    peer = Peer()
    peer.sink.goal_topics, peer.sink.teleop_topics, peer.sink.pose_topics = {}, {}, {}
    with pytest.raises(ValueError, match=r"\(this run takes none\)$"):
        _command(peer, "__publish", topic="/robot_1/goal_pose", message_name="x/Y")


@pytest.mark.parametrize("name", ["__request", "__response"])
def test_a_service_call_is_refused_and_its_payload_frame_skipped(name):
    peer = Peer(following=[b"the request's payload", b"next"])
    with pytest.raises(
        ValueError, match=rf"^{name}: cosim runs without ROS and serves no services"
    ):
        handle(peer, name, b"{}")
    assert peer.following == [b"next"]  # the payload frame was read with the command


@pytest.mark.parametrize("name", ["__ros_service", "__unity_service"])
def test_a_service_registration_is_refused(name):
    with pytest.raises(ValueError, match="expected topics only"):
        _command(Peer(), name, topic="/srv", message_name="x/Y")


@pytest.mark.parametrize("name", ["__remove_ros_service", "__remove_unity_service"])
def test_removing_a_service_never_registered_is_ignored(name):
    peer = Peer()
    handle(peer, name, b"not even json")
    assert peer.sent == []


def test_an_unknown_command_is_refused_naming_it():
    with pytest.raises(ValueError, match=r"unknown command '__teleport'; expected ROS-TCP-Conn"):
        _command(Peer(), "__teleport")


def test_a_command_whose_payload_is_not_json_is_refused_naming_it():
    with pytest.raises(ValueError, match=r"^__subscribe: the payload is not JSON"):
        handle(Peer(), "__subscribe", b"{not json")


@settings(max_examples=300, deadline=None)
@given(
    st.sampled_from(
        [
            "",
            "__subscribe",
            "__publish",
            "__topic_list",
            "__remove_subscriber",
            "__remove_publisher",
            "__request",
            "__handshake",
            "/robot_1/goal_pose",
            "/robot_1/cmd_vel",
            "/body_1/pose",
        ]
    ),
    st.one_of(
        st.binary(max_size=60),
        st.dictionaries(
            st.sampled_from(["topic", "message_name"]),
            st.one_of(st.text(max_size=20), st.integers(), st.none()),
        ).map(lambda d: json.dumps(d).encode()),
    ),
    st.booleans(),
)
def test_any_frame_is_acted_on_or_refused_with_a_value_error_and_the_queues_hold_checked_values(
    destination, payload, registered
):
    peer = Peer(following=[b""])
    if registered:
        peer.publishes = {
            "/robot_1/goal_pose": "robot_1",
            "/robot_1/cmd_vel": "robot_1",
            "/body_1/pose": "/unity/body_1/pose",
        }
    try:
        handle(peer, destination, payload)
    except ValueError as problem:
        assert "\n" not in str(problem)
    assert peer.subscriptions <= set(peer.sink.by_topic)
    assert set(peer.publishes) <= {"/robot_1/goal_pose", "/robot_1/cmd_vel", "/body_1/pose"}
    while not peer.sink.goals.empty():
        goal = peer.sink.goals.get_nowait()
        assert goal.robot == "robot_1" and abs(goal.x_m) < float("inf")
