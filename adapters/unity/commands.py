"""What a connection does with each frame Unity sends: system commands, publications.

Everything is checked before it is used; a refusal raises ``ValueError`` with the line
the connection sends back as ``__error`` (the Connector logs it in Unity's console) and
counts as a rejected frame. Nothing a scene sends can end the run.
"""

from __future__ import annotations

import queue
from collections.abc import Mapping, Sequence
from typing import Protocol

from adapters.fleet.topics import cmd_vel_topic
from adapters.navigation.topics import goal_pose_topic
from adapters.unity import framing as frames
from adapters.unity.inbound import (
    GOAL_TYPE,
    TWIST_TYPE,
    UnityGoal,
    UnityPose,
    UnityTwist,
    decode_goal,
    decode_pose,
    decode_twist,
    same_type,
    unity_name,
)


class Served(Protocol):
    """A topic the endpoint serves."""

    @property
    def topic(self) -> str:
        """The topic."""
        ...

    @property
    def msgtype(self) -> str:
        """Its ROS 2 type, ``pkg/msg/Type``."""
        ...


class Endpoint(Protocol):
    """What the frames of a connection act on (:class:`~adapters.unity.server.UnitySink`)."""

    channels: Sequence[Served]
    by_topic: Mapping[str, int]
    goal_topics: Mapping[str, str]
    teleop_topics: Mapping[str, str]
    pose_topics: Mapping[str, str]
    goals: queue.SimpleQueue[UnityGoal]
    twists: queue.SimpleQueue[UnityTwist]

    def latched(self, topic: str) -> list[bytes]:
        """The last frame of each publisher of a latched topic."""
        ...

    def topic_list(self) -> dict[str, list[str]]:
        """``__topic_list``'s answer."""
        ...

    def take_pose(self, pose: UnityPose) -> None:
        """Keep a tracked pose for the run."""
        ...


class Peer(Protocol):
    """One connection, as its frames act on it (:class:`~adapters.unity.connection.Connection`)."""

    sink: Endpoint
    subscriptions: frozenset[str]
    publishes: dict[str, str]

    def send(self, data: bytes) -> None:
        """Queue a frame to the scene."""
        ...

    def read_next(self) -> bytes:
        """The payload of the next frame."""
        ...


_IGNORED = frozenset({"__remove_ros_service", "__remove_unity_service"})
"""Commands about registrations cosim never makes: nothing to undo."""


def handle(client: Peer, destination: str, payload: bytes) -> None:
    """Act on one frame from Unity.

    Raises:
        ValueError: the frame is refused (the message says why and what was expected).
        FrameError: the stream cannot be followed (a service payload never came).
    """
    if destination == "":
        return  # keepalive
    if not destination.startswith("__"):
        _publication(client, destination, payload)
        return
    if destination in _IGNORED:
        return
    if destination in ("__request", "__response"):
        client.read_next()  # the payload follows in the next frame: skip it with the command
        raise ValueError(
            f"{destination}: cosim runs without ROS and serves no services; "
            "expected topics only (subscribe, publish)"
        )
    params = frames.parse_json(destination, payload)
    sink = client.sink
    if destination == "__subscribe":
        topic = frames.text_field(params, "topic", destination)
        name = frames.text_field(params, "message_name", destination)
        index = sink.by_topic.get(topic)
        if index is None:
            raise ValueError(
                f"__subscribe: {topic!r} is not a topic of this run; expected one of "
                f"__topic_list's topics ({len(sink.channels)} served)"
            )
        msgtype = sink.channels[index].msgtype
        if not same_type(name, msgtype):
            raise ValueError(f"__subscribe: {topic} carries {unity_name(msgtype)}, not {name!r}")
        client.subscriptions = client.subscriptions | {topic}
        for last in sink.latched(topic):
            client.send(last)
    elif destination == "__publish":
        topic = frames.text_field(params, "topic", destination)
        name = frames.text_field(params, "message_name", destination)
        client.publishes[topic] = _publishable(client, topic, name)
    elif destination == "__topic_list":
        client.send(frames.command("__topic_list", sink.topic_list()))
    elif destination == "__remove_subscriber":
        topic = frames.text_field(params, "topic", destination)
        client.subscriptions = client.subscriptions - {topic}
    elif destination == "__remove_publisher":
        client.publishes.pop(frames.text_field(params, "topic", destination), None)
    elif destination in ("__ros_service", "__unity_service"):
        raise ValueError(
            f"{destination}: cosim runs without ROS and serves no services; "
            "expected topics only (subscribe, publish)"
        )
    else:
        raise ValueError(f"unknown command {destination!r}; expected ROS-TCP-Connector 0.7's")


def _publishable(client: Peer, topic: str, name: str) -> str:
    """The robot a ``__publish`` of ``topic`` with type ``name`` steers (a pose: its bus topic).

    Raises:
        ValueError: the topic is not one cosim takes, or not with that type.
    """
    sink = client.sink
    robot, msgtype = sink.goal_topics.get(topic), GOAL_TYPE
    if robot is None:
        robot, msgtype = sink.teleop_topics.get(topic), TWIST_TYPE
    if robot is None:
        robot, msgtype = sink.pose_topics.get(topic), GOAL_TYPE
    if robot is None:
        robot_named = topic.split("/")[1] if topic.count("/") == 2 else ""
        if robot_named and cmd_vel_topic(robot_named) == topic:
            raise ValueError(
                f"__publish: {topic}: {robot_named!r} takes no velocity commands; "
                'expected a robot whose driver allows teleoperation (robots.driver = "teleop")'
            )
        takes = ", ".join([*sink.goal_topics, *sink.teleop_topics, *sink.pose_topics])
        raise ValueError(
            f"__publish: cosim takes no {topic!r} from Unity; expected a goal "
            f"{goal_pose_topic('<robot>')}, a teleop {cmd_vel_topic('<robot>')} or a tracked pose "
            f"({takes or 'this run takes none'})"
        )
    if not same_type(name, msgtype):
        raise ValueError(f"__publish: {topic} takes {unity_name(msgtype)}, not {name!r}")
    return robot


def _publication(client: Peer, topic: str, payload: bytes) -> None:
    """A goal, a velocity command or a tracked pose this connection registered."""
    robot = client.publishes.get(topic)
    if robot is None:
        raise ValueError(
            f"{topic!r} is not registered for publishing on this connection; expected "
            "__publish first (a goal: /<robot>/goal_pose, geometry_msgs/PoseStamped; a "
            "teleop command: /<robot>/cmd_vel, geometry_msgs/Twist)"
        )
    if topic in client.sink.teleop_topics:
        client.sink.twists.put(decode_twist(robot, payload))
    elif topic in client.sink.pose_topics:
        client.sink.take_pose(decode_pose(topic, robot, payload))
    else:
        client.sink.goals.put(decode_goal(robot, payload))
