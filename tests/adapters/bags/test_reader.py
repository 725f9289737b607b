"""Reading bags: ours, rosbag2's own, and anything else handed over as a bag."""

import shutil
import subprocess
import sys

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from adapters.bags.reader import bag_info, format_info, read_messages
from cosim.core.errors import BagError
from tests.bags import mcap_file
from tests.conftest import SHARED_DATA


def test_bag_info_of_our_bag_lists_topics_types_counts_and_duration(task_run):
    info = bag_info(task_run.bag)
    topics = {t.name: t for t in info.topics}
    assert info.storage == "mcap"
    assert topics["/robot_1/scan"].msgtype == "sensor_msgs/msg/LaserScan"
    assert topics["/robot_1/scan"].count == 60
    assert info.messages == sum(task_run.recorded.values())
    assert info.start_ns == 0
    assert info.duration_s == pytest.approx(5.95)
    text = format_info(info)
    assert "/fleet/tasks" in text and "cosim_msgs/msg/TaskSet" in text


def test_bag_info_reads_a_bag_rosbag2_wrote_as_a_bare_mcap_file(nav2_bag):
    info = bag_info(nav2_bag)
    counts = {t.name: t.count for t in info.topics}
    assert counts == {"/odom": 2639, "/tf": 5422, "/tf_static": 1, "/amcl_pose": 135}
    assert info.duration_s == pytest.approx(97.36, abs=0.01)


def test_messages_of_our_bag_and_of_rosbag2s_decode_through_one_reader(task_run, nav2_bag):
    ours = list(read_messages(task_run.bag, ["/robot_1/odom"]))
    theirs = list(read_messages(nav2_bag, ["/amcl_pose"]))
    assert len(ours) == 120 and len(theirs) == 135
    assert ours[0].message.header.frame_id == "robot_1/odom"
    assert theirs[0].msgtype == "geometry_msgs/msg/PoseWithCovarianceStamped"
    assert [m.t_ns for m in theirs] == sorted(m.t_ns for m in theirs)


def test_the_aces_recording_reads_as_a_rosbag2_folder():
    folder = SHARED_DATA / "aces_lidar"
    if not folder.is_dir():
        pytest.skip(f"{folder} (the shared sample data) is not beside this clone")
    counts = {t.name: t.count for t in bag_info(folder).topics}
    assert counts == {"/scan": 440, "/ground_truth": 440, "/odom": 440}


def test_asking_for_a_topic_the_bag_lacks_names_the_topics_it_has(task_run):
    with pytest.raises(BagError, match=r"no topic /scan; the bag has /clock"):
        list(read_messages(task_run.bag, ["/scan"]))


@pytest.mark.parametrize(
    ("make", "expected"),
    [
        (lambda p: p / "missing", "no such file or folder"),
        (lambda p: p, "not a ROS 2 bag"),
        (lambda p: _write(p / "notes.txt", b"hello"), "expected a .mcap or .db3 file"),
        (lambda p: _write(p / "x.mcap", b""), "damaged"),
        (lambda p: _write(p / "x.mcap", b"\x89MCAP0\r\n" + b"\x00" * 64), "damaged"),
        (lambda p: _write(p / "x.db3", b"not sqlite at all, just text" * 10), "damaged"),
        (lambda p: _write(p / "m" / "metadata.yaml", b"[unclosed"), "damaged"),
        (lambda p: _write(p / "m" / "metadata.yaml", b"a: 1\n"), "damaged"),
    ],
)
def test_what_is_not_a_readable_bag_is_one_line_naming_it(tmp_path, make, expected):
    path = make(tmp_path)
    with pytest.raises(BagError) as raised:
        bag_info(path)
    message = str(raised.value)
    assert expected in message and str(path) in message and "\n" not in message


def _write(path, data: bytes):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(data)
    return path if path.name != "metadata.yaml" else path.parent


def test_a_bag_cut_short_is_damaged_not_a_crash(task_run, tmp_path):
    data = mcap_file(task_run.bag).read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    with pytest.raises(BagError, match="damaged"):
        bag_info(cut)


def test_a_bag_folder_without_metadata_says_it_is_unfinished(task_run, tmp_path):
    folder = tmp_path / "bag"
    folder.mkdir()
    shutil.copy(mcap_file(task_run.bag), folder / "bag.mcap")
    with pytest.raises(BagError, match="unfinished bag"):
        bag_info(folder)


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    data=st.binary(max_size=600),
    name=st.sampled_from(["x.mcap", "x.db3", "metadata.yaml"]),
    prefix=st.sampled_from(
        [b"", b"\x89MCAP0\r\n", b"SQLite format 3\x00", b"rosbag2_bagfile_information:\n"]
    ),
)
def test_any_bytes_given_as_a_bag_raise_a_bag_error_and_nothing_else(tmp_path, data, name, prefix):
    folder = tmp_path / "fuzz"
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir()
    (folder / name).write_bytes(prefix + data)
    target = folder if name == "metadata.yaml" else folder / name
    try:
        bag_info(target)
    except BagError as error:
        assert "\n" not in str(error)


@pytest.mark.slow
def test_cosim_bag_info_prints_the_table_or_one_line_and_exit_2(task_run, tmp_path):
    ok = subprocess.run(
        [sys.executable, "-m", "cosim", "bag", "info", str(task_run.bag)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert ok.returncode == 0, ok.stderr
    assert "/robot_1/scan" in ok.stdout and "sensor_msgs/msg/LaserScan" in ok.stdout
    bad = subprocess.run(
        [sys.executable, "-m", "cosim", "bag", "info", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert bad.returncode == 2
    assert bad.stderr.strip().count("\n") == 0 and "not a ROS 2 bag" in bad.stderr


@pytest.mark.slow
@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    flips=st.lists(st.tuples(st.floats(0, 1), st.integers(0, 255)), min_size=1, max_size=12),
    keep=st.one_of(st.none(), st.floats(0, 1)),
)
def test_a_corrupted_bag_of_ours_reads_or_raises_a_bag_error(task_run, tmp_path, flips, keep):
    data = bytearray(mcap_file(task_run.bag).read_bytes())
    for where, value in flips:
        data[int(where * (len(data) - 1))] = value
    if keep is not None:
        data = data[: int(keep * len(data))]
    target = tmp_path / "corrupt.mcap"
    target.write_bytes(bytes(data))
    try:
        bag_info(target)
        for _ in read_messages(target):
            pass
    except BagError as error:
        assert str(target) in str(error) and "\n" not in str(error)
