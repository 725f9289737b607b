"""`cosim map BAG`: the robots' mapping on recordings, ours and a real building's."""

import json
import math
import tempfile
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import cosim
from adapters.mapping.bagmap import RESOLUTION_M
from adapters.world.files import read_map
from cosim.cli.bagmap import map_bag
from cosim.core.errors import BagError, ExportError
from tests.adapters.mapping.recordings import Drive, Odom, Scan, drive, write
from tests.conftest import SHARED_DATA, SMALL, cosim_main

ACES = SHARED_DATA / "aces_lidar"


_cli = cosim_main


@pytest.fixture(scope="module")
def drifting_bag(tmp_path_factory):
    """A bag of ours: 3 robots with drifting odometry, ground truth recorded."""
    overrides = {
        **SMALL,
        "robots.driver": "navigation",
        "lidar.beams": 180,
        "odometry.drift": 0.03,
        "scenario.duration_s": 40.0,
        "record.topics": ["/robot_1/*", "/clock", "/tf*"],
    }
    out = tmp_path_factory.mktemp("runs") / "recorded"
    cosim.run(cosim.load_scenario("warehouse-random", overrides=overrides), out=out)
    return out / "bag"


@pytest.mark.slow
def test_mapping_a_bag_of_ours_corrects_its_drifting_odometry(drifting_bag, tmp_path):
    result = map_bag(
        drifting_bag,
        tmp_path / "map",
        scan_topic="/robot_1/scan",
        odom_topic="/robot_1/odom",
        reference_topic="/robot_1/ground_truth",
        loop_closure=False,
    )
    s = result.summary
    assert s["ate_odom_m"] > 0.1 and s["ate_m"] <= s["ate_odom_m"] / 3
    assert s["scans"] == 400 and s["map_updates"] > 10
    written = {p.name for p in result.files}
    assert written == {
        "map.yaml", "map.pgm", "map.png", "trajectory.parquet", "trajectory.csv", "summary.json",
    }  # fmt: skip
    table = pd.read_parquet(tmp_path / "map" / "trajectory.parquet")
    assert list(table.columns) == ["t_s", "x_m", "y_m", "yaw_rad"]
    assert table.t_s.is_monotonic_increasing and table.t_s.iloc[0] == 0.0
    csv = pd.read_csv(tmp_path / "map" / "trajectory.csv")
    assert np.allclose(csv.to_numpy(), table.to_numpy())
    assert (read_map(tmp_path / "map" / "map.yaml").data == 100).any()


@pytest.mark.slow
def test_the_aces_building_maps_within_five_percent_of_the_odometrys_error(tmp_path):
    if not ACES.is_dir():
        pytest.skip(f"{ACES} (the shared sample data) is not beside this clone")
    done = _cli("map", str(ACES), "--out", str(tmp_path), "--reference", "/ground_truth", "--quiet")
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["ate_odom_m"] == pytest.approx(3.32, abs=0.01)  # as the data's README says
    assert summary["ate_m"] <= 0.05 * summary["ate_odom_m"]
    assert summary["loop_closures"] + summary["loop_closures_not_needed"] > 0
    assert "trajectory error" in done.stdout and "revisits already in place" in done.stdout


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--scan", "/nothing"], "--scan /nothing: no such topic"),
        (["--scan", "/robot_1/odom"], "--scan /robot_1/odom is nav_msgs/msg/Odometry; expected"),
        (["--odom", "/robot_1/scan"], "--odom /robot_1/scan is sensor_msgs/msg/LaserScan"),
        (["--reference", "/clock"], "--reference /clock is rosgraph_msgs/msg/Clock"),
    ],
)
def test_topics_missing_or_of_the_wrong_type_are_one_line_and_exit_2(
    drifting_bag, tmp_path, args, fragment
):
    base = ["--scan", "/robot_1/scan", "--odom", "/robot_1/odom"]
    done = _cli("map", str(drifting_bag), "--out", str(tmp_path / "m"), *base, *args)
    assert done.returncode == 2, done.stdout
    assert fragment in done.stderr and done.stderr.count("\n") == 1
    assert not (tmp_path / "m").exists()


def test_a_bag_without_scans_says_so(tmp_path):
    nav2 = SHARED_DATA / "nav2_turtlebot.mcap"
    if not nav2.is_file():
        pytest.skip(f"{nav2} (the shared sample data) is not beside this clone")
    with pytest.raises(BagError, match=r"--scan /scan: no such topic.*/amcl_pose"):
        map_bag(nav2, tmp_path / "m")


def test_a_folder_that_is_not_a_bag_or_a_full_output_folder_is_refused(drifting_bag, tmp_path):
    with pytest.raises(BagError, match="not a ROS 2 bag"):
        map_bag(tmp_path, tmp_path / "m")
    out = tmp_path / "full"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    with pytest.raises(ExportError, match="not empty"):
        map_bag(drifting_bag, out, scan_topic="/robot_1/scan", odom_topic="/robot_1/odom")


def test_a_sqlite3_bag_maps_through_the_same_path(tmp_path):
    overrides = {
        **SMALL,
        "robots.driver": "navigation",
        "lidar.beams": 180,
        "scenario.duration_s": 10.0,
        "record.bag": "sqlite3",
        "record.topics": ["/robot_2/scan", "/robot_2/odom"],
    }
    cosim.run(cosim.load_scenario("warehouse-random", overrides=overrides), out=tmp_path / "run")
    result = map_bag(
        tmp_path / "run" / "bag", tmp_path / "map", scan_topic="/robot_2/scan",
        odom_topic="/robot_2/odom",
    )  # fmt: skip
    assert result.summary["scans"] == 100 and result.summary["map_updates"] >= 1


# Issue 34: whatever a recording holds and whatever the flags say, `cosim map` maps it (exit
# 0) or says in one line what is wrong, naming the bag, topic, message or flag (exit 2).


def _odom(k: int, **fields) -> Callable[[Drive], None]:
    def edit(d: Drive) -> None:
        d.odom[k] = replace(d.odom[k], **fields)

    return edit


def _every(kind: str, **fields) -> Callable[[Drive], None]:
    def edit(d: Drive) -> None:
        setattr(d, kind, [replace(m, **fields) for m in getattr(d, kind)])

    return edit


def _scan(k: int, **fields) -> Callable[[Drive], None]:
    def edit(d: Drive) -> None:
        d.scans[k] = replace(d.scans[k], **fields)

    return edit


def _far_odometry(d: Drive) -> None:
    d.odom = [replace(o, x=o.x + 1e9) for o in d.odom]


def _stamped_back(kind: str, k: int) -> Callable[[Drive], None]:
    def edit(d: Drive) -> None:
        messages = getattr(d, kind)
        # recorded in its place, stamped just after an earlier one (a clock that jumped back)
        messages[k] = replace(
            messages[k], stamp_ns=messages[1].stamp_ns + 7, log_ns=messages[k].stamp_ns
        )

    return edit


NAN, INF = math.nan, math.inf
BAD_RECORDINGS = [
    pytest.param(
        _odom(3, x=NAN),
        "--odom /odom message 3 (2.500000000 s): position (nan, 0.5) m, orientation (0, 0, "
        "0.0749297, 0.997189); expected finite numbers",
        id="one odometry pose NaN",
    ),
    pytest.param(
        _every("odom", x=NAN, y=NAN),
        "--odom /odom message 0 (1.000000000 s): position (nan, nan) m",
        id="every odometry pose NaN",
    ),
    pytest.param(
        _odom(3, y=-INF), "message 3 (2.500000000 s): position (-0.6, -inf) m", id="odometry inf"
    ),
    pytest.param(
        _odom(2, quaternion=(0.0, 0.0, NAN, NAN)),
        "message 2 (2.000000000 s): position (-0.9, 0.5) m, orientation (0, 0, nan, nan); "
        "expected finite numbers",
        id="odometry orientation NaN",
    ),
    pytest.param(
        _odom(0, quaternion=(0.0, 0.0, 0.0, 0.0)),
        "message 0 (1.000000000 s): orientation (0, 0, 0, 0) has |q|^2 = 0; expected a unit "
        "quaternion (within 0.01, as tf2)",
        id="odometry orientation zero",
    ),
    pytest.param(
        _far_odometry,
        "message 0 (1.000000000 s): position (1e+09, 0.5) m; expected x and y within 1e+08 m "
        "of the frame's origin",
        id="odometry at 1e9 m",
    ),
    pytest.param(
        _odom(6, x=5000.0),
        "--odom /odom spans 5001.5 m x 0.0 m at the scans (x -1.5 to 5000.0 m, y 0.5 to 0.5 m; "
        "its largest step, 5000.0 m, between scans 5 and 6): with the lidar's reach (20 m) all "
        "round, a map at --resolution-m 0.05 would be 100,830 x 800 cells; expected at most "
        "25,000,000 cells (100 MB): --resolution-m 0.09 or more fits",
        id="odometry jumping 5 km",
    ),
    pytest.param(
        _odom(6, x=2e5),
        "spans 200001.5 m x 0.0 m at the scans",
        id="odometry jumping 200 km",
    ),
    pytest.param(
        _odom(3, stamp_ns=2_000_000_000),
        "--odom /odom message 3 (2.000000000 s) has the same stamp as message 2 (2.000000000 "
        "s); expected stamps increasing strictly",
        id="odometry stamped twice",
    ),
    pytest.param(
        _stamped_back("odom", 4),
        "--odom /odom message 4 (1.500000007 s) is stamped before message 3 (2.500000000 s)",
        id="odometry stamped backwards",
    ),
    pytest.param(
        _every("scans", ranges=[]),
        "--scan /scan scan 0 has no ranges; expected at least one beam",
        id="scans without beams",
    ),
    pytest.param(
        _every("scans", angle_increment=0.0),
        "--scan /scan scan 0: angle_increment 0 rad over 91 beams; expected a finite, non-zero "
        "angle between beams",
        id="angle_increment 0",
    ),
    pytest.param(
        _scan(3, angle_increment=NAN), "scan 3: angle_increment nan rad", id="angle_increment NaN"
    ),
    pytest.param(
        _every("scans", angle_increment=2.0),
        "scan 0: angle_increment 2 rad over 91 beams spans 180 rad; expected at most one turn",
        id="angle_increment in degrees",
    ),
    pytest.param(
        _every("scans", angle_min=-INF),
        "scan 0: angle_min -inf rad; expected -2 pi to 2 pi",
        id="angle_min inf",
    ),
    pytest.param(
        _every("scans", range_max=0.05),
        "--scan /scan scan 0: range_min 0.1 m, range_max 0.05 m; expected 0 <= range_min < "
        "range_max (m)",
        id="range_max below range_min",
    ),
    pytest.param(
        _every("scans", range_min=2.0, range_max=2.0),
        "range_min 2 m, range_max 2 m",
        id="range_max equal to range_min",
    ),
    pytest.param(
        _scan(5, range_max=NAN), "scan 5: range_min 0.1 m, range_max nan m", id="range_max NaN"
    ),
    pytest.param(_scan(0, range_min=-1.0), "scan 0: range_min -1 m", id="range_min negative"),
    pytest.param(
        _scan(4, ranges=[2.0] * 50),
        "--scan /scan scan 4 has 50 beams; expected 91 like the first (one lidar per topic)",
        id="scans of different sizes",
    ),
    pytest.param(
        _scan(5, range_max=30.0),
        "--scan /scan scan 5: range_max 30; expected 20 like the first (one lidar per topic)",
        id="scans of different lidars",
    ),
    pytest.param(
        _scan(3, stamp_ns=2_000_000_000),
        "--scan /scan scan 3 (2.000000000 s) has the same stamp as scan 2 (2.000000000 s); "
        "expected stamps increasing strictly (one sensor's clock: did it jump back, or do two "
        "publishers share the topic?)",
        id="scan stamped twice",
    ),
    pytest.param(
        _stamped_back("scans", 4),
        "--scan /scan scan 4 (1.500000007 s) is stamped before scan 3 (2.500000000 s)",
        id="scan stamped backwards",
    ),
]


@pytest.mark.parametrize(("edit", "fragment"), BAD_RECORDINGS)
def test_a_bad_recording_is_one_line_naming_bag_topic_message_and_value_and_exit_2(
    tmp_path, edit, fragment
):
    recording = drive()
    edit(recording)
    bag = write(tmp_path / "bag", recording)
    done = _cli("map", str(bag), "--out", str(tmp_path / "m"), "--quiet")
    assert done.returncode == 2, done.stdout
    assert done.stderr.startswith(f"cosim: error: {bag}: ") and done.stderr.count("\n") == 1
    assert fragment in done.stderr
    assert not (tmp_path / "m").exists()


@pytest.mark.parametrize(
    "reference",
    [[NAN, 0.5], [1e300, 0.5]],
    ids=["NaN", "1e300 m"],
)
def test_a_reference_topic_with_a_bad_pose_is_refused_naming_it(tmp_path, reference):
    recording = drive()
    assert recording.reference is not None
    recording.reference[3] = replace(recording.reference[3], x=reference[0], y=reference[1])
    bag = write(tmp_path / "bag", recording)
    done = _cli("map", str(bag), "--out", str(tmp_path / "m"), "--reference", "/ground_truth")
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert f"{bag}: --reference /ground_truth message 3 (2.500000000 s): position (" in done.stderr


def test_nan_inf_and_negative_ranges_and_a_lidar_without_maximum_map_with_exit_0(tmp_path):
    recording = drive()
    odd = [NAN, INF, -INF, -1.0, 0.0, 1e30, 3e38]  # REP 117, and what drivers publish
    recording.scans = [
        replace(s, ranges=[odd[k % len(odd)] if k % 3 == 0 else r for k, r in enumerate(s.ranges)])
        for s in recording.scans
    ]
    for range_max in (20.0, INF):  # pointcloud_to_laserscan publishes inf
        recording.scans = [replace(s, range_max=range_max) for s in recording.scans]
        bag = write(tmp_path / f"bag{range_max}", recording)
        out = tmp_path / f"m{range_max}"
        done = _cli("map", str(bag), "--out", str(out), "--quiet", "--reference", "/ground_truth")
        assert done.returncode == 0, done.stderr
        assert done.stderr == ""
        summary = json.loads((out / "summary.json").read_text())
        assert summary["scans"] == 12 and summary["ate_m"] < 0.05


@pytest.mark.parametrize("refine", ["score", "walls"])
def test_either_refine_maps_a_drive_and_an_unknown_one_is_refused_in_one_line(tmp_path, refine):
    bag = write(tmp_path / "bag", drive())
    out = tmp_path / refine
    done = _cli(
        "map", str(bag), "--out", str(out), "--quiet", "--reference", "/ground_truth",
        "--refine", refine,
    )  # fmt: skip
    assert done.returncode == 0 and done.stderr == "", done.stderr
    assert json.loads((out / "summary.json").read_text())["ate_m"] < 0.05
    refused = _cli("map", str(bag), "--out", str(tmp_path / "x"), "--refine", "icp")
    assert refused.returncode == 2 and refused.stderr.count("\n") == 1
    assert "argument --refine: invalid choice: 'icp'" in refused.stderr


@pytest.mark.parametrize(
    ("flag", "value", "expected"),
    [
        ("--resolution-m", "1e-6", "a map cell size from 0.01 to 1 m"),
        ("--resolution-m", "0", "a map cell size from 0.01 to 1 m"),
        ("--resolution-m", "-0.05", "a map cell size from 0.01 to 1 m"),
        ("--resolution-m", "nan", "a map cell size from 0.01 to 1 m"),
        ("--resolution-m", "inf", "a map cell size from 0.01 to 1 m"),
        ("--resolution-m", "2", "a map cell size from 0.01 to 1 m"),
        ("--resolution-m", "fine", "'fine' is not a number"),
        ("--min-travel-m", "nan", "nan is not a finite number >= 0"),
        ("--min-travel-m", "inf", "inf is not a finite number >= 0"),
        ("--min-travel-m", "-0.5", "-0.5 is not a finite number >= 0"),
        ("--match-margin", "nan", "nan is not a score from 0 to 1"),
        ("--match-margin", "-0.1", "-0.1 is not a score from 0 to 1"),
        ("--match-margin", "1.5", "1.5 is not a score from 0 to 1"),
        ("--match-margin", "inf", "inf is not a score from 0 to 1"),
    ],
)
def test_every_numeric_flag_out_of_its_bounds_is_one_line_naming_it_and_exit_2(
    tmp_path, flag, value, expected
):
    done = _cli("map", str(tmp_path / "bag"), "--out", str(tmp_path / "m"), f"{flag}={value}")
    assert done.returncode == 2
    assert done.stderr.startswith(f"cosim map: error: argument {flag}: ")
    assert expected in done.stderr and done.stderr.count("\n") == 1


def test_the_parser_takes_exactly_the_cell_sizes_the_mapping_takes(tmp_path):
    low, high = RESOLUTION_M
    bag = write(tmp_path / "bag", drive(n=2))
    for value, accepted in ((low, True), (high, True), (low * 0.99, False), (high * 1.01, False)):
        done = _cli(
            "map", str(tmp_path / "none"), "--out", str(tmp_path), f"--resolution-m={value}"
        )
        assert ("--resolution-m" not in done.stderr) == accepted, (value, done.stderr)
    with pytest.raises(ValueError, match=r"resolution_m 0\.001: expected 0\.01 to 1 m"):
        map_bag(bag, tmp_path / "m", resolution_m=0.001)


def test_a_cell_size_too_fine_for_the_recording_names_the_flag_and_one_that_fits(
    tmp_path, monkeypatch
):
    monkeypatch.setattr("adapters.mapping.bagmap.MAX_CELLS", 400_000)  # a smaller memory
    bag = write(tmp_path / "bag", drive())
    done = _cli("map", str(bag), "--out", str(tmp_path / "m"), "--resolution-m", "0.05")
    assert done.returncode == 2 and done.stderr.count("\n") == 1
    assert done.stderr.startswith(
        f"cosim: error: {bag}: --odom /odom spans 3.3 m x 0.0 m at the scans (x -1.5 to 1.8 m, "
        "y 0.5 to 0.5 m; its largest step, 0.3 m, between scans "
    )
    assert done.stderr.endswith(
        "with the lidar's reach (20 m) all round, a map at --resolution-m 0.05 would be 866 x "
        "800 cells; expected at most 400,000 cells (2 MB): --resolution-m 0.066 or more fits\n"
    )
    done = _cli("map", str(bag), "--out", str(tmp_path / "m"), "--resolution-m", "0.066")
    assert done.returncode == 0, done.stderr


def test_a_refused_recording_leaves_earlier_results_in_place_even_with_force(tmp_path):
    out = tmp_path / "m"
    assert _cli("map", str(write(tmp_path / "good", drive())), "--out", str(out)).returncode == 0
    before = (out / "map.pgm").read_bytes()
    bad = drive()
    bad.odom[2] = replace(bad.odom[2], x=NAN)
    done = _cli("map", str(write(tmp_path / "bad", bad)), "--out", str(out), "--force")
    assert done.returncode == 2
    assert (out / "map.pgm").read_bytes() == before and (out / "summary.json").is_file()


PATHOLOGICAL = st.sampled_from([NAN, INF, -INF, 0.0, -1.0, 1e-30, 1e9, 3e38, -3e38])
"""Values a broken driver or a corrupt bag may hold (float32-representable, for LaserScan)."""
CORRUPTIONS = [
    *(("scan", name) for name in ("angle_min", "angle_increment", "range_min", "range_max")),
    *(("odom", name) for name in ("x", "y")),
    ("odom", "quaternion"),
    ("odom", "stamp_ns"),
    ("scan", "stamp_ns"),
    ("scan", "ranges"),
    ("reference", "x"),
]
"""What one corruption of a recording changes: a field of one message."""


@st.composite
def recordings(draw: st.DrawFn) -> Drive:
    """A recording of sane fields but for up to two corruptions (one field of one message each).

    Its ranges may be anything (REP 117: NaN, +-inf, below and above the lidar's limits).
    """
    n = draw(st.integers(1, 6))
    beams = draw(st.integers(1, 9))
    steps = draw(st.lists(st.integers(1, 2 * 10**9), min_size=n, max_size=n))
    stamps = [int(t) for t in np.cumsum([1_000_000_000, *steps[1:]])]
    low = draw(st.sampled_from([0.0, 0.02, 0.1, 0.45]))
    high = draw(st.sampled_from([0.5, 4.0, 30.0, 80.99, 250.0, INF]))
    ranges = st.one_of(st.floats(0.0, 40.0, width=32), PATHOLOGICAL, st.floats(width=32))
    geometry = {
        "angle_min": draw(st.floats(-math.pi, math.pi)),
        "angle_increment": draw(st.floats(0.01, 2 * math.pi / beams))
        * draw(st.sampled_from([1, -1])),
        "range_min": low,
        "range_max": high,
    }
    scans = [
        Scan(t, draw(st.lists(ranges, min_size=beams, max_size=beams)), **geometry) for t in stamps
    ]
    spread = draw(st.sampled_from([0.5, 5.0, 50.0]))
    coordinate, yaw = st.floats(-spread, spread), st.floats(-10.0, 10.0)
    ends = [stamps[0] - 1, stamps[-1] + 1]  # odometry covering every scan, mostly
    covered = draw(st.sampled_from([[], ends[:1], ends, ends, ends, ends]))
    odom_stamps = sorted({*covered, *draw(st.lists(st.sampled_from(stamps), max_size=n))}) or [1]
    poses = [Odom(t, draw(coordinate), draw(coordinate), draw(yaw)) for t in odom_stamps]
    recording = Drive(scans, poses, [replace(p) for p in poses])
    for kind, name in draw(st.lists(st.sampled_from(CORRUPTIONS), max_size=2)):
        messages = {"scan": recording.scans, "odom": poses}.get(kind, recording.reference)
        k = draw(st.integers(0, len(messages) - 1))
        if name == "stamp_ns":  # a repeated or earlier stamp, recorded in its place
            value = draw(st.sampled_from([m.stamp_ns for m in messages]))
            messages[k] = replace(messages[k], stamp_ns=value, log_ns=messages[k].stamp_ns)
            continue
        if name == "ranges":  # another number of beams
            value = draw(st.lists(ranges, max_size=beams + 2))
        elif name == "quaternion":
            value = tuple(draw(st.one_of(st.floats(-1.0, 1.0), PATHOLOGICAL)) for _ in range(4))
        else:
            value = draw(PATHOLOGICAL)
        messages[k] = replace(messages[k], **{name: value})
    return recording


FLAG_VALUES = {
    "--resolution-m": st.sampled_from(["0.05", "0.02", "0.1", "1", "0.01", "1e-6", "nan", "3"]),
    "--min-travel-m": st.sampled_from(["0", "0.5", "0.1", "1e300", "-0", "nan", "-2", "inf"]),
    "--match-margin": st.sampled_from(["0", "0.02", "0.5", "1", "2", "nan", "-0.1"]),
    "--refine": st.sampled_from(["score", "walls", "icp"]),
}


@pytest.mark.slow
@settings(
    max_examples=40,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(
    recording=recordings(),
    flags=st.dictionaries(st.sampled_from(list(FLAG_VALUES)), st.just(None), max_size=3),
    data=st.data(),
    switches=st.lists(
        st.sampled_from(["--no-loop-closure", "--scan-matching=none", "--reference=/ground_truth"]),
        unique=True,
    ),
)
def test_any_recording_with_any_flags_maps_or_is_refused_in_one_line(
    recording, flags, data, switches
):
    values = [f"{flag}={data.draw(FLAG_VALUES[flag], label=flag)}" for flag in flags]
    with tempfile.TemporaryDirectory() as folder:
        bag = write(Path(folder) / "bag", recording)
        out = Path(folder) / "m"
        done = _cli("map", str(bag), "--out", str(out), "--quiet", *values, *switches)
        assert done.returncode in (0, 2), done.stderr
        if done.returncode == 0:
            assert done.stderr == "" and (out / "summary.json").is_file()
        else:
            assert done.stderr.count("\n") == 1, done.stderr
            assert done.stderr.startswith((f"cosim: error: {bag}: ", "cosim map: error: argument"))
