"""Topics of a robot's navigation: the names Nav2 and RViz use."""

from __future__ import annotations

from adapters.navigation.topics import goal_pose_topic, goal_topic, plan_topic, status_topic


def test_a_robots_navigation_topics_are_in_its_namespace():
    assert goal_topic("robot_1") == "/robot_1/nav/goal"
    assert status_topic("robot_1") == "/robot_1/nav/status"
    assert plan_topic("robot_1") == "/robot_1/plan"
    assert goal_pose_topic("robot_1") == "/robot_1/goal_pose"  # RViz's 2D Goal Pose


def test_no_two_topics_are_the_same():
    names = [
        f(f"robot_{i}")
        for i in range(1, 12)
        for f in (goal_topic, status_topic, plan_topic, goal_pose_topic)
    ]
    assert len(set(names)) == len(names)
