from pathlib import Path

import pytest

import cosim
from adapters.bags.tracks import TrackError
from adapters.mocap.replay import RecordedSource
from adapters.mocap.settings import MocapConfig
from adapters.mocap.topics import pose_topic
from cosim.core.errors import BagError, ConfigError
from cosim.core.messages import PoseStamped
from cosim.runner.assembly import assemble
from cosim.runner.execute import execute
from tests.adapters.mapping.recordings import T0_NS, Drive, Odom, write
from tests.conftest import SHARED_DATA

NAV2 = SHARED_DATA / "nav2_turtlebot.mcap"
NAMES = ["robot_1", "robot_2"]
SMALL = {
    "world.size_m": [12.0, 12.0],
    "world.shelf_count": 4,
    "robots.count": 2,
    "lidar.beams": 60,
    "record.messages": False,
}


def scenario(**overrides: object) -> cosim.Scenario:
    return cosim.load_scenario("warehouse-random", overrides={**SMALL, **overrides})


def test_a_replay_comes_from_outside_without_a_wall_clock():
    assert RecordedSource.name == "bag"
    assert (RecordedSource.external, RecordedSource.live, RecordedSource.uses_dds) == (
        True,
        False,
        False,
    )
    assert RecordedSource.keys == ("file", "bodies")


def test_it_replays_the_bodies_named_or_the_bags_only_track_on_the_first_robot():
    cfg = MocapConfig(source="bag", file="run.mcap")
    assert RecordedSource.tracks(cfg, {"robot_2": "mocap"}, NAMES) == [("robot_1", "")]
    named = MocapConfig(source="bag", file="run.mcap", bodies=(("robot_2", "/odom"),))
    assert RecordedSource.tracks(named, {}, NAMES) == [("robot_2", "/odom")]


def test_it_says_which_track_of_which_file_it_replays():
    cfg = MocapConfig(source="bag", file="run.mcap")
    assert RecordedSource.describe(cfg, "/odom") == "the pose track /odom of run.mcap"
    assert RecordedSource.describe(cfg, "") == "the pose track (the only pose topic) of run.mcap"


def test_it_needs_a_file_and_one_body_for_a_csv_file():
    problems = list(RecordedSource.problems(MocapConfig(source="bag")))
    assert [(p.key, p.value) for p in problems] == [("file", "")]
    two = (("robot_1", "a"), ("robot_2", "b"))
    csv = MocapConfig(source="bag", file="t.csv", bodies=two)
    assert [(p.key, p.value) for p in RecordedSource.problems(csv)] == [
        ("bodies", [["robot_1", "a"], ["robot_2", "b"]])
    ]
    bag = MocapConfig(source="bag", file="t.mcap", bodies=two)
    assert list(RecordedSource.problems(bag)) == []
    with pytest.raises(ConfigError) as refused:
        scenario(**{"mocap.source": "bag", "mocap.file": "t.csv", "mocap.bodies": list(two)})
    assert str(refused.value) == (
        "--set mocap.bodies: [mocap] bodies = [['robot_1', 'a'], ['robot_2', 'b']]: expected "
        "one body for a CSV file"
    )


def test_a_file_that_cannot_be_read_is_refused_when_the_run_is_built(tmp_path: Path):
    bad = tmp_path / "track.csv"
    bad.write_text("t_s,x_m,y_m\n0,1,2\n")
    with pytest.raises(TrackError, match="missing column 'yaw_rad'"):
        assemble(scenario(**{"mocap.source": "bag", "mocap.file": str(bad)}))


def test_tracks_of_one_bag_are_replayed_from_the_earliest_stamp_of_all(tmp_path: Path):
    early = [Odom(T0_NS + k * 100_000_000, 2.0 + 0.01 * k, 2.0) for k in range(10)]
    late = [Odom(T0_NS + 500_000_000 + k * 100_000_000, 6.0, 3.0 + 0.01 * k) for k in range(5)]
    bag = write(tmp_path / "bag", Drive([], early, extra={"/late": late}))
    s = scenario(
        **{
            "mocap.source": "bag",
            "mocap.file": str(bag),
            "mocap.bodies": [["robot_1", "/odom"], ["robot_2", "/late"]],
        }
    )
    assembly = assemble(s)
    run = assembly.run
    seen: list[tuple[int, str, PoseStamped]] = []
    for name in NAMES:
        run.bus.monitor(pose_topic(name), lambda t, m, _src, now: seen.append((now, t, m)))
    dict(assembly.adapters)["mocap"].start(run)
    run.kernel.run(2_000_000_000)
    first = [(now, m.stamp_ns, m.x_m) for now, t, m in seen if t == pose_topic("robot_1")]
    second = [(now, m.stamp_ns, m.y_m) for now, t, m in seen if t == pose_topic("robot_2")]
    assert first == [(k * 100_000_000,) * 2 + (pytest.approx(2.0 + 0.01 * k),) for k in range(10)]
    assert [now for now, _, _ in second] == [500_000_000 + k * 100_000_000 for k in range(5)]
    assert [y for _, _, y in second] == pytest.approx([3.0 + 0.01 * k for k in range(5)])


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


def test_a_bag_without_the_named_topic_is_refused_before_the_run(tmp_path: Path):
    if not NAV2.exists():
        pytest.skip(f"{NAV2} absent (the shared data folder)")
    s = scenario(
        **{"mocap.source": "bag", "mocap.file": str(NAV2), "mocap.bodies": [["robot_1", "/nope"]]}
    )
    with pytest.raises(BagError, match="no topic /nope"):
        assemble(s)
