"""Topics of the fleet: what drives a robot's base, what it reports, what it tells the others."""

from __future__ import annotations

from adapters.naming import topic

ROBOT_STATES = "/fleet/robot_states"
"""RobotState broadcasts of the robots layer (every robot's pose and footprint)."""


def cmd_vel_topic(robot: str) -> str:
    """Velocity commands to a robot's base (Twist, ``base_link``): ``/robot_1/cmd_vel``."""
    return topic(robot, "cmd_vel")


def odom_topic(robot: str) -> str:
    """A robot's wheel odometry (Odometry, ``odom``): ``/robot_1/odom``."""
    return topic(robot, "odom")
