"""Topics the run publishes for ROS 2 tools: the names RViz, Foxglove and ros2 bag expect."""

from __future__ import annotations

from adapters.recording.topics import CLOCK, MAP, MARKERS, TF, TF_STATIC, ground_truth_topic


def test_the_shared_topics_are_the_ones_ros_tools_listen_on():
    assert (CLOCK, TF, TF_STATIC, MAP) == ("/clock", "/tf", "/tf_static", "/map")
    assert MARKERS == "/world/markers"


def test_a_robots_ground_truth_is_in_its_namespace():
    assert ground_truth_topic("robot_1") == "/robot_1/ground_truth"
    assert ground_truth_topic("robot_12") == "/robot_12/ground_truth"


def test_no_two_topics_are_the_same():
    names = [CLOCK, TF, TF_STATIC, MAP, MARKERS]
    names += [ground_truth_topic(f"robot_{i}") for i in range(1, 4)]
    assert len(set(names)) == len(names)
