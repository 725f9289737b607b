import pytest
from hypothesis import given
from hypothesis import strategies as st

import cosim
from adapters.naming import robot_name, topic
from adapters.ros2dds.naming import dds_topic
from cosim.runner.assembly import assemble
from models.fleet.kinematics import FleetState
from tests.conftest import SMALL


def test_robot_names_count_from_one_as_in_the_paper():
    assert [robot_name(i) for i in range(3)] == ["robot_1", "robot_2", "robot_3"]
    assert robot_name(9) == "robot_10"


@given(st.integers(min_value=0, max_value=10_000))
def test_a_robot_name_gives_its_index_back_and_is_a_ros_name_token(index):
    name = robot_name(index)
    assert int(name.removeprefix("robot_")) - 1 == index
    assert dds_topic(f"/{name}") == f"rt/{name}"


def test_a_topic_lies_in_the_namespace_of_its_robot():
    assert topic("robot_3", "scan") == "/robot_3/scan"
    assert topic("robot_1", "teleop/cmd_vel") == "/robot_1/teleop/cmd_vel"


@pytest.mark.parametrize("leaf", ["scan", "odom", "cmd_vel", "nav/goal", "teleop/cmd_vel"])
def test_topics_of_robots_are_valid_absolute_ros_topics_and_distinct_per_robot(leaf):
    names = [robot_name(i) for i in range(50)]
    topics = [topic(name, leaf) for name in names]
    assert len(set(topics)) == len(names)
    for name, t in zip(names, topics, strict=True):
        assert dds_topic(t) == f"rt/{name}/{leaf}"


def test_the_fleet_names_its_robots_by_robot_name():
    scenario = cosim.load_scenario("warehouse-random", overrides={**SMALL, "robots.count": 4})
    fleet = assemble(scenario, names=["fleet"]).run.service(FleetState)
    assert list(fleet.names) == [robot_name(i) for i in range(4)]
