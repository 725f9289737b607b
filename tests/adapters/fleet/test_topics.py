import cosim
from adapters.fleet.topics import ROBOT_STATES, cmd_vel_topic, odom_topic
from adapters.ros2dds.naming import dds_topic
from cosim.core.messages import Odometry, RobotState, Twist
from cosim.runner.assembly import assemble
from tests.conftest import SMALL


def test_a_robots_base_takes_commands_and_reports_odometry_in_its_namespace():
    assert cmd_vel_topic("robot_1") == "/robot_1/cmd_vel"
    assert odom_topic("robot_1") == "/robot_1/odom"


def test_the_robot_states_go_to_the_whole_fleet_on_one_topic():
    assert ROBOT_STATES == "/fleet/robot_states"
    assert dds_topic(ROBOT_STATES) == "rt/fleet/robot_states"


def test_the_fleet_topics_are_valid_ros_topics_and_distinct():
    names = [f"robot_{i}" for i in range(1, 11)]
    topics = [ROBOT_STATES] + [f(n) for n in names for f in (cmd_vel_topic, odom_topic)]
    assert len(set(topics)) == len(topics)
    for t in topics:
        assert dds_topic(t) == "rt" + t


def test_a_run_advertises_the_fleet_topics_with_their_message_types():
    overrides = {**SMALL, "robots.driver": "navigation", "navigation.robots_layer": True}
    advertised = assemble(cosim.load_scenario("warehouse-random", overrides)).run.bus.advertised()
    assert advertised[ROBOT_STATES].message_type is RobotState
    for robot in ("robot_1", "robot_2", "robot_3"):
        assert advertised[cmd_vel_topic(robot)].message_type is Twist
        assert advertised[odom_topic(robot)].message_type is Odometry
