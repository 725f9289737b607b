from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from adapters.bags.tracks import TrackError, read_csv_track, read_pose_track, yaw_of
from cosim.core.errors import BagError
from tests.conftest import SHARED_DATA

NAV2 = SHARED_DATA / "nav2_turtlebot.mcap"
needs_nav2 = pytest.mark.skipif(not NAV2.exists(), reason=f"{NAV2} absent (shared data folder)")


def mcap_reference(topic: str) -> tuple[list[int], list[tuple[float, float, float]]]:
    """What the independent mcap reader decodes: header stamps and planar poses."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    stamps, poses = [], []
    with NAV2.open("rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _schema, _channel, _message, msg in reader.iter_decoded_messages(topics=[topic]):
            stamps.append(msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec)
            p, q = msg.pose.pose.position, msg.pose.pose.orientation
            poses.append((p.x, p.y, yaw_of(q.x, q.y, q.z, q.w)))
    return stamps, poses


@needs_nav2
@pytest.mark.parametrize(("topic", "count"), [("/amcl_pose", 135), ("/odom", 2639)])
def test_a_rosbag2_track_reads_as_the_mcap_reader_decodes_it(topic, count):
    track = read_pose_track(NAV2, topic)
    stamps, poses = mcap_reference(topic)
    assert len(stamps) == count
    order = np.argsort(stamps, kind="stable")
    ref_t = np.asarray(stamps)[order]
    keep = np.concatenate([[True], np.diff(ref_t) > 0])
    ref = np.asarray(poses)[order][keep]
    assert track.stamps == "header"
    assert track.t_ns.tolist() == ref_t[keep].tolist()
    assert np.array_equal(track.x_m, ref[:, 0]) and np.array_equal(track.y_m, ref[:, 1])
    assert np.allclose(track.yaw_rad, ref[:, 2], atol=1e-12)


@needs_nav2
def test_a_bag_with_two_pose_topics_asks_which_one():
    with pytest.raises(BagError, match=r"found 2: /amcl_pose .*, /odom"):
        read_pose_track(NAV2)


@needs_nav2
def test_a_topic_of_another_type_is_refused_naming_its_type():
    with pytest.raises(BagError, match="/tf is tf2_msgs/msg/TFMessage"):
        read_pose_track(NAV2, "/tf")


def test_a_file_that_is_not_a_bag_is_refused(tmp_path: Path):
    fake = tmp_path / "x.mcap"
    fake.write_text("not a bag")
    with pytest.raises(BagError, match=r"x\.mcap"):
        read_pose_track(fake, "/pose")


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "track.csv"
    path.write_text(text)
    return path


def test_a_csv_track_reads_with_times_in_ns(tmp_path: Path):
    track = read_csv_track(write(tmp_path, "t_s,x_m,y_m,yaw_rad\n0.5,1,2,0.1\n0.6,1.1,2,0.2\n"))
    assert track.t_ns.tolist() == [500_000_000, 600_000_000]
    assert track.x_m.tolist() == [1.0, 1.1] and track.stamps == "csv"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "empty"),
        ("t_s,x_m,y_m,yaw_rad\n", "no rows"),
        ("t_s,x_m,y_m\n0,1,2\n", "row 1: missing column 'yaw_rad'"),
        ("t_s,x_m,y_m,yaw_rad,z\n0,1,2,3,4\n", "row 1: unknown column 'z'"),
        ("t_s,x_m,y_m,yaw_rad\n0,1,two,3\n", "row 2: y_m = 'two': expected a finite number"),
        ("t_s,x_m,y_m,yaw_rad\n0,1,2,nan\n", "row 2: yaw_rad = 'nan'"),
        ("t_s,x_m,y_m,yaw_rad\n1,1,2,0\n1,1,2,0\n", "row 3: t_s = 1.0: expected a time after"),
        ("t_s,x_m,y_m,yaw_rad\n1,1,2\n", "row 2: 3 values; expected 4"),
    ],
)
def test_a_bad_csv_track_names_file_row_column_and_value(tmp_path: Path, text, message):
    with pytest.raises(TrackError, match=message) as error:
        read_csv_track(write(tmp_path, text))
    assert "track.csv" in str(error.value)


CELLS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-5, 5).map(str),
    st.text(alphabet='0123456789.-eanx," ', max_size=6),
)


@settings(max_examples=200, deadline=None)
@given(
    st.sampled_from(["t_s,x_m,y_m,yaw_rad", "t_s,x_m,y_m", "x_m,t_s,yaw_rad,y_m", ""]),
    st.lists(st.lists(CELLS, min_size=0, max_size=5), max_size=6),
)
def test_any_csv_reads_as_a_valid_track_or_fails_with_a_track_error(tmp_path_factory, head, rows):
    text = head + "\n" + "\n".join(",".join(row) for row in rows)
    path = tmp_path_factory.mktemp("fuzz") / "t.csv"
    path.write_text(text)
    try:
        track = read_csv_track(path)
    except TrackError:
        return
    assert len(track) >= 1 and np.all(np.diff(track.t_ns) > 0)
    assert np.isfinite(track.x_m).all() and np.isfinite(track.yaw_rad).all()


def test_a_csv_with_a_byte_order_mark_reads_and_a_giant_cell_is_a_track_error(tmp_path: Path):
    path = tmp_path / "bom.csv"
    path.write_bytes("\ufefft_s,x_m,y_m,yaw_rad\n0,1,2,0\n".encode())
    assert len(read_csv_track(path)) == 1
    with pytest.raises(TrackError, match="not a CSV"):
        read_csv_track(write(tmp_path, "t_s,x_m,y_m,yaw_rad\n" + '"' + "1" * 200_000 + '"\n'))
