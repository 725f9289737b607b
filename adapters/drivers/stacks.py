"""cosim's own robot drivers, registered in ``cosim.drivers`` as a plugin's are.

A driver is the robot software a scenario runs (``robots.driver``): a set of adapters.
"""

from __future__ import annotations

from cosim.core.adapter import Driver

NAVIGATION = Driver(
    ("navigation", "goals"),
    "navigation (the Nav2 role) to random reachable goals, or to navigation.goals in turn",
)
TASKS = Driver(
    ("navigation", "task_source", "dta"),
    "dynamic task assignment over the network (assignment.protocol), driving through navigation",
)
WAYPOINTS = Driver(
    ("waypoints",),
    "straight-line random waypoints with a go-to-goal controller, avoiding nothing",
    needs_lidar=False,
)
WANDER = Driver(("wander",), "reactive roaming that steers away from what the lidar sees")
TELEOP = Driver(
    ("teleop",),
    "an operator's velocity commands (a Unity scene's /<robot>/cmd_vel), stopped 0.5 s after "
    "the last one, avoiding nothing",
    needs_lidar=False,
)
AGENTS = Driver(
    ("agents",),
    "learning agents: a Gymnasium or PettingZoo environment (cosim.envs) decides every "
    "robot's velocity or goal ([agents])",
    needs_lidar=False,
)
