"""Topics of a robot's navigation (the Nav2 role)."""

from __future__ import annotations

from adapters.naming import topic


def goal_topic(robot: str) -> str:
    """Goals for a robot's navigation (NavGoal, ``map``): ``/robot_1/nav/goal``."""
    return topic(robot, "nav/goal")


def status_topic(robot: str) -> str:
    """Progress of a robot's goals (NavStatus): ``/robot_1/nav/status``."""
    return topic(robot, "nav/status")


def plan_topic(robot: str) -> str:
    """A robot's planned path (Path, ``map``), as Nav2's planner publishes: ``/robot_1/plan``."""
    return topic(robot, "plan")


def goal_pose_topic(robot: str) -> str:
    """Where Nav2 and RViz's 2D Goal Pose take a goal (PoseStamped): ``/robot_1/goal_pose``."""
    return topic(robot, "goal_pose")
