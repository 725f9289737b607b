"""ROS 2 messages as Cyclone DDS types: byte-equal to rosbags' CDR serializer, and round trips."""

import math

import numpy as np
import pytest
from cyclonedds.idl import IdlStruct
from hypothesis import given
from hypothesis import strategies as st
from rosbags.typesys import Stores, get_typestore

from adapters.ros2dds.naming import ros_type
from adapters.ros2dds.types import (
    Header,
    LaserScan,
    Odometry,
    Point,
    Pose,
    PoseStamped,
    PoseWithCovariance,
    PoseWithCovarianceStamped,
    Quaternion,
    Time,
    Transform,
    TransformStamped,
    Twist,
    TwistWithCovariance,
    Vector3,
    quaternion_to_yaw,
    stamp,
    stamp_ns,
    yaw_to_quaternion,
)

HEADER = Header(stamp=Time(sec=1_700_000_000, nanosec=123_456_789), frame_id="robot_3/odom")
POSE = Pose(
    position=Point(x=1.5, y=-2.25, z=0.125),
    orientation=Quaternion(x=0.0, y=0.0, z=0.5, w=math.sqrt(0.75)),
)
TWIST = Twist(linear=Vector3(x=0.5, y=0.0, z=0.0), angular=Vector3(x=0.0, y=0.0, z=-0.75))
COVARIANCE = [float(i) / 8 for i in range(36)]

SAMPLES = [
    HEADER.stamp,
    HEADER,
    POSE.position,
    POSE.orientation,
    POSE,
    PoseStamped(header=HEADER, pose=POSE),
    PoseWithCovariance(pose=POSE, covariance=COVARIANCE),
    PoseWithCovarianceStamped(header=HEADER, pose=PoseWithCovariance(POSE, COVARIANCE)),
    TWIST.linear,
    TWIST,
    TwistWithCovariance(twist=TWIST, covariance=COVARIANCE),
    Transform(translation=Vector3(x=0.25, y=0.5, z=0.0), rotation=POSE.orientation),
    TransformStamped(
        header=HEADER, child_frame_id="robot_3/base_link", transform=Transform(Vector3(x=1.0))
    ),
    Odometry(
        header=HEADER,
        child_frame_id="robot_3/base_link",
        pose=PoseWithCovariance(POSE, COVARIANCE),
        twist=TwistWithCovariance(TWIST, COVARIANCE[::-1]),
    ),
    # float32 fields hold values exact in float32, so that they round-trip
    LaserScan(
        header=Header(stamp=HEADER.stamp, frame_id="robot_3/laser"),
        angle_min=-3.0,
        angle_max=3.0,
        angle_increment=0.0625,
        time_increment=0.0,
        scan_time=0.125,
        range_min=0.125,
        range_max=10.0,
        ranges=[1.0, 2.5, math.inf, 0.5],
        intensities=[],
    ),
]
GEOMETRY = [
    "Point",
    "Quaternion",
    "Pose",
    "PoseStamped",
    "PoseWithCovariance",
    "PoseWithCovarianceStamped",
    "Vector3",
    "Twist",
    "TwistWithCovariance",
    "Transform",
    "TransformStamped",
]
STORES = [get_typestore(Stores.ROS2_HUMBLE), get_typestore(Stores.ROS2_JAZZY)]


def _typename(sample: IdlStruct) -> str:
    return ros_type(type(sample).__idl_typename__)


def _to_rosbags(store, sample):
    """The rosbags message with the same content, built from rosbags' own field definitions."""
    typename = _typename(sample)
    values = {}
    for name, (_kind, detail) in store.fielddefs[typename][1]:
        value = getattr(sample, name)
        if isinstance(value, IdlStruct):
            values[name] = _to_rosbags(store, value)
        elif isinstance(value, list):
            values[name] = np.array(value, dtype=detail[0][1][0])
        else:
            values[name] = value
    return store.types[typename](**values)


@pytest.mark.parametrize("store", STORES, ids=["humble", "jazzy"])
@pytest.mark.parametrize("sample", SAMPLES, ids=_typename)
def test_every_type_serializes_byte_equal_to_rosbags(store, sample):
    expected = bytes(store.serialize_cdr(_to_rosbags(store, sample), _typename(sample)))
    assert sample.serialize() == expected


@pytest.mark.parametrize("sample", SAMPLES, ids=_typename)
def test_every_type_round_trips(sample):
    assert type(sample).deserialize(sample.serialize()) == sample


def test_every_ros_message_of_the_bridge_is_covered():
    covered = {_typename(sample) for sample in SAMPLES}
    assert covered == {
        "builtin_interfaces/msg/Time",
        "std_msgs/msg/Header",
        *(f"geometry_msgs/msg/{name}" for name in GEOMETRY),
        "nav_msgs/msg/Odometry",
        "sensor_msgs/msg/LaserScan",
    }


def test_a_default_quaternion_is_the_identity_as_in_ros_2():
    assert Quaternion() == Quaternion(0.0, 0.0, 0.0, 1.0)


@given(st.floats(min_value=-math.pi + 1e-9, max_value=math.pi))
def test_yaw_survives_a_quaternion(yaw):
    assert quaternion_to_yaw(*yaw_to_quaternion(yaw)) == pytest.approx(yaw, abs=1e-12)


def test_a_yaw_quaternion_is_a_unit_rotation_about_z():
    x, y, z, w = yaw_to_quaternion(math.pi / 2)
    assert (x, y) == (0.0, 0.0)
    assert (z, w) == pytest.approx((math.sqrt(0.5), math.sqrt(0.5)))


@given(st.integers(min_value=-(2**31) * 10**9, max_value=2**31 * 10**9 - 1))
def test_nanoseconds_survive_a_ros_time(ns):
    time = stamp(ns)
    assert 0 <= time.nanosec < 1_000_000_000
    assert stamp_ns(time) == ns


def test_a_time_beyond_int32_seconds_is_rejected_naming_the_value():
    with pytest.raises(ValueError, match=str(2**31 * 10**9)):
        stamp(2**31 * 10**9)
