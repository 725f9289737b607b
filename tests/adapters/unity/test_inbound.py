"""What a Unity scene may publish into a run: goals, velocity commands and poses, checked."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from adapters.unity.inbound import (
    GOAL_TYPE,
    TWIST_TYPE,
    UnityGoal,
    UnityPose,
    UnityTwist,
    decode_goal,
    decode_pose,
    decode_twist,
    goal_topics,
    pose_topics,
    same_type,
    teleop_topics,
    unity_name,
)
from cosim.core.bus import Advertisement, TopicQos
from cosim.core.messages import LaserScan, NavGoal, NavStatus, PoseStamped, Twist
from cosim.recording.schemas import typestore
from tests.cosim.recording.connector import goal_pose_cdr, twist_cdr


def _pose_cdr(
    x: float,
    y: float,
    quaternion: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0),
    frame_id: str = "map",
) -> bytes:
    """A geometry_msgs/PoseStamped as a scene writes it (CDR, rosbags' typestore)."""
    store = typestore()
    t = store.types
    qx, qy, qz, qw = quaternion
    msg = t["geometry_msgs/msg/PoseStamped"](
        header=t["std_msgs/msg/Header"](
            stamp=t["builtin_interfaces/msg/Time"](sec=3, nanosec=5), frame_id=frame_id
        ),
        pose=t["geometry_msgs/msg/Pose"](
            position=t["geometry_msgs/msg/Point"](x=x, y=y, z=0.4),
            orientation=t["geometry_msgs/msg/Quaternion"](x=qx, y=qy, z=qz, w=qw),
        ),
    )
    return bytes(store.serialize_cdr(msg, "geometry_msgs/msg/PoseStamped"))


def _advertised(*topics: tuple[str, type]) -> dict[str, Advertisement]:
    return {name: Advertisement(name, kind, TopicQos.DEFAULT) for name, kind in topics}


def test_the_types_are_the_ros2_names_and_unity_spells_them_without_msg():
    assert (GOAL_TYPE, TWIST_TYPE) == ("geometry_msgs/msg/PoseStamped", "geometry_msgs/msg/Twist")
    assert unity_name("sensor_msgs/msg/LaserScan") == "sensor_msgs/LaserScan"
    assert same_type("geometry_msgs/Twist", TWIST_TYPE)
    assert same_type("geometry_msgs/msg/Twist", TWIST_TYPE)
    assert not same_type("geometry_msgs/TwistStamped", TWIST_TYPE)


def test_a_goal_pose_becomes_the_robots_goal_in_map_with_its_heading():
    goal = decode_goal("robot_2", goal_pose_cdr(4.5, -1.25, yaw=1.0))
    assert goal == UnityGoal("robot_2", 4.5, -1.25, pytest.approx(1.0))


def test_a_goal_with_a_zero_quaternion_takes_any_heading():
    goal = decode_goal("robot_1", _pose_cdr(1.0, 2.0, (0.0, 0.0, 0.0, 0.0)))
    assert (goal.x_m, goal.y_m) == (1.0, 2.0) and math.isnan(goal.yaw_rad)


def test_a_heading_is_read_from_any_unit_quaternion_about_z():
    for yaw in (-3.0, -0.5, 0.0, 2.5):
        q = (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
        assert decode_goal("robot_1", _pose_cdr(0.0, 0.0, q)).yaw_rad == pytest.approx(yaw)


@pytest.mark.parametrize("scale", [1e-200, 1e-3, 7.0, 1e200])
def test_a_heading_is_read_from_a_quaternion_of_any_scale(scale):
    # its products would vanish or overflow: the quaternion is normalized first
    q = (0.0, 0.0, scale * math.sin(0.6), scale * math.cos(0.6))
    assert decode_goal("robot_1", _pose_cdr(0.0, 0.0, q)).yaw_rad == pytest.approx(1.2)
    pose = decode_pose("/robot_1/pose", "/unity/robot_1/pose", _pose_cdr(0.0, 0.0, q))
    assert pose.yaw_rad == pytest.approx(1.2)


def test_a_goal_in_another_frame_than_map_is_refused_naming_the_topic_and_frame():
    with pytest.raises(ValueError) as refused:
        decode_goal("robot_1", _pose_cdr(1.0, 2.0, frame_id="odom"))
    assert str(refused.value) == ("/robot_1/goal_pose: header.frame_id is 'odom'; expected 'map'")


@pytest.mark.parametrize(("x", "y"), [(math.nan, 1.0), (1.0, math.inf), (-math.inf, 0.0)])
def test_a_goal_position_that_is_not_finite_is_refused(x, y):
    with pytest.raises(ValueError, match=r"/robot_1/goal_pose: position .*expected finite metres"):
        decode_goal("robot_1", _pose_cdr(x, y))


def test_an_orientation_that_is_not_finite_is_refused():
    with pytest.raises(ValueError, match=r"/robot_1/goal_pose: orientation .*expected finite"):
        decode_goal("robot_1", _pose_cdr(1.0, 1.0, (0.0, 0.0, math.nan, 1.0)))


@pytest.mark.parametrize("data", [b"", b"\x00\x01\x00\x00", b"garbage that is not cdr"])
def test_bytes_that_are_no_pose_stamped_are_refused_naming_the_topic_and_byte_count(data):
    with pytest.raises(ValueError) as refused:
        decode_goal("robot_3", data)
    assert str(refused.value).startswith(f"/robot_3/goal_pose: {len(data)} bytes are not a CDR")


def test_a_twist_is_the_forward_speed_and_yaw_rate_of_the_robots_cmd_vel():
    assert decode_twist("robot_1", twist_cdr(0.4, -0.3)) == UnityTwist("robot_1", 0.4, -0.3)
    # a sideways speed is not the robot's to take: it is dropped, not refused
    assert decode_twist("robot_1", twist_cdr(0.4, 0.0, linear_y=1.0)).linear_x_mps == 0.4


def test_a_twist_with_a_value_that_is_not_finite_is_refused_naming_the_topic():
    with pytest.raises(ValueError) as refused:
        decode_twist("robot_2", twist_cdr(math.nan, 0.0))
    message = str(refused.value)
    assert message.startswith("/robot_2/cmd_vel: linear [nan, 0.0, 0.0], angular [0.0, 0.0, 0.0]")
    assert message.endswith("expected finite numbers (m/s, rad/s)")


def test_a_twist_that_does_not_decode_is_refused_naming_the_topic():
    with pytest.raises(ValueError, match=r"^/robot_2/cmd_vel: 3 bytes are not a CDR"):
        decode_twist("robot_2", b"abc")


def test_a_tracked_pose_is_kept_with_its_bus_topic():
    pose = decode_pose("/robot_1/pose", "/unity/robot_1/pose", goal_pose_cdr(2.0, 3.0, yaw=-0.5))
    assert pose == UnityPose("/unity/robot_1/pose", 2.0, 3.0, pytest.approx(-0.5))


def test_a_tracked_pose_without_a_heading_is_refused():
    with pytest.raises(ValueError) as refused:
        decode_pose("/robot_1/pose", "/unity/robot_1/pose", _pose_cdr(1.0, 1.0, (0, 0, 0, 0)))
    assert str(refused.value) == (
        "/robot_1/pose: orientation is a zero quaternion; expected a heading"
    )


def test_a_tracked_pose_in_another_frame_is_refused_naming_the_scenes_topic():
    with pytest.raises(ValueError, match=r"^/body_7: header.frame_id is 'world'; expected 'map'"):
        decode_pose("/body_7", "/unity/body_7", _pose_cdr(1.0, 1.0, frame_id="world"))


def test_goal_topics_are_the_goal_poses_of_robots_whose_navigation_takes_goals():
    advertised = _advertised(
        ("/robot_1/nav/goal", NavGoal),
        ("/robot_2/nav/goal", NavGoal),
        ("/robot_2/nav/status", NavStatus),
        ("/robot_3/nav/goal", NavStatus),  # not a goal
        ("/nav/goal", NavGoal),  # no robot
        ("/fleet/robot_4/nav/goal", NavGoal),  # not a robot's own topic
    )
    assert goal_topics(advertised) == {
        "/robot_1/goal_pose": "robot_1",
        "/robot_2/goal_pose": "robot_2",
    }


def test_teleop_topics_are_the_cmd_vel_of_robots_whose_driver_takes_an_operator():
    advertised = _advertised(
        ("/robot_1/teleop/cmd_vel", Twist),
        ("/robot_2/cmd_vel", Twist),  # the fleet's own: not teleoperated
        ("/robot_3/teleop/cmd_vel", LaserScan),
    )
    assert teleop_topics(advertised) == {"/robot_1/cmd_vel": "robot_1"}


def test_pose_topics_map_each_scene_topic_to_its_bus_topic_under_unity():
    advertised = _advertised(
        ("/unity/robot_1/pose", PoseStamped),
        ("/unity/rigid/3", PoseStamped),
        ("/unity/robot_2/scan", LaserScan),  # not a pose
        ("/robot_1/pose", PoseStamped),  # not Unity's
        ("/unityish/pose", PoseStamped),
    )
    assert pose_topics(advertised) == {
        "/robot_1/pose": "/unity/robot_1/pose",
        "/rigid/3": "/unity/rigid/3",
    }


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=120))
def test_any_bytes_decode_to_a_checked_goal_twist_and_pose_or_are_refused(data):
    try:
        goal = decode_goal("robot_1", data)
        assert math.isfinite(goal.x_m) and math.isfinite(goal.y_m)
    except ValueError as problem:
        assert str(problem).startswith("/robot_1/goal_pose: ") and "\n" not in str(problem)
    try:
        twist = decode_twist("robot_1", data)
        assert math.isfinite(twist.linear_x_mps) and math.isfinite(twist.angular_z_radps)
    except ValueError as problem:
        assert str(problem).startswith("/robot_1/cmd_vel: ") and "\n" not in str(problem)
    try:
        pose = decode_pose("/robot_1/pose", "/unity/robot_1/pose", data)
        assert all(math.isfinite(v) for v in (pose.x_m, pose.y_m, pose.yaw_rad))
    except ValueError as problem:
        assert str(problem).startswith("/robot_1/pose: ") and "\n" not in str(problem)


@settings(max_examples=100, deadline=None)
@given(
    st.floats(-1e6, 1e6),
    st.floats(-1e6, 1e6),
    st.floats(-math.pi + 1e-6, math.pi - 1e-6),
)
def test_any_finite_goal_pose_decodes_to_the_same_position_and_heading(x, y, yaw):
    goal = decode_goal("robot_1", goal_pose_cdr(x, y, yaw=yaw))
    assert (goal.x_m, goal.y_m) == (x, y)
    assert goal.yaw_rad == pytest.approx(yaw, abs=1e-9)


ANY_FLOAT = st.floats(allow_nan=True, allow_infinity=True)


@settings(max_examples=200, deadline=None)
@given(ANY_FLOAT, ANY_FLOAT, st.tuples(ANY_FLOAT, ANY_FLOAT, ANY_FLOAT, ANY_FLOAT))
def test_a_well_formed_pose_with_any_numbers_is_taken_only_when_finite(x, y, quaternion):
    finite = all(math.isfinite(v) for v in (x, y, *quaternion))
    try:
        goal = decode_goal("robot_1", _pose_cdr(x, y, quaternion))
    except ValueError:
        assert not finite
        return
    assert finite and (goal.x_m, goal.y_m) == (x, y)
    assert math.isnan(goal.yaw_rad) == (not any(quaternion))
