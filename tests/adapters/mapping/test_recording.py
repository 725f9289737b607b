import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from adapters.mapping.recording import (
    MAX_POSITION_M,
    ODOM_TYPES,
    REFERENCE_TYPES,
    SCAN_TYPES,
    check_topics,
    read_recording,
)
from cosim.core.errors import BagError
from tests.adapters.mapping.recordings import T0_NS, Drive, Odom, Scan, drive, room_ranges, write

HALF_S = 500_000_000


def test_every_scan_comes_with_the_odometry_at_its_stamp(tmp_path: Path):
    recorded = drive(n=6)
    bag = write(tmp_path / "bag", recorded)
    recording = read_recording(bag)
    assert recording.bag == bag
    assert recording.stamps_ns.tolist() == [T0_NS + k * HALF_S for k in range(6)]
    expected = [(o.x, o.y, o.yaw) for o in recorded.odom]
    assert np.allclose(recording.odometry, expected, atol=1e-12)
    assert recording.reference is None and recording.skipped == 0


def test_the_lidar_geometry_is_the_first_scans(tmp_path: Path):
    recording = read_recording(write(tmp_path / "bag", drive(n=3)))
    assert recording.ranges_m.shape == (3, 91) and recording.ranges_m.dtype == np.float32
    assert recording.angles_rad[0] == pytest.approx(-math.pi / 2)
    assert np.allclose(np.diff(recording.angles_rad), math.pi / 90)
    assert (recording.range_min_m, recording.range_max_m) == (pytest.approx(0.1), 20.0)
    assert np.allclose(recording.ranges_m[0], room_ranges((-1.5, 0.5, 0.0)), atol=1e-5)


def test_odometry_between_two_messages_is_interpolated_and_the_yaw_across_pi_too(
    tmp_path: Path,
):
    odom = [Odom(T0_NS, 0.0, 0.0, 3.0), Odom(T0_NS + 2 * HALF_S, 1.0, -2.0, -3.0)]
    scans = [Scan(T0_NS + HALF_S // 2, room_ranges((0.0, 0.0, 0.0)))]
    scans.append(Scan(T0_NS + HALF_S, room_ranges((0.0, 0.0, 0.0))))
    recording = read_recording(write(tmp_path / "bag", Drive(scans, odom)))
    quarter, half = recording.odometry
    assert quarter[:2].tolist() == pytest.approx([0.25, -0.5])
    assert half[:2].tolist() == pytest.approx([0.5, -1.0])
    # 3 rad to -3 rad is 0.28 rad through pi, not 6 rad back through 0
    assert quarter[2] == pytest.approx(3.0 + 0.25 * (2 * math.pi - 6.0))
    assert abs(half[2]) == pytest.approx(math.pi)


def test_scans_outside_the_odometrys_time_span_are_left_out_and_counted(tmp_path: Path):
    recorded = drive(n=8)
    recorded.odom = recorded.odom[2:6]
    recording = read_recording(write(tmp_path / "bag", recorded))
    assert recording.skipped == 4
    assert recording.stamps_ns.tolist() == [T0_NS + k * HALF_S for k in range(2, 6)]
    assert len(recording.ranges_m) == len(recording.odometry) == 4


def test_the_reference_is_read_at_each_scan_and_nan_outside_its_span(tmp_path: Path):
    recorded = drive(n=6)
    assert recorded.reference is not None
    recorded.reference = [replace(o, x=o.x + 10.0) for o in recorded.reference[:4]]
    recording = read_recording(write(tmp_path / "bag", recorded), reference_topic="/ground_truth")
    assert recording.reference is not None
    assert recording.reference[:4, 0].tolist() == pytest.approx(
        [o.x + 10.0 for o in recorded.odom[:4]]
    )
    assert np.isnan(recording.reference[4:]).all()


def test_ranges_stay_as_recorded_rep_117(tmp_path: Path):
    recorded = drive(n=3)
    odd = [math.nan, math.inf, -math.inf, 0.05, *room_ranges((-1.2, 0.5, 0.05))[4:]]
    recorded.scans[1] = replace(recorded.scans[1], ranges=odd)
    ranges = read_recording(write(tmp_path / "bag", recorded)).ranges_m[1]
    assert math.isnan(ranges[0]) and ranges[1] == math.inf and ranges[2] == -math.inf
    assert ranges[3] == pytest.approx(0.05)


def test_a_header_stamp_of_zero_means_the_log_time(tmp_path: Path):
    recorded = drive(n=3)
    recorded.scans = [replace(s, stamp_ns=0, log_ns=s.stamp_ns) for s in recorded.scans]
    recording = read_recording(write(tmp_path / "bag", recorded))
    assert recording.stamps_ns.tolist() == [T0_NS, T0_NS + HALF_S, T0_NS + 2 * HALF_S]


def test_scans_and_odometry_that_never_overlap_are_refused(tmp_path: Path):
    recorded = drive(n=6)
    recorded.odom = [replace(o, stamp_ns=o.stamp_ns + 10 * HALF_S) for o in recorded.odom]
    bag = write(tmp_path / "bag", recorded)
    with pytest.raises(BagError) as refused:
        read_recording(bag)
    assert str(refused.value) == (
        f"{bag}: no scan on /scan falls within the odometry on /odom (their stamps do not overlap)"
    )


def test_the_topics_are_checked_present_and_typed_and_listed_once(tmp_path: Path):
    bag = write(tmp_path / "bag", drive(n=2))
    assert check_topics(bag, "/scan", "/odom", None) == ["/odom", "/scan"]
    assert check_topics(bag, "/scan", "/odom", "/odom") == ["/odom", "/scan"]
    with pytest.raises(BagError) as missing:
        check_topics(bag, "/lidar", "/odom", None)
    assert str(missing.value) == (
        f"{bag}: --scan /lidar: no such topic; expected one of sensor_msgs/msg/LaserScan (the "
        "bag has /ground_truth (nav_msgs/msg/Odometry), /odom (nav_msgs/msg/Odometry), /scan "
        "(sensor_msgs/msg/LaserScan))"
    )
    with pytest.raises(BagError, match=r"--odom /scan is sensor_msgs/msg/LaserScan; expected nav"):
        check_topics(bag, "/scan", "/scan", None)
    with pytest.raises(BagError, match=r"--reference /scan is sensor_msgs/msg/LaserScan; expec"):
        check_topics(bag, "/scan", "/odom", "/scan")


def test_a_topic_without_messages_is_refused(tmp_path: Path):
    recorded = drive(n=2)
    recorded.extra = {"/quiet": []}
    bag = write(tmp_path / "bag", recorded)
    with pytest.raises(BagError, match=r"--reference /quiet has no messages$"):
        check_topics(bag, "/scan", "/odom", "/quiet")


def test_what_is_accepted_on_each_topic():
    assert SCAN_TYPES == ("sensor_msgs/msg/LaserScan",)
    assert ODOM_TYPES == ("nav_msgs/msg/Odometry",)
    assert set(ODOM_TYPES) < set(REFERENCE_TYPES)
    assert MAX_POSITION_M == 1e8


def test_odometry_farther_than_any_frame_on_earth_is_refused_naming_the_message(tmp_path: Path):
    recorded = drive(n=3)
    recorded.odom[1] = replace(recorded.odom[1], y=-2e8)
    bag = write(tmp_path / "bag", recorded)
    with pytest.raises(BagError) as refused:
        read_recording(bag)
    assert str(refused.value).startswith(
        f"{bag}: --odom /odom message 1 (1.500000000 s): position (-1.2, -2e+08) m; expected "
        "x and y within 1e+08 m of the frame's origin"
    )
