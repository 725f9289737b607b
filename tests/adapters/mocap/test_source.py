"""The mocap adapter through real runs: simulated frames, replays, a live mock system."""

import pytest

import cosim
from adapters.bags.tracks import read_pose_track
from cosim.core.errors import ConfigError
from cosim.runner.assembly import assemble
from cosim.runner.execute import execute
from tests.conftest import SHARED_DATA

NAV2 = SHARED_DATA / "nav2_turtlebot.mcap"
SMALL = {
    "world.size_m": [12.0, 12.0],
    "world.shelf_count": 4,
    "robots.count": 2,
    "lidar.beams": 60,
    "record.messages": False,
}


def scenario(**overrides: object) -> cosim.Scenario:
    return cosim.load_scenario("warehouse-random", overrides={**SMALL, **overrides})


def test_robots_localize_by_simulated_mocap_and_every_frame_reaches_them():
    result = execute(scenario(**{"scenario.duration_s": 5.0, "mocap.source": "simulated"}))
    s = result.summary
    # 100 Hz x 2 robots x 5 s, minus the frame at t = 5 s (not run)
    assert s["mocap_poses"] == 2 * 500
    assert s["mocap_stale_stops"] == 0
    assert s["distance_m"] > 2.0


def test_a_robot_that_gets_no_pose_stops_once_its_last_one_is_too_old():
    result = execute(
        scenario(**{"scenario.duration_s": 5.0, "mocap.source": "simulated", "mocap.dropout": 1.0})
    )
    s = result.summary
    assert s["mocap_poses"] == 0
    assert s["mocap_stale_stops"] == 2
    rows = result.tables["mocap"]
    stale = rows[rows.event == "stale"]
    # the start pose is stamped 0; the first 10 Hz control tick after 200 ms stops them
    assert list(stale.t_s) == [0.3, 0.3]
    poses = result.tables["poses"]
    late = poses[poses.t_s >= 1.5]
    assert late.groupby("robot", observed=True).x_m.nunique().max() == 1  # standing still


@pytest.mark.slow
@pytest.mark.skipif(not NAV2.exists(), reason=f"{NAV2} absent (the shared data folder)")
def test_odometry_of_a_rosbag2_bag_recorded_outside_the_room_is_rejected_and_the_twin_held():
    # the TurtleBot's odometry starts at (-2.8, 1.1) m, outside the 12 m x 12 m room
    s = scenario(
        **{
            "scenario.duration_s": 20.0,
            "mocap.source": "bag",
            "mocap.file": str(NAV2),
            "mocap.bodies": [["robot_2", "/odom"]],
            "robots.driver": "waypoints",
            "mocap.jump_tolerance_m": 0.2,
        }
    )
    track = read_pose_track(NAV2, "/odom")
    replayed = int((track.relative() <= 20_000_000_000).sum())
    result = execute(s)
    mocap = result.tables["mocap"]
    assert list(mocap.event) == ["off_map", "on_map", "off_map"]  # one row each way
    assert mocap.detail.iloc[0] == (
        "pose (-2.80, 1.10) m outside the world [-0.2, 12.2] x [-0.2, 12.2] m: rejected, the "
        "robot holds its last pose"
    )
    events = result.tables["events"]
    kinds = [k for k in events[events.source == "robot_2"].kind if k.startswith("pose_")]
    assert kinds == ["pose_off_map", "pose_on_map", "pose_off_map"]
    twin = result.tables["poses"].query("robot == 'robot_2'")
    back_s = mocap.t_s.iloc[1]
    before = twin[twin.t_s < back_s]
    assert (before.x_m.nunique(), before.y_m.nunique()) == (1, 1)  # held where it started
    assert twin.x_m.between(-0.2, 12.2).all() and twin.y_m.between(-0.2, 12.2).all()
    summary = result.summary
    assert summary["mocap_rejected_off_map"] + summary["mocap_poses"] == replayed
    assert 0 < summary["mocap_poses"] < replayed / 4


def test_a_body_for_a_robot_that_does_not_exist_is_named():
    s = scenario(**{"mocap.source": "ros2", "mocap.bodies": [["robot_7", "/x"]]})
    with pytest.raises(ConfigError, match="robot_7"):
        assemble(s)


@pytest.mark.slow
def test_a_live_mock_mocap_system_holds_its_robot_at_the_start_pose_in_real_time():
    s = scenario(
        **{
            "scenario.duration_s": 1.5,
            "mocap.source": "motioncapture",
            "mocap.system": "mock",
            "mocap.bodies": [["robot_1", "robot_1"]],
        }
    )
    result = execute(s)
    summary = result.summary
    assert summary["mocap_poses"] > 50  # the mock system runs at about 100 Hz
    assert summary["mocap_missing_bodies"] == 0
    assert summary["max_lateness_ms"] is not None
    assert len(result.tables["realtime"]) > 10
    poses = result.tables["poses"]
    twin = poses[poses.robot == "robot_1"]
    # held where the mock system says it is (its float32 copy of the start pose)
    assert twin.x_m.max() - twin.x_m.min() < 1e-5
    assert twin.x_m.iloc[-1] == pytest.approx(twin.x_m.iloc[0], abs=1e-5)
