"""Topics of the robots' sensors."""

from __future__ import annotations

from adapters.naming import topic


def scan_topic(robot: str) -> str:
    """A robot's lidar scans (LaserScan, ``robot_i/laser``): ``/robot_1/scan``."""
    return topic(robot, "scan")
