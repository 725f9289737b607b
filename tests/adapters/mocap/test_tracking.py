import pytest

from adapters.mocap.replay import RecordedSource
from adapters.mocap.simulated import SimulatedSource
from adapters.mocap.tracking import live_sources, source_of, tracked_bodies, tracked_robots
from adapters.physical.bridge import physical_robots
from cosim import load_scenario
from cosim.core.errors import ConfigError

NAMES = ["robot_1", "robot_2", "robot_3"]


def scenario(**overrides: object):
    three = {"robots.count": 3, "robots.placement": "dock", "robots.positions": []}
    return load_scenario("lab-room", {**three, **overrides})


def test_simulated_mocap_tracks_every_robot_unless_told_which():
    assert tracked_robots(scenario(**{"mocap.source": "simulated"}), NAMES) == NAMES
    s = scenario(**{"mocap.source": "simulated", "mocap.robots": ["robot_2"]})
    assert tracked_robots(s, NAMES) == ["robot_2"]


def test_a_ros2_source_tracks_each_physical_robot_on_the_topic_pattern():
    s = scenario(
        **{
            "mocap.source": "ros2",
            "mocap.topic_pattern": "/vicon/{robot}/{robot}",
            "physical.robots": ["robot_2"],
        }
    )
    assert tracked_bodies(s, NAMES) == [("robot_2", "/vicon/robot_2/robot_2")]
    assert physical_robots(s, NAMES) == ["robot_2"]
    assert tracked_robots(s, NAMES) == ["robot_2"]


def test_a_physical_robot_reporting_its_own_odometry_localizes_by_it():
    s = scenario(**{"physical.robots": ["robot_3"], "physical.pose": "odom"})
    assert tracked_robots(s, NAMES) == ["robot_3"]


def test_without_a_source_nothing_is_tracked():
    s = scenario()
    assert source_of(s) is None
    assert tracked_bodies(s, NAMES) == [] and tracked_robots(s, NAMES) == []


def test_the_scenarios_source_is_its_registered_class():
    assert source_of(scenario(**{"mocap.source": "simulated"})) is SimulatedSource
    assert source_of(scenario(**{"mocap.source": "bag", "mocap.file": "t.csv"})) is RecordedSource


def test_a_replay_without_bodies_moves_the_first_robot_on_the_bags_only_track():
    s = scenario(**{"mocap.source": "bag", "mocap.file": "t.csv"})
    assert tracked_bodies(s, NAMES) == [("robot_1", "")]


def test_tracked_robots_come_in_fleet_order_whatever_the_order_of_the_bodies():
    s = scenario(**{"mocap.source": "ros2", "mocap.bodies": [["robot_3", "/a"], ["robot_1", "/b"]]})
    assert tracked_bodies(s, NAMES) == [("robot_3", "/a"), ("robot_1", "/b")]
    assert tracked_robots(s, NAMES) == ["robot_1", "robot_3"]


def test_an_external_source_that_tracks_nobody_is_refused_naming_what_it_needs():
    with pytest.raises(ConfigError) as refused:
        tracked_bodies(scenario(**{"mocap.source": "ros2"}), NAMES)
    assert str(refused.value) == (
        "preset lab-room: [mocap] bodies = []: expected [[robot, body], ...] or "
        "physical.robots for source = 'ros2'"
    )


@pytest.mark.parametrize(
    ("overrides", "key", "robot"),
    [
        ({"mocap.source": "simulated", "mocap.robots": ["robot_9"]}, "robots", "robot_9"),
        (
            {
                "mocap.source": "motioncapture",
                "mocap.system": "mock",
                "mocap.bodies": [["r7", "j"]],
            },
            "bodies",
            "r7",
        ),
    ],
)
def test_a_robot_not_in_the_fleet_is_refused_naming_the_key_and_the_robots(overrides, key, robot):
    with pytest.raises(ConfigError) as refused:
        tracked_bodies(scenario(**overrides), NAMES)
    assert str(refused.value) == (
        f"preset lab-room: [mocap] {key} names {robot!r}: expected one of the robots "
        "robot_1, robot_2, robot_3"
    )


def test_the_live_sources_are_those_that_send_on_the_wall_clock():
    assert live_sources() == ["motioncapture", "ros2", "unity"]
