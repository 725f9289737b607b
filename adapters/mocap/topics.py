"""Topics of motion capture."""

from __future__ import annotations

from adapters.naming import topic


def pose_topic(robot: str) -> str:
    """The measured poses a robot localizes by (PoseStamped, ``map``): ``/robot_1/pose``."""
    return topic(robot, "pose")
