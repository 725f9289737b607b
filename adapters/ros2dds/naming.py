"""ROS 2 names on DDS, as ``rmw_cyclonedds`` maps them.

``rmw_cyclonedds`` (ros2/rmw_cyclonedds, ``rmw_cyclonedds_cpp/src/rmw_node.cpp``) prefixes
every topic with ``rt`` (``rq``/``rr`` are service requests and replies, which cosim does
not use), and names a message type ``pkg::msg::dds_::Name_``: the ROS type's namespaces
joined by ``::`` with ``dds_`` before the type, whose name gains a trailing underscore.
"""

from __future__ import annotations

import re

_TOPIC_PREFIX = "rt"
_TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_TYPE = re.compile(r"([A-Za-z][A-Za-z0-9_]*)/msg/([A-Za-z][A-Za-z0-9_]*)")
_DDS_TYPE = re.compile(r"([A-Za-z][A-Za-z0-9_]*)::msg::dds_::([A-Za-z][A-Za-z0-9_]*)_")


def _check_ros_topic(ros_topic: str) -> None:
    if not ros_topic.startswith("/"):
        raise ValueError(f"ROS topic {ros_topic!r} must be absolute (start with '/')")
    if ros_topic.endswith("/"):
        raise ValueError(f"ROS topic {ros_topic!r} must not end with '/'")
    for token in ros_topic[1:].split("/"):
        if not token:
            raise ValueError(f"ROS topic {ros_topic!r} must not contain an empty token ('//')")
        if not _TOKEN.fullmatch(token):
            raise ValueError(
                f"ROS topic {ros_topic!r} has token {token!r}; expected letters, digits and"
                " '_', not starting with a digit"
            )


def dds_topic(ros_topic: str) -> str:
    """The DDS topic name of a fully qualified ROS 2 topic.

    Args:
        ros_topic: an absolute ROS 2 topic name, e.g. ``/robot_0/cmd_vel``.

    Returns:
        The DDS topic, e.g. ``rt/robot_0/cmd_vel``.

    Raises:
        ValueError: ``ros_topic`` is not a valid absolute ROS 2 name (it must start with
            ``/``, have no empty token and no trailing ``/``, and each token must be made of
            ``[A-Za-z0-9_]`` and not start with a digit).
    """
    _check_ros_topic(ros_topic)
    return _TOPIC_PREFIX + ros_topic


def ros_topic(dds_topic: str) -> str | None:
    """The ROS 2 topic that a DDS topic carries, or None for a topic that is not ROS 2's.

    Args:
        dds_topic: a DDS topic name, e.g. ``rt/robot_0/cmd_vel``.

    Returns:
        The ROS 2 topic (``/robot_0/cmd_vel``), or None if ``dds_topic`` lacks the ``rt``
        prefix or what follows it is not a valid ROS 2 name.
    """
    if not dds_topic.startswith(_TOPIC_PREFIX + "/"):
        return None
    name = dds_topic[len(_TOPIC_PREFIX) :]
    try:
        _check_ros_topic(name)
    except ValueError:
        return None
    return name


def dds_type(ros_type: str) -> str:
    """The DDS type name of a ROS 2 message type.

    Args:
        ros_type: a ROS 2 message type, e.g. ``geometry_msgs/msg/Twist``.

    Returns:
        The DDS type name, e.g. ``geometry_msgs::msg::dds_::Twist_``.

    Raises:
        ValueError: ``ros_type`` is not of the form ``package/msg/Name``.
    """
    match = _TYPE.fullmatch(ros_type)
    if match is None:
        raise ValueError(
            f"ROS type {ros_type!r} is not a message type; expected 'package/msg/Name'"
        )
    package, name = match.groups()
    return f"{package}::msg::dds_::{name}_"


def ros_type(dds_type: str) -> str:
    """The ROS 2 message type of a DDS type name (the inverse of :func:`dds_type`).

    Args:
        dds_type: a DDS type name, e.g. ``geometry_msgs::msg::dds_::Twist_``.

    Returns:
        The ROS 2 message type, e.g. ``geometry_msgs/msg/Twist``.

    Raises:
        ValueError: ``dds_type`` is not of the form ``package::msg::dds_::Name_``.
    """
    match = _DDS_TYPE.fullmatch(dds_type)
    if match is None:
        raise ValueError(
            f"DDS type {dds_type!r} is not a ROS 2 message type;"
            " expected 'package::msg::dds_::Name_'"
        )
    package, name = match.groups()
    return f"{package}/msg/{name}"
