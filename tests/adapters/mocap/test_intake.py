from pathlib import Path
from typing import Any, ClassVar

import numpy as np
import pytest

import cosim
from adapters.fleet.mirror import Mirrors
from adapters.mocap.contract import SourceContext
from adapters.mocap.intake import JUMP_TOLERANCE_RAD, PoseIntake
from adapters.mocap.topics import pose_topic
from cosim.core.hosts import HostId
from cosim.core.messages import PoseStamped
from cosim.core.plugins import PluginError
from cosim.core.registry import registered
from cosim.recording.dataframes import table_frame
from cosim.runner.assembly import Assembly, assemble

SMALL = {
    "world.size_m": [12.0, 12.0],
    "world.shelf_count": 4,
    "robots.count": 2,
    "lidar.beams": 60,
    "record.messages": False,
}


def scenario(**overrides: object) -> cosim.Scenario:
    return cosim.load_scenario("warehouse-random", overrides={**SMALL, **overrides})


def intake_of(assembly: Assembly) -> PoseIntake:
    intake = dict(assembly.adapters)["mocap"].intake
    assert isinstance(intake, PoseIntake)
    return intake


def simulated() -> tuple[Assembly, PoseIntake, list[tuple[int, PoseStamped, str]]]:
    """The intake of a simulated system (not started), and what it publishes on robot_1's pose."""
    assembly = assemble(scenario(**{"scenario.duration_s": 1.0, "mocap.source": "simulated"}))
    seen: list[tuple[int, PoseStamped, str]] = []
    assembly.run.bus.monitor(
        pose_topic("robot_1"), lambda _t, m, src, now: seen.append((now, m, src))
    )
    return assembly, intake_of(assembly), seen


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


def test_an_accepted_pose_is_published_in_map_from_the_mocap_host_with_its_stamp():
    _, intake, seen = simulated()
    assert intake.submit(0, 5_000_000, 2.0, 3.0, 0.5, mirror=False)
    [(now, message, src)] = seen
    assert message == PoseStamped(5_000_000, "map", 2.0, 3.0, 0.5)
    assert (now, src) == (0, "mocap")
    assert intake.records.counts["poses"] == 1


def test_a_pose_may_be_published_from_another_host():
    _, intake, seen = simulated()
    intake.submit(0, 5_000_000, 2.0, 3.0, 0.5, mirror=False, host=HostId("robot_1"))
    assert seen[0][2] == "robot_1"


def test_the_records_stamp_the_kernel_time_unless_told_otherwise():
    assembly, intake, _ = simulated()
    assembly.run.kernel.run(250_000_000)
    intake.submit(0, 1, float("inf"), 0.0, 0.0, mirror=False)
    intake.submit(0, 1, float("nan"), 0.0, 0.0, mirror=False, now_ns=400_000_000)
    rows = table_frame(intake.records.table)
    assert list(rows.t_s) == [0.25, 0.4]
    assert list(rows.detail) == ["pose (inf, 0.0, 0.0)", "pose (nan, 0.0, 0.0)"]


def test_a_rejected_pose_leaves_the_last_good_one_to_check_against():
    _, intake, seen = simulated()
    assert intake.submit(0, 100_000_000, 2.0, 2.0, 0.0, mirror=False)
    assert not intake.submit(0, 200_000_000, 9.0, 9.0, 0.0, mirror=False)  # a jump
    # 1 s after the good one: 0.5 m is within reach of it, not of the rejected one
    assert intake.submit(0, 1_100_000_000, 2.5, 2.0, 0.0, mirror=False)
    assert [m.x_m for _, m, _ in seen] == [2.0, 2.5]


def test_a_turn_faster_than_the_robot_can_is_a_jump_too():
    _, intake, _ = simulated()
    assert intake.submit(0, 100_000_000, 2.0, 2.0, 0.0, mirror=False)
    assert not intake.submit(0, 110_000_000, 2.0, 2.0, 1.5, mirror=False)  # 1.5 rad in 10 ms
    assert intake.submit(0, 120_000_000, 2.0, 2.0, JUMP_TOLERANCE_RAD / 2, mirror=False)


def test_robots_are_checked_each_against_their_own_last_pose():
    _, intake, _ = simulated()
    assert intake.submit(0, 100_000_000, 2.0, 2.0, 0.0, mirror=False)
    assert intake.submit(1, 100_000_000, 8.0, 8.0, 0.0, mirror=False)
    assert intake.submit(1, 90_000_000, 8.0, 8.0, 0.0, mirror=False) is False
    assert intake.submit(0, 110_000_000, 2.0, 2.0, 0.0, mirror=False)


def test_the_world_reaches_to_the_walls_outer_faces():
    _, intake, _ = simulated()
    assert intake.world_m == (-0.2, -0.2, 12.2, 12.2)
    assert intake.submit(0, 100_000_000, -0.2, 12.2, 0.0, mirror=False)
    assert intake.records.counts["off_map_poses"] == 0


def test_poses_leaving_the_world_are_recorded_once_each_way_and_all_counted():
    assembly, intake, seen = simulated()
    stamps = iter(range(100_000_000, 10_000_000_000, 100_000_000))
    assert intake.submit(0, next(stamps), 0.1, 1.0, 0.0, mirror=False)
    for x in (-0.25, -0.3, -0.35):  # outside, three times
        assert not intake.submit(0, next(stamps), x, 1.0, 0.0, mirror=False)
    assert intake.off_map == [True, False]
    assert intake.submit(0, next(stamps), 0.0, 1.0, 0.0, mirror=False)  # back
    assert intake.off_map == [False, False]
    rows = table_frame(intake.records.table)
    assert list(rows.event) == ["off_map", "on_map"]
    assert rows.detail.iloc[0] == (
        "pose (-0.25, 1.00) m outside the world [-0.2, 12.2] x [-0.2, 12.2] m: rejected, the "
        "robot holds its last pose"
    )
    assert rows.detail.iloc[1] == "pose (0.00, 1.00) m: back in the world"
    events = table_frame(assembly.run.recorder.events)
    assert list(events.kind) == ["pose_off_map", "pose_on_map"]
    assert list(events.source) == ["robot_1", "robot_1"]
    assert intake.records.summary()["mocap_rejected_off_map"] == 3
    assert [m.x_m for _, m, _ in seen] == [0.1, 0.0]


def test_the_pose_topics_are_advertised_once_for_each_robot():
    assembly, intake, _ = simulated()
    intake.advertise(0)
    intake.advertise(0)
    advertised = assembly.run.bus.advertised()
    assert advertised[pose_topic("robot_1")].message_type is PoseStamped
    assert pose_topic("robot_2") in advertised  # the simulated system tracks both


def test_an_accepted_pose_of_a_twin_becomes_its_ground_truth(tmp_path: Path):
    track = tmp_path / "track.csv"
    track.write_text("t_s,x_m,y_m,yaw_rad\n0,2.0,3.0,0.0\n")
    assembly = assemble(
        scenario(**{"mocap.source": "bag", "mocap.file": str(track), "scenario.duration_s": 1.0})
    )
    intake = intake_of(assembly)
    mirrors = assembly.run.service(Mirrors)
    assert mirrors.mirrored.tolist() == [True, False]  # robot_1 follows the recording
    assert intake.submit(0, 100_000_000, 2.0, 3.0, 0.25, mirror=True)
    assert mirrors.target[0].tolist() == [2.0, 3.0, 0.25] and mirrors.fresh[0]
    assert not intake.submit(0, 110_000_000, 9.0, 9.0, 0.0, mirror=True)
    assert mirrors.target[0].tolist() == [2.0, 3.0, 0.25]  # a rejected pose moves nothing
    with pytest.raises(ValueError, match="robot robot_2 is not mirrored"):
        intake.submit(1, 100_000_000, 5.0, 5.0, 0.0, mirror=True)


# -- what is not a pose at all: a fault of the source's code ------------------------------------
class Spoilt:
    """A plugin pose source (measures nothing) whose ``start`` submits ``pose`` once at 0.1 s."""

    name: ClassVar[str] = "spoilt"
    external: ClassVar[bool] = False
    live: ClassVar[bool] = False
    uses_dds: ClassVar[bool] = False
    pose: ClassVar[tuple[Any, ...]] = ()

    @classmethod
    def tracks(cls, mocap: Any, outside: Any, names: list[str]) -> list[tuple[str, str]]:
        return [(name, "") for name in names]

    @classmethod
    def describe(cls, mocap: Any, body: str) -> str:
        return "a test's source"

    def __init__(self, context: SourceContext) -> None:
        self.intake = context.intake

    def start(self, run: Any) -> None:
        run.kernel.at(100_000_000, lambda: self.intake.submit(*self.pose, mirror=False))

    def close(self) -> None:
        pass

    def summary(self) -> dict[str, Any]:
        return {}


def _spoilt(*pose: Any) -> str:
    source = type("Spoilt", (Spoilt,), {"pose": pose})
    overrides = {"scenario.duration_s": 0.5, "mocap.source": "spoilt"}
    with registered("cosim.mocap_sources", "spoilt", source), pytest.raises(PluginError) as caught:
        cosim.run(scenario(**overrides))
    error = caught.value
    assert error.plugin is not None and error.plugin.name == "spoilt"
    line = str(error)
    assert line.startswith("motion capture source 'spoilt' (")
    return line


@pytest.mark.parametrize(
    ("pose", "said"),
    [
        (
            (0, 100_000_000, "1.0", 2.0, 0.0),
            "submitted x_m = '1.0' (str) for robot_1; expected a number (m, rad) "
            "while taking in robot_1's pose",
        ),
        (
            (1, 100_000_000, 1.0, None, 0.0),
            "submitted y_m = None (NoneType) for robot_2; expected a number (m, rad)",
        ),
        (
            (1, 100_000_000, 1.0, 2.0, True),
            "submitted yaw_rad = True (bool) for robot_2; expected a number (m, rad)",
        ),
        (
            (0, 0.1, 1.0, 2.0, 0.0),
            "submitted stamp_ns = 0.1 (float) for robot_1; expected an int (kernel ns)",
        ),
        (
            (2, 100_000_000, 1.0, 2.0, 0.0),
            "submitted a pose for robot index 2; expected a robot index 0 to 1 (an int, in "
            "fleet order) while taking in a pose",
        ),
        (
            ("robot_1", 100_000_000, 1.0, 2.0, 0.0),
            "submitted a pose for robot index 'robot_1'; expected a robot index 0 to 1",
        ),
    ],
)
def test_a_pose_that_is_not_numbers_is_refused_naming_the_source_robot_and_value(pose, said):
    assert said in _spoilt(*pose)


def test_numpy_numbers_are_poses_and_non_finite_ones_stay_measurement_rejections():
    _, intake, seen = simulated()
    pose = (np.float32(2.0), 3, np.float64(0.5))
    assert intake.submit(np.int64(0), np.int64(5), *pose, mirror=False)
    assert seen[0][1] == PoseStamped(5, "map", 2.0, 3.0, 0.5)
    assert not intake.submit(0, 6, float("nan"), 3.0, 0.5, mirror=False)  # recorded, not raised
    assert list(table_frame(intake.records.table).event) == ["invalid"]
