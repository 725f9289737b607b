"""`cosim map BAG`: the robots' mapping on recordings, ours and a real building's."""

import json

import numpy as np
import pandas as pd
import pytest

import cosim
from adapters.world.files import read_map
from cosim.cli.bagmap import map_bag
from cosim.core.errors import BagError, ExportError
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
