"""What a connection does with each frame Unity sends: system commands, publications.

Everything is checked before it is used; a refusal raises ``ValueError`` with the line
the connection sends back as ``__error`` (the Connector logs it in Unity's console) and
counts as a rejected frame. Nothing a scene sends can end the run.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from cosim.recording.unity import frames
from cosim.recording.unity.inbound import (
    GOAL_TYPE,
    TWIST_TYPE,
    decode_goal,
    decode_pose,
    decode_twist,
    same_type,
    unity_name,
)

if TYPE_CHECKING:
    from cosim.recording.unity.server import _Client

_IGNORED = frozenset({"__remove_ros_service", "__remove_unity_service"})
"""Commands about registrations cosim never makes: nothing to undo."""


def handle(client: _Client, destination: str, payload: bytes) -> None:
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


def _publishable(client: _Client, topic: str, name: str) -> str:
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
        if topic.endswith("/cmd_vel") and topic.count("/") == 2:
            raise ValueError(
                f"__publish: {topic}: {topic.split('/')[1]!r} takes no velocity commands; "
                'expected a robot whose driver allows teleoperation (robots.driver = "teleop")'
            )
        takes = ", ".join([*sink.goal_topics, *sink.teleop_topics, *sink.pose_topics])
        raise ValueError(
            f"__publish: cosim takes no {topic!r} from Unity; expected a goal "
            f"/<robot>/goal_pose, a teleop /<robot>/cmd_vel or a tracked pose "
            f"({takes or 'this run takes none'})"
        )
    if not same_type(name, msgtype):
        raise ValueError(f"__publish: {topic} takes {unity_name(msgtype)}, not {name!r}")
    return robot


def _publication(client: _Client, topic: str, payload: bytes) -> None:
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
