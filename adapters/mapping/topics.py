"""Topics of the robots' mapping (slam_toolbox's, namespaced per robot as Nav2 remaps them)."""

from __future__ import annotations

from adapters.naming import topic

SCANS = "/fleet/mapping/scans"
"""LocalizedScan broadcasts of ``mapping.share = "scans"``."""
UPDATES = "/fleet/mapping/updates"
"""MapUpdate broadcasts of ``mapping.share = "maps"``."""
FLEET_MAP = "/fleet/map"
"""OccupancyGrid: every robot's map fused, from the base station."""


def map_topic(robot: str) -> str:
    """A robot's map (OccupancyGrid, latched), which its navigation plans on."""
    return topic(robot, "map")


def correction_topic(robot: str) -> str:
    """A robot's ``map -> robot_i/odom`` correction (TFMessage, namespaced tf)."""
    return topic(robot, "tf")
