"""The mocap adapter through real runs: simulated frames, replays, a live mock system."""

from pathlib import Path

import numpy as np
import pytest

import cosim
from adapters.bags.tracks import read_pose_track
from adapters.mocap.intake import PoseIntake
from cosim.core.errors import BagError, ConfigError
from cosim.recording.dataframes import table_frame
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


def run_watching(s: cosim.Scenario, topic: str) -> tuple[list[tuple[int, object]], object]:
    """Run ``s`` and keep every publication on ``topic`` with its time."""
    from cosim.runner.execute import _run_assembled

    assembly = assemble(s)
    seen: list[tuple[int, object]] = []
    assembly.run.bus.monitor(topic, lambda _t, message, _src, t_ns: seen.append((t_ns, message)))
    return seen, _run_assembled(s, assembly, None)


def test_simulated_poses_carry_the_configured_noise_latency_and_stamp():
    s = scenario(
        **{
            "scenario.duration_s": 4.0,
            "mocap.source": "simulated",
            "mocap.noise_std_m": 0.01,
            "mocap.latency_ms": 7.0,
        }
    )
    seen, result = run_watching(s, "/robot_1/pose")
    truth = result.tables["poses"]
    truth = truth[truth.robot == "robot_1"].set_index("t_s")
    errors = []
    for t_ns, message in seen:
        assert t_ns - message.stamp_ns == 7_000_000  # sent 7 ms after the frame instant
        if message.stamp_ns % 100_000_000 == 0:  # frames on the 10 Hz pose samples
            row = truth.loc[round(message.stamp_ns / 1e9, 1)]
            errors += [message.x_m - row.x_m, message.y_m - row.y_m]
    assert len(errors) > 60
    assert 0.006 < float(np.std(errors)) < 0.014


def test_a_pose_further_than_the_robot_can_drive_is_rejected_and_recorded():
    s = scenario(**{"scenario.duration_s": 1.0, "mocap.source": "simulated"})
    assembly = assemble(s)
    intake = dict(assembly.adapters)["mocap"].intake
    assert isinstance(intake, PoseIntake)
    assert intake.submit(0, 1_000_000, 1.0, 1.0, 0.0, mirror=False, now_ns=0)
    assert not intake.submit(0, 11_000_000, 3.0, 1.0, 0.0, mirror=False, now_ns=0)  # 2 m in 10 ms
    assert not intake.submit(0, 1_000_000, 1.0, 1.0, 0.0, mirror=False, now_ns=0)  # same stamp
    assert not intake.submit(0, 21_000_000, float("nan"), 1.0, 0.0, mirror=False, now_ns=0)
    assert intake.submit(0, 21_000_000, 1.01, 1.0, 0.0, mirror=False, now_ns=0)
    rows = table_frame(intake.records.table)
    assert list(rows.event) == ["jump", "out_of_order", "invalid"]
    assert rows.detail.iloc[0] == "2.000 m in 0.010 s"


def write_csv(path: Path, rows: list[tuple[float, float, float, float]]) -> Path:
    path.write_text("t_s,x_m,y_m,yaw_rad\n" + "".join(f"{t},{x},{y},{a}\n" for t, x, y, a in rows))
    return path


def test_a_replayed_csv_track_moves_its_robot_along_the_recording(tmp_path: Path):
    rows = [(10.0 + 0.05 * k, 2.0 + 0.02 * k, 3.0, 0.0) for k in range(60)]  # 0.4 m/s for 3 s
    track = write_csv(tmp_path / "track.csv", rows)
    s = scenario(
        **{
            "scenario.duration_s": 4.0,
            "mocap.source": "bag",
            "mocap.file": str(track),
            "robots.driver": "waypoints",
        }
    )
    result = execute(s)
    poses = result.tables["poses"]
    twin = poses[poses.robot == "robot_1"].set_index("t_s")
    # the replay starts at time 0 (sample k at 0.05 k s); a pose arriving at an instant is
    # applied at the next physics tick, so at 1.0 s the twin stands where sample 19 put it
    assert twin.loc[1.0].x_m == pytest.approx(2.0 + 0.02 * 19)
    assert twin.loc[3.5].x_m == pytest.approx(2.0 + 0.02 * 59)
    assert twin.loc[3.5].y_m == pytest.approx(3.0)
    assert result.summary["mocap_poses"] == 60


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


def test_a_bag_without_the_named_topic_is_refused_before_the_run(tmp_path: Path):
    if not NAV2.exists():
        pytest.skip(f"{NAV2} absent (the shared data folder)")
    s = scenario(
        **{"mocap.source": "bag", "mocap.file": str(NAV2), "mocap.bodies": [["robot_1", "/nope"]]}
    )
    with pytest.raises(BagError, match="no topic /nope"):
        assemble(s)


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
