import cosim
from adapters.drivers.topics import teleop_topic, waypoint_topic
from adapters.fleet.topics import cmd_vel_topic
from adapters.navigation.topics import goal_pose_topic, goal_topic
from adapters.ros2dds.naming import dds_topic
from cosim.core.messages import Goal, Twist
from cosim.runner.assembly import assemble
from tests.conftest import SMALL


def test_the_drivers_topics_are_the_documented_ros_names():
    assert teleop_topic("robot_1") == "/robot_1/teleop/cmd_vel"
    assert waypoint_topic("robot_1") == "/robot_1/goal"
    assert dds_topic(teleop_topic("robot_7")) == "rt/robot_7/teleop/cmd_vel"
    assert dds_topic(waypoint_topic("robot_7")) == "rt/robot_7/goal"


def test_an_operators_commands_and_a_waypoint_are_not_taken_for_other_topics():
    robot = "robot_2"
    topics = [
        teleop_topic(robot),
        cmd_vel_topic(robot),
        waypoint_topic(robot),
        goal_topic(robot),
        goal_pose_topic(robot),
    ]
    assert len(set(topics)) == len(topics)


def test_the_waypoints_driver_advertises_a_goal_topic_per_robot():
    advertised = assemble(cosim.load_scenario("warehouse-random", SMALL)).run.bus.advertised()
    for robot in ("robot_1", "robot_2", "robot_3"):
        assert advertised[waypoint_topic(robot)].message_type is Goal
        assert teleop_topic(robot) not in advertised


def test_the_teleop_driver_listens_on_each_robots_teleop_topic():
    scenario = cosim.load_scenario("lab-room", overrides={"robots.driver": "teleop"})
    assembly = assemble(scenario)
    for _name, adapter in assembly.adapters:
        adapter.start(assembly.run)
    bus = assembly.run.bus
    for robot in ("robot_1", "robot_2"):
        assert bus.subscribers(teleop_topic(robot)) == [robot]
        assert bus.advertised()[cmd_vel_topic(robot)].message_type is Twist
