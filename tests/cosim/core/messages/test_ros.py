"""The planar views of ROS 2's standard messages: sized, framed and decoded as ROS 2 has them."""

import dataclasses
import math

import numpy as np
import pytest
from rosbags.typesys import Stores, get_typestore

from cosim.core.messages import Goal, LaserScan, Odometry, Path, PoseStamped, Twist, std
from cosim.core.messages.decoding import decode_tree

STORE = get_typestore(Stores.ROS2_JAZZY)


def _ros(typename: str):
    return STORE.types[typename]


def _header(stamp_ns: int, frame_id: str):
    time = _ros("builtin_interfaces/msg/Time")(sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9)
    return _ros("std_msgs/msg/Header")(stamp=time, frame_id=frame_id)


def _pose():
    point = _ros("geometry_msgs/msg/Point")(x=1.0, y=2.0, z=0.0)
    quat = _ros("geometry_msgs/msg/Quaternion")(x=0.0, y=0.0, z=0.0, w=1.0)
    return _ros("geometry_msgs/msg/Pose")(position=point, orientation=quat)


def _vector():
    return _ros("geometry_msgs/msg/Vector3")(x=0.0, y=0.0, z=0.0)


def _cdr_size(typename: str, message) -> int:
    return len(STORE.serialize_cdr(message, typename))


def test_twist_size_matches_the_cdr_serialization_of_rosbags():
    ros = _ros("geometry_msgs/msg/Twist")(linear=_vector(), angular=_vector())
    assert Twist(1.0, 0.5).size_bytes() == _cdr_size(Twist.ros_type, ros)


@pytest.mark.parametrize("frame", ["map", "robot_12/odom", ""])
def test_pose_stamped_size_matches_the_cdr_serialization_of_rosbags(frame):
    ros = _ros("geometry_msgs/msg/PoseStamped")(header=_header(5, frame), pose=_pose())
    assert PoseStamped(5, frame, 1.0, 2.0, 0.0).size_bytes() == _cdr_size(PoseStamped.ros_type, ros)


def test_goal_is_sized_as_a_pose_stamped_in_map():
    ros = _ros("geometry_msgs/msg/PoseStamped")(header=_header(5, "map"), pose=_pose())
    assert Goal(5, 1.0, 2.0).size_bytes() == _cdr_size(Goal.ros_type, ros)


@pytest.mark.parametrize(("frame", "child"), [("odom", "base_link"), ("robot_1/odom", "a")])
def test_odometry_size_matches_the_cdr_serialization_of_rosbags(frame, child):
    cov = np.zeros(36)
    pose = _ros("geometry_msgs/msg/PoseWithCovariance")(pose=_pose(), covariance=cov)
    twist = _ros("geometry_msgs/msg/Twist")(linear=_vector(), angular=_vector())
    twist_cov = _ros("geometry_msgs/msg/TwistWithCovariance")(twist=twist, covariance=cov)
    ros = _ros("nav_msgs/msg/Odometry")(
        header=_header(7, frame), child_frame_id=child, pose=pose, twist=twist_cov
    )
    ours = Odometry(7, frame, child, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert ours.size_bytes() == _cdr_size(Odometry.ros_type, ros)


@pytest.mark.parametrize("beams", [0, 1, 360, 1081])
def test_laser_scan_size_matches_the_cdr_serialization_of_rosbags(beams):
    ranges = np.ones(beams, dtype=np.float32)
    ros = _ros("sensor_msgs/msg/LaserScan")(
        header=_header(9, "robot_1/laser"),
        angle_min=-3.14,
        angle_max=3.14,
        angle_increment=0.01,
        time_increment=0.0,
        scan_time=0.1,
        range_min=0.1,
        range_max=10.0,
        ranges=ranges,
        intensities=np.zeros(0, dtype=np.float32),
    )
    ours = LaserScan(9, "robot_1/laser", -3.14, 0.01, 0.1, 10.0, 0.1, ranges)
    assert ours.size_bytes() == _cdr_size(LaserScan.ros_type, ros)


def test_messages_are_immutable_including_scan_ranges():
    scan = LaserScan(0, "laser", 0.0, 0.1, 0.1, 10.0, 0.1, np.ones(4, dtype=np.float32))
    with pytest.raises(dataclasses.FrozenInstanceError):
        scan.stamp_ns = 5  # type: ignore[misc]
    with pytest.raises(ValueError):
        scan.ranges_m[0] = 3.0


def test_a_twist_is_sent_as_a_geometry_msgs_twist_with_only_x_and_yaw_rate_set():
    linear, angular = decode_tree(std.TWIST, Twist(0.7, -0.25).to_cdr())
    assert (linear, angular) == ((0.7, 0.0, 0.0), (0.0, 0.0, -0.25))
    assert Twist.from_cdr(Twist(0.7, -0.25).to_cdr()) == Twist(0.7, -0.25)


def test_odometry_leaves_both_covariances_zero_and_decodes_back():
    odom = Odometry(7, "robot_1/odom", "robot_1/base_link", 1.0, -2.0, 0.3, 0.5, -0.1)
    _, _, (_, pose_cov), (_, twist_cov) = decode_tree(std.ODOMETRY, odom.to_cdr())
    assert not pose_cov.any() and not twist_cov.any() and len(pose_cov) == 36
    back = Odometry.from_cdr(odom.to_cdr())
    assert dataclasses.replace(back, yaw_rad=0.3) == odom
    assert back.yaw_rad == pytest.approx(0.3)


def test_a_goal_is_a_pose_in_map_whose_missing_heading_is_sent_as_yaw_zero():
    goal = Goal(5, 1.0, 2.0)
    assert math.isnan(goal.yaw_rad)
    (stamp, frame), (_, rotation) = decode_tree(std.POSE_STAMPED, goal.to_cdr())
    assert (stamp, frame) == (5, "map")
    assert rotation == (0.0, 0.0, 0.0, 1.0)
    assert Goal.from_cdr(goal.to_cdr()) == Goal(5, 1.0, 2.0, 0.0)


def test_a_pose_stamped_keeps_its_frame_position_and_heading():
    back = PoseStamped.from_cdr(PoseStamped(42, "robot_2/odom", 3.0, 4.0, -2.5).to_cdr())
    assert (back.stamp_ns, back.frame_id, back.x_m, back.y_m) == (42, "robot_2/odom", 3.0, 4.0)
    assert back.yaw_rad == pytest.approx(-2.5)


def test_a_scan_sends_its_last_beam_angle_no_time_increment_and_no_intensities():
    ranges = np.array([1.0, np.inf, np.nan, 2.0], np.float32)
    scan = LaserScan(9, "robot_1/laser", -1.0, 0.5, 0.1, 10.0, 0.2, ranges)
    assert scan.angle_max_rad == pytest.approx(0.5)
    tree = dict(
        zip(std.LASER_SCAN.names(), decode_tree(std.LASER_SCAN, scan.to_cdr()), strict=True)
    )
    assert tree["angle_max"] == pytest.approx(0.5)
    assert tree["time_increment"] == 0.0 and len(tree["intensities"]) == 0
    assert tree["scan_time"] == pytest.approx(0.2)
    back = LaserScan.from_cdr(scan.to_cdr())
    assert back.ranges_m.tobytes() == ranges.tobytes()
    assert back.angle_increment_rad == pytest.approx(0.5) and back.frame_id == "robot_1/laser"


def test_a_path_of_one_waypoint_heads_along_x_and_an_empty_path_has_no_poses():
    _, poses = decode_tree(std.PATH, Path(3, "map", np.array([[2.0, 1.0]])).to_cdr())
    assert [pose for _, pose in poses] == [((2.0, 1.0, 0.0), (0.0, 0.0, 0.0, 1.0))]
    _, none = decode_tree(std.PATH, Path(3, "map", np.zeros((0, 2))).to_cdr())
    assert none == []


def test_a_path_decodes_to_its_waypoints_and_holds_them_read_only():
    xy = np.array([[0.0, 0.0], [1.0, 0.5], [1.0, 2.0]])
    path = Path(11, "map", xy)
    back = Path.from_cdr(path.to_cdr())
    assert (back.stamp_ns, back.frame_id) == (11, "map")
    assert np.array_equal(back.xy_m, xy) and back.xy_m.shape == (3, 2)
    assert Path.from_cdr(Path(1, "map", np.zeros((0, 2))).to_cdr()).xy_m.shape == (0, 2)
    with pytest.raises(ValueError):
        path.xy_m[0, 0] = 1.0
