"""Every bus message encodes to the CDR bytes rosbags' serializer produces, and decodes back."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.core.messages import (
    CbbaBids,
    Clock,
    Goal,
    LaserScan,
    LocalizedScan,
    MapUpdate,
    Marker,
    MarkerAction,
    MarkerArray,
    MarkerType,
    Message,
    NavGoal,
    NavStatus,
    OccupancyGrid,
    Odometry,
    Path,
    PoseStamped,
    RobotState,
    ServiceReply,
    ServiceRequest,
    SimplexBasis,
    TaskAssignment,
    TaskClaim,
    TaskDone,
    TaskInfo,
    TaskOrder,
    TaskSet,
    TFMessage,
    Transform,
    Twist,
)
from cosim.recording.schemas import register, typestore

STORE = typestore()

EXAMPLES: list[Message] = [
    Twist(0.7, -0.25),
    Odometry(1_500_000_001, "robot_1/odom", "robot_1/base_link", 1.0, -2.0, 0.3, 0.5, -0.1),
    Odometry(7, "odom", "b", 0.0, 0.0, -3.0, 0.0, 0.0),
    PoseStamped(42, "map", 3.0, 4.0, 1.2),
    Goal(5, 1.0, 2.0),
    Goal(5, 1.0, 2.0, 0.5),
    LaserScan(
        9, "robot_12/laser", -math.pi, 0.0175, 0.1, 10.0, 0.1, np.linspace(0.1, 9, 360, dtype="f4")
    ),
    LaserScan(9, "l", -1.0, 0.5, 0.1, 10.0, 0.1, np.array([np.inf, np.nan, 1.0], dtype="f4")),
    LaserScan(9, "l", 0.0, 0.5, 0.1, 10.0, 0.1, np.zeros(0, dtype="f4")),
    Path(11, "map", np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 2.0]])),
    Path(11, "map", np.zeros((0, 2))),
    NavGoal(3, 2, 1.5, 2.5),
    NavStatus(3, 2, "progress", 1.0, 2.0, 7.5),
    RobotState(3, "robot_7", 1.0, 2.0, 0.1, 0.5, 0.33),
    TaskSet(
        13,
        4,
        (
            TaskInfo(1, 2.0, 3.0, ("robot_1", "robot_2"), "robot_1"),
            TaskInfo(2, 5.0, 6.0, (), ""),
        ),
    ),
    TaskSet(13, 0, ()),
    TaskClaim(14, 4, 1, "robot_1", 12.5, "claim"),
    ServiceRequest(15, 1, "robot_3"),
    ServiceReply(16, 1, "robot_3", True),
    TaskDone(17, 1, "robot_3"),
    SimplexBasis(18, 4, "robot_1", 3, ((0, 1, 2, 3.5), (1, 0, -1, 1e6))),
    CbbaBids(19, 4, "robot_2", (1.0, 2.5), (0, -1)),
    TaskOrder(20, 4, "robot_2", -1, math.nan),
    TaskAssignment(21, 4, "robot_2", 3, 8.25, 6),
    Clock(3_000_000_007),
    TFMessage(
        22,
        (
            Transform("map", "robot_1/odom", 0.1, -0.2, 0.05),
            Transform("robot_1/odom", "robot_1/base_link", 3.0, 4.0, -1.0),
            Transform("map", "robot_10/odom", 0.0, 0.0, 0.0),
        ),
    ),
    TFMessage(22, ()),
    OccupancyGrid(23, "map", 0.05, 3, 2, -0.2, -0.2, bytes([0, 100, 255, 0, 0, 100])),
    LocalizedScan(25, "robot_3", 1.0, 2.0, 0.5, -3.1, 0.0175, 0.1, 10.0, np.ones(7, dtype="f4")),
    MapUpdate(26, "robot_2", 4, 10, -3, 20, 5, 0.05, bytes(range(17))),
    MarkerArray(
        24,
        (
            Marker("shelves", 3, MarkerType.CUBE, x_m=1.0, y_m=2.0, z_m=0.9, scale_m=(2, 0.8, 1.8)),
            Marker(
                "robots", 0, MarkerType.CYLINDER, frame_id="robot_1/base_link", frame_locked=True
            ),
            Marker("tasks", 0, MarkerType.CYLINDER, action=MarkerAction.DELETEALL),
            Marker("tasks", 1_000_003, MarkerType.TEXT_VIEW_FACING, text="task 3: robot_1"),
        ),
    ),
    TaskInfo(3, 1.0, 2.0, ("robot_1",), "robot_2"),
]
for _example in EXAMPLES:
    register(type(_example).wire)


def _roundtrip(message: Message) -> tuple[bytes, object]:
    ours = message.to_cdr()
    decoded = STORE.deserialize_cdr(ours, message.ros_type)
    return ours, decoded


@pytest.mark.parametrize("message", EXAMPLES, ids=lambda m: type(m).__name__)
def test_our_encoding_equals_what_rosbags_serializes_from_the_decoded_message(message):
    ours, decoded = _roundtrip(message)
    assert STORE.serialize_cdr(decoded, message.ros_type) == ours


@pytest.mark.parametrize("message", EXAMPLES, ids=lambda m: type(m).__name__)
def test_the_size_a_message_reports_is_the_length_of_its_encoding(message):
    assert message.size_bytes() == len(message.to_cdr())


def test_every_message_class_has_an_example():
    # by name: a slotted dataclass leaves its pre-slots class behind among the subclasses
    covered = {type(m).__qualname__ for m in EXAMPLES}
    ours = {c.__qualname__ for c in Message.__subclasses__() if c.__module__.startswith("cosim.")}
    assert ours <= covered


def test_odometry_decodes_to_its_pose_twist_and_frames():
    message = EXAMPLES[1]
    assert isinstance(message, Odometry)
    _, ros = _roundtrip(message)
    assert (ros.header.stamp.sec, ros.header.stamp.nanosec) == (1, 500_000_001)
    assert (ros.header.frame_id, ros.child_frame_id) == ("robot_1/odom", "robot_1/base_link")
    pose = ros.pose.pose
    assert (pose.position.x, pose.position.y) == (1.0, -2.0)
    yaw = 2 * math.atan2(pose.orientation.z, pose.orientation.w)
    assert yaw == pytest.approx(0.3)
    assert (ros.twist.twist.linear.x, ros.twist.twist.angular.z) == (0.5, -0.1)


def test_a_scan_keeps_rep_117_no_return_and_dropout_values():
    message = EXAMPLES[7]
    _, ros = _roundtrip(message)
    assert math.isinf(ros.ranges[0]) and math.isnan(ros.ranges[1]) and ros.ranges[2] == 1.0
    assert ros.angle_max == pytest.approx(message.angle_max_rad)
    assert len(ros.intensities) == 0


def test_a_path_points_each_pose_along_the_path():
    _, ros = _roundtrip(EXAMPLES[9])
    yaws = [2 * math.atan2(p.pose.orientation.z, p.pose.orientation.w) for p in ros.poses]
    assert yaws == pytest.approx([0.0, math.pi / 2, math.pi / 2])
    assert [p.header.frame_id for p in ros.poses] == ["map"] * 3


def test_transforms_keep_their_frames_translation_and_yaw():
    _, ros = _roundtrip(EXAMPLES[25])
    frames = [(t.header.frame_id, t.child_frame_id) for t in ros.transforms]
    assert frames == [
        ("map", "robot_1/odom"),
        ("robot_1/odom", "robot_1/base_link"),
        ("map", "robot_10/odom"),
    ]
    second = ros.transforms[1].transform
    assert (second.translation.x, second.translation.y) == (3.0, 4.0)
    assert 2 * math.atan2(second.rotation.z, second.rotation.w) == pytest.approx(-1.0)


def test_an_occupancy_grid_keeps_unknown_cells_as_minus_one():
    _, ros = _roundtrip(EXAMPLES[27])
    assert ros.data.tolist() == [0, 100, -1, 0, 0, 100]
    assert (ros.info.width, ros.info.height) == (3, 2)
    assert ros.info.resolution == pytest.approx(0.05)


frame_ids = st.text(
    alphabet=st.characters(codec="utf-8", exclude_categories=("Cs",), exclude_characters="\x00"),
    max_size=23,
)


finite = st.floats(allow_nan=False, allow_infinity=False, width=32)


@settings(max_examples=150, deadline=None)
@given(
    frame=frame_ids,
    child=frame_ids,
    stamp=st.integers(0, 2**31 * 10**9 - 1),
    values=st.lists(
        st.floats(allow_nan=False, allow_infinity=False, width=32), min_size=5, max_size=5
    ),
    beams=st.integers(0, 40),
)
def test_any_frame_names_and_stamps_encode_exactly_as_rosbags_does(
    frame, child, stamp, values, beams
):
    x, y, yaw, v, w = values
    messages = [
        Odometry(stamp, frame, child, x, y, yaw, v, w),
        LaserScan(stamp, frame, x, 0.01, 0.1, 10.0, 0.1, np.full(beams, v, dtype="f4")),
        TFMessage(stamp, (Transform(frame, child, x, y, yaw), Transform(child, frame, v, w, x))),
        PoseStamped(stamp, frame, x, y, yaw),
    ]
    for message in messages:
        ours, decoded = _roundtrip(message)
        assert STORE.serialize_cdr(decoded, message.ros_type) == ours
        assert len(ours) == message.size_bytes()
