"""Topics of the simple robot drivers."""

from __future__ import annotations

from adapters.naming import topic


def teleop_topic(robot: str) -> str:
    """An operator's commands to a robot (Twist): ``/robot_1/teleop/cmd_vel``."""
    return topic(robot, "teleop/cmd_vel")


def waypoint_topic(robot: str) -> str:
    """The waypoint a go-to driver heads for (Goal, ``map``): ``/robot_1/goal``."""
    return topic(robot, "goal")
