"""Topics the run publishes for ROS 2 tools (RViz, Foxglove, ``ros2 bag``)."""

from __future__ import annotations

from adapters.naming import topic

CLOCK = "/clock"
"""The simulation time (Clock)."""
TF = "/tf"
"""Every robot's frames (TFMessage): ``map`` -> ``robot_i/odom`` -> ``robot_i/base_link``."""
TF_STATIC = "/tf_static"
"""Frames that never move (TFMessage, latched): ``robot_i/base_link`` -> ``robot_i/laser``."""
MAP = "/map"
"""The world's occupancy grid (OccupancyGrid, latched)."""
MARKERS = "/world/markers"
"""Walls, shelves, robots, tasks and people as shapes (MarkerArray)."""


def ground_truth_topic(robot: str) -> str:
    """A robot's true pose (PoseStamped, ``map``): ``/robot_1/ground_truth``."""
    return topic(robot, "ground_truth")
