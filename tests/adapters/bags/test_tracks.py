import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.typesys import Stores, get_typestore

from adapters.bags.tracks import TrackError, read_pose_track
from cosim.core.errors import BagError
from tests.conftest import SHARED_DATA

NAV2 = SHARED_DATA / "nav2_turtlebot.mcap"
needs_nav2 = pytest.mark.skipif(
    not NAV2.exists(), reason=f"real ROS 2 bag {NAV2} absent (the shared data folder is not here)"
)

TYPES = get_typestore(Stores.ROS2_HUMBLE)
Time = TYPES.types["builtin_interfaces/msg/Time"]
Header = TYPES.types["std_msgs/msg/Header"]
Point = TYPES.types["geometry_msgs/msg/Point"]
Vector3 = TYPES.types["geometry_msgs/msg/Vector3"]
Quaternion = TYPES.types["geometry_msgs/msg/Quaternion"]
Pose = TYPES.types["geometry_msgs/msg/Pose"]
PoseStamped = TYPES.types["geometry_msgs/msg/PoseStamped"]
Transform = TYPES.types["geometry_msgs/msg/Transform"]
TransformStamped = TYPES.types["geometry_msgs/msg/TransformStamped"]

EPOCH_NS = 1_700_000_000_123_456_789
# (header stamp ns, x_m, y_m, yaw_rad), stamps increasing, yaws on both sides of +-pi
POSES = [
    (EPOCH_NS, 1.25, -0.5, 0.3),
    (EPOCH_NS + 10_000_001, 1.2625, -0.4875, 3.1),
    (EPOCH_NS + 20_000_000, 1.275, -0.475, -3.1),
    (EPOCH_NS + 3_000_000_000, -7.0, 1e-3, -math.pi / 2),
]


def reference(topic: str) -> tuple[list[int], list[tuple[float, float, float]], str]:
    """Header stamps, planar poses and frame as the independent mcap reader decodes them."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    stamps, poses, frames = [], [], set()
    with NAV2.open("rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _schema, _channel, _message, msg in reader.iter_decoded_messages(topics=[topic]):
            stamps.append(msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec)
            p, q = msg.pose.pose.position, msg.pose.pose.orientation
            # the yaw of a unit quaternion, spelled unlike tracks.yaw_of
            yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), q.w**2 + q.x**2 - q.y**2 - q.z**2)
            poses.append((p.x, p.y, yaw))
            frames.add(msg.header.frame_id)
    (frame,) = frames
    return stamps, poses, frame


@needs_nav2
@pytest.mark.parametrize(
    ("topic", "count", "frame"), [("/amcl_pose", 135, "map"), ("/odom", 2639, "odom")]
)
def test_a_rosbag2_track_reads_as_the_mcap_reader_decodes_it(topic, count, frame):
    stamps, poses, ref_frame = reference(topic)
    # read_pose_track sorts by stamp and keeps one pose per stamp; this bag's header
    # stamps are already strictly increasing, so the track is the topic message for message
    assert len(stamps) == count
    assert np.all(np.diff(stamps) > 0)
    track = read_pose_track(NAV2, topic)
    assert len(track) == count and track.stamps == "header"
    assert track.t_ns.dtype == np.int64 and track.t_ns.tolist() == stamps
    ref = np.asarray(poses)
    assert np.array_equal(track.x_m, ref[:, 0]) and np.array_equal(track.y_m, ref[:, 1])
    assert np.allclose(track.yaw_rad, ref[:, 2], rtol=0, atol=1e-12)
    assert track.frame_id == ref_frame == frame
    assert str(NAV2) in track.source and topic in track.source


@needs_nav2
def test_a_bag_with_two_pose_topics_and_no_topic_named_lists_both():
    with pytest.raises(BagError) as error:
        read_pose_track(NAV2)
    message = str(error.value)
    assert "found 2" in message
    assert "/amcl_pose (geometry_msgs/msg/PoseWithCovarianceStamped)" in message
    assert "/odom (nav_msgs/msg/Odometry)" in message


@needs_nav2
def test_a_topic_of_another_type_is_refused_naming_its_type():
    with pytest.raises(BagError, match=r"topic /tf is tf2_msgs/msg/TFMessage: expected one of"):
        read_pose_track(NAV2, "/tf")


@needs_nav2
def test_an_unknown_topic_is_refused_listing_the_pose_topics():
    with pytest.raises(BagError, match=r"no topic /nosuch; pose topics are /amcl_pose, /odom"):
        read_pose_track(NAV2, "/nosuch")


def test_a_text_file_named_mcap_is_not_a_bag(tmp_path: Path):
    fake = tmp_path / "notes.mcap"
    fake.write_text("these are notes, not a bag\n")
    with pytest.raises(BagError, match=r"notes\.mcap"):
        read_pose_track(fake, "/pose")
    with pytest.raises(BagError, match=r"notes\.mcap"):
        read_pose_track(fake)


def header(stamp_ns: int, frame: str) -> object:
    return Header(stamp=Time(sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9), frame_id=frame)


def rotation(yaw: float) -> object:
    return Quaternion(x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2))


def pose_stamped(stamp_ns: int, x: float, y: float, yaw: float) -> object:
    position = Point(x=x, y=y, z=0.3)
    return PoseStamped(header(stamp_ns, "map"), Pose(position=position, orientation=rotation(yaw)))


def transform_stamped(stamp_ns: int, x: float, y: float, yaw: float) -> object:
    move = Transform(translation=Vector3(x=x, y=y, z=0.3), rotation=rotation(yaw))
    return TransformStamped(header(stamp_ns, "vicon_world"), "r1", move)


def write_bag(
    path: Path,
    topic: str,
    msgtype: str,
    messages: list[tuple[int, object]],
    storage: StoragePlugin = StoragePlugin.MCAP,
) -> Path:
    """A rosbag2 folder holding ``messages`` (log time ns, message) on one topic."""
    with Writer(path, version=9, storage_plugin=storage) as writer:
        connection = writer.add_connection(topic, msgtype, typestore=TYPES)
        for log_ns, message in messages:
            writer.write(connection, log_ns, TYPES.serialize_cdr(message, msgtype))
    return path


@pytest.mark.parametrize("storage", [StoragePlugin.MCAP, StoragePlugin.SQLITE3])
@pytest.mark.parametrize(
    ("msgtype", "build", "frame"),
    [
        ("geometry_msgs/msg/PoseStamped", pose_stamped, "map"),
        ("geometry_msgs/msg/TransformStamped", transform_stamped, "vicon_world"),
    ],
)
def test_a_written_pose_track_reads_back_exactly(tmp_path: Path, storage, msgtype, build, frame):
    messages = [(t + 2_000_000, build(t, x, y, yaw)) for t, x, y, yaw in POSES]  # 2 ms late
    bag = write_bag(tmp_path / "bag", "/r1/pose", msgtype, messages, storage)
    track = read_pose_track(bag)  # the only pose topic
    assert track.stamps == "header"
    assert track.t_ns.tolist() == [p[0] for p in POSES]
    assert track.x_m.tolist() == [p[1] for p in POSES]
    assert track.y_m.tolist() == [p[2] for p in POSES]
    assert np.allclose(track.yaw_rad, [p[3] for p in POSES], rtol=0, atol=1e-12)
    assert track.frame_id == frame
    assert track.source == f"{bag} /r1/pose"


def test_a_bag_whose_header_stamps_are_all_zero_is_timed_by_its_log_times(tmp_path: Path):
    logged = [EPOCH_NS + k * 10_000_000 for k in range(len(POSES))]
    messages = [
        (log_ns, pose_stamped(0, x, y, yaw))
        for log_ns, (_, x, y, yaw) in zip(logged, POSES, strict=True)
    ]
    track = read_pose_track(write_bag(tmp_path / "bag", "/pose", PoseStamped.__msgtype__, messages))
    assert track.stamps == "log"
    assert track.t_ns.tolist() == logged
    assert track.x_m.tolist() == [p[1] for p in POSES]


def test_poses_logged_out_of_stamp_order_are_sorted_and_a_repeated_stamp_kept_once(
    tmp_path: Path,
):
    a, b, c = EPOCH_NS, EPOCH_NS + 5_000_000, EPOCH_NS + 9_000_000
    messages = [
        (EPOCH_NS + 10, pose_stamped(b, 2.0, 0.0, 0.0)),
        (EPOCH_NS + 20, pose_stamped(a, 1.0, 0.0, 0.0)),
        (EPOCH_NS + 30, pose_stamped(b, 2.5, 0.0, 0.0)),  # same stamp, logged later: dropped
        (EPOCH_NS + 40, pose_stamped(c, 3.0, 0.0, 0.0)),
    ]
    track = read_pose_track(write_bag(tmp_path / "bag", "/pose", PoseStamped.__msgtype__, messages))
    assert track.t_ns.tolist() == [a, b, c]
    assert track.x_m.tolist() == [1.0, 2.0, 3.0]


def test_a_pose_topic_without_messages_is_refused(tmp_path: Path):
    bag = write_bag(tmp_path / "bag", "/pose", PoseStamped.__msgtype__, [])
    with pytest.raises(BagError, match=r"topic /pose has no messages"):
        read_pose_track(bag, "/pose")


def write_csv(tmp_path: Path, text: str, name: str = "track.csv") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_a_csv_track_reads_with_its_columns_in_any_order(tmp_path: Path):
    path = write_csv(tmp_path, "t_s, yaw_rad ,x_m,y_m\n0.5,0.1,1.0,2.0\n\n0.75,-3.0,1.5,-2.25\n")
    track = read_pose_track(path)
    assert track.t_ns.tolist() == [500_000_000, 750_000_000]
    assert track.x_m.tolist() == [1.0, 1.5] and track.y_m.tolist() == [2.0, -2.25]
    assert track.yaw_rad.tolist() == [0.1, -3.0]
    assert track.stamps == "csv" and track.frame_id == "" and track.source == str(path)


def test_a_csv_yaw_outside_minus_pi_to_pi_is_wrapped(tmp_path: Path):
    track = read_pose_track(write_csv(tmp_path, "t_s,x_m,y_m,yaw_rad\n0,0,0,4.0\n1,0,0,-7.0\n"))
    assert track.yaw_rad.tolist() == pytest.approx([4.0 - 2 * math.pi, -7.0 + 2 * math.pi])


def test_a_csv_track_takes_no_topic(tmp_path: Path):
    with pytest.raises(TrackError, match=r"track\.csv: a CSV holds one track"):
        read_pose_track(write_csv(tmp_path, "t_s,x_m,y_m,yaw_rad\n0,0,0,0\n"), "/pose")


HEAD = "t_s,x_m,y_m,yaw_rad\n"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("t_s,x_m,y_m\n0,1,2\n", r"row 1: missing column 'yaw_rad'"),
        ("t_s,x_m,y_m,yaw_rad,z_m\n0,1,2,3,4\n", r"row 1: unknown column 'z_m'"),
        ("t_s,x_m,x_m,y_m\n0,1,1,2\n", r"row 1: missing column 'yaw_rad'"),
        ("t_s,x_m,y_m,yaw_rad,t_s\n0,1,2,3,0\n", r"row 1: a repeated column"),
        (HEAD + "0,1,2,0\n1,1,two,0\n", r"row 3: y_m = 'two': expected a finite number"),
        (HEAD + "0,1,2,nan\n", r"row 2: yaw_rad = 'nan': expected a finite number"),
        (HEAD + "0,inf,2,0\n", r"row 2: x_m = 'inf': expected a finite number"),
        (HEAD + "0,,2,0\n", r"row 2: x_m = '': expected a finite number"),
        (HEAD + "1,1,2,0\n1,1,2,0\n", r"row 3: t_s = 1.0: expected a time after 1.0"),
        (HEAD + "1,1,2,0\n\n0.5,1,2,0\n", r"row 4: t_s = 0.5: expected a time after 1.0"),
        (HEAD + "0,1,2\n", r"row 2: 3 values; expected 4"),
        (HEAD + "0,1,2,0,9\n", r"row 2: 5 values; expected 4"),
        (HEAD + "2e9,1,2,0\n", r"row 2: t_s = 2000000000.0: expected \|t_s\| <= 1e9 s"),
    ],
)
def test_a_bad_csv_row_is_a_track_error_naming_file_and_row(tmp_path: Path, text, message):
    with pytest.raises(TrackError, match=message) as error:
        read_pose_track(write_csv(tmp_path, text))
    assert str(error.value).startswith(f"{tmp_path / 'track.csv'}: row ")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", r"empty; expected a header t_s,x_m,y_m,yaw_rad"),
        (HEAD, r"no rows; expected at least one pose under the header"),
        (HEAD + "\n , ,,\n", r"no rows; expected at least one pose under the header"),
    ],
)
def test_a_csv_without_poses_is_a_track_error_naming_the_file(tmp_path: Path, text, message):
    with pytest.raises(TrackError, match=message) as error:
        read_pose_track(write_csv(tmp_path, text))
    assert str(error.value).startswith(f"{tmp_path / 'track.csv'}: ")


def test_times_closer_than_a_nanosecond_are_a_track_error(tmp_path: Path):
    with pytest.raises(TrackError, match=r"closer than 1 ns"):
        read_pose_track(write_csv(tmp_path, HEAD + "1.0,0,0,0\n1.0000000000000002,0,0,0\n"))


def test_a_csv_that_is_not_utf8_is_a_track_error(tmp_path: Path):
    path = tmp_path / "latin.csv"
    path.write_bytes(HEAD.encode() + b"0,1,2,\xff\n")
    with pytest.raises(TrackError, match=r"latin\.csv: cannot read"):
        read_pose_track(path)


NUMBER = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.floats(-1e10, 1e10).map(str),
    st.integers(-3, 3).map(str),
    st.decimals(-(10**10), 10**10, places=9).map(str),
)
CELL = NUMBER | st.text(
    alphabet=st.sampled_from(list("0123456789.-+eEinfa_ x\",;\t\r'")), max_size=8
)
ROW = st.lists(CELL, min_size=0, max_size=6).map(",".join)
POSE_ROW = st.lists(NUMBER, min_size=4, max_size=4).map(",".join)
# rows that mostly make a track: increasing times, then numbers with an odd bad cell
TIMED_ROWS = st.lists(
    st.tuples(
        st.floats(0, 1e3), st.lists(NUMBER | st.floats(-1e3, 1e3).map(str), min_size=3, max_size=3)
    ),
    max_size=8,
).map(
    lambda rows: [
        ",".join([repr(t), *cells])
        for t, (_, cells) in zip(sorted(r[0] for r in rows), rows, strict=True)
    ]
)
HEADER = st.sampled_from(
    [
        "t_s,x_m,y_m,yaw_rad",
        "yaw_rad,y_m,x_m,t_s",
        " t_s , x_m , y_m , yaw_rad ",
        "\ufefft_s,x_m,y_m,yaw_rad",
        "t_s,x_m,y_m",
        "t_s,x_m,y_m,yaw_rad,t_s",
        "",
    ]
)
CSV_LIKE = st.builds(
    lambda head, rows, end: "\n".join([head, *rows]) + end,
    HEADER,
    st.lists(ROW, max_size=8) | st.lists(POSE_ROW, max_size=8) | TIMED_ROWS,
    st.sampled_from(["", "\n", "\r\n"]),
)


@pytest.mark.slow
@settings(
    max_examples=400, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(text=st.one_of(st.text(), CSV_LIKE))
def test_any_text_reads_as_a_valid_track_or_fails_with_a_track_error(tmp_path: Path, text: str):
    path = write_csv(tmp_path, text, "fuzz.csv")
    try:
        track = read_pose_track(path)
    except TrackError as error:
        assert str(error).startswith(str(path))
        return
    assert len(track) >= 1
    assert track.t_ns.dtype == np.int64 and np.all(np.diff(track.t_ns) > 0)
    for values in (track.x_m, track.y_m, track.yaw_rad):
        assert len(values) == len(track) and np.isfinite(values).all()
    assert np.all((track.yaw_rad >= -math.pi) & (track.yaw_rad < math.pi))
