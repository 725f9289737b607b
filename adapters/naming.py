"""Names of robots and their topics (ROS-like, one namespace per robot)."""

from __future__ import annotations


def robot_name(index: int) -> str:
    """Name of robot ``index`` (0-based index, 1-based name as in the paper: ``robot_1``)."""
    return f"robot_{index + 1}"


def topic(robot: str, leaf: str) -> str:
    """Topic ``leaf`` in the namespace of ``robot``, e.g. ``/robot_3/scan``."""
    return f"/{robot}/{leaf}"
