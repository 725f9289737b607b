from collections.abc import Mapping
from typing import Any, ClassVar

import pytest

import cosim
from adapters.mocap.contract import SourceContext
from adapters.mocap.live import LiveSourceError, PolledSource, Sample
from adapters.mocap.settings import MocapConfig
from adapters.mocap.topics import pose_topic
from cosim.core.adapter import RunContext
from cosim.core.errors import BridgeError
from cosim.core.messages import PoseStamped
from cosim.recording.dataframes import table_frame
from cosim.runner.assembly import assemble

SMALL = {
    "world.size_m": [12.0, 12.0],
    "world.shelf_count": 4,
    "robots.count": 3,
    "lidar.beams": 60,
    "record.messages": False,
}


class Scripted(PolledSource):
    """A live source whose arrivals and failure a test decides."""

    name: ClassVar[str] = "scripted"
    uses_dds: ClassVar[bool] = False
    settings_hint: ClassVar[str] = "mocap.bodies and the scripted system"

    def __init__(self, context: SourceContext) -> None:
        super().__init__(context)
        self.arrivals: dict[int, list[Sample]] = {}
        self.polls: list[int] = []
        self.broken: str | None = None
        self.connects = self.disconnects = 0

    def connect(self, run: RunContext) -> None:
        self.connects += 1

    def take(self, now_ns: int) -> list[Sample]:
        self.polls.append(now_ns)
        return self.arrivals.pop(now_ns, [])

    def failure(self) -> str | None:
        return self.broken

    def silence(self, index: int) -> str:
        return f"nothing of {self.names[index]} from the scripted system"

    def disconnect(self) -> None:
        self.disconnects += 1

    def counts(self) -> Mapping[str, Any]:
        return {"mocap_scripted_polls": len(self.polls)}


def scripted(
    timeout_s: float = 0.5, rate_hz: float = 10.0, duration_s: float = 300.0
) -> tuple[RunContext, Scripted, list]:
    """A source tracking robot_1 and robot_3, polled at ``rate_hz``, started at time 0."""
    s = cosim.load_scenario(
        "warehouse-random",
        {
            **SMALL,
            "mocap.source": "simulated",
            "mocap.connect_timeout_s": timeout_s,
            "mocap.rate_hz": rate_hz,
            "scenario.duration_s": duration_s,
        },
    )
    assembly = assemble(s)
    run = assembly.run
    mocap = dict(assembly.adapters)["mocap"]
    for index in (0, 2):
        mocap.intake.mirrors.add(index)
    context = SourceContext(
        run, s.section(MocapConfig), mocap.intake, mocap.records, mocap.host, [(0, "a"), (2, "c")]
    )
    source = Scripted(context)
    published: list[tuple[int, str, PoseStamped]] = []
    for name in ("robot_1", "robot_3"):
        run.bus.monitor(pose_topic(name), lambda t, m, _src, now: published.append((now, t, m)))
    source.start(run)
    return run, source, published


def events(run: RunContext) -> list[tuple[float, str, str, str]]:
    frame = table_frame(run.recorder.events)
    return list(zip(frame.t_ns / 1e9, frame.source, frame.kind, frame.detail, strict=True))


def test_a_live_source_sends_on_the_wall_clock_poses_from_outside():
    assert (PolledSource.external, PolledSource.live) == (True, True)
    assert PolledSource.settings_hint == "mocap.bodies"
    assert issubclass(LiveSourceError, BridgeError)


def test_it_connects_once_and_is_polled_at_the_mocap_rate():
    run, source, _ = scripted(rate_hz=20.0, timeout_s=10.0)
    run.kernel.run(200_000_000)
    assert source.connects == 1
    assert source.polls == [k * 50_000_000 for k in range(4)]


def test_what_arrived_goes_through_the_intake_as_poses_of_twins():
    run, source, published = scripted(timeout_s=10.0)
    source.arrivals[100_000_000] = [(0, 90_000_000, 2.0, 2.0, 0.0), (2, 95_000_000, 4.0, 1.0, 1.0)]
    source.arrivals[200_000_000] = [(2, 150_000_000, float("nan"), 1.0, 1.0)]
    run.kernel.run(300_000_000)
    assert [(now, t, m.stamp_ns, m.x_m) for now, t, m in published] == [
        (100_000_000, "/robot_1/pose", 90_000_000, 2.0),
        (100_000_000, "/robot_3/pose", 95_000_000, 4.0),
    ]
    mirrors = source.context.intake.mirrors
    assert mirrors.target[2].tolist() == [4.0, 1.0, 1.0]
    rows = table_frame(source.context.records.table)
    assert list(zip(rows.t_s, rows.robot, rows.event, strict=True)) == [(0.2, "robot_3", "invalid")]


def test_a_failed_source_ends_the_run_at_once_naming_why_and_the_keys():
    run, source, _ = scripted(timeout_s=10.0)
    run.kernel.run(150_000_000)
    source.broken = "the scripted system at 'lab' hung up"
    with pytest.raises(LiveSourceError) as ended:
        run.kernel.run(1_000_000_000)
    assert str(ended.value) == (
        "the scripted system at 'lab' hung up; expected a pose of every tracked robot within "
        "mocap.connect_timeout_s = 10 s (see mocap.bodies and the scripted system)"
    )
    assert events(run) == [(0.2, "mocap", "mocap_failed", "the scripted system at 'lab' hung up")]


def test_a_tracked_robot_without_a_pose_by_the_timeout_ends_the_run_naming_it():
    run, source, _ = scripted(timeout_s=0.5)
    source.arrivals[100_000_000] = [(0, 90_000_000, 2.0, 2.0, 0.0)]
    run.kernel.run(500_000_000)  # the polls up to 0.4 s: still waiting
    with pytest.raises(LiveSourceError) as ended:
        run.kernel.run(2_000_000_000)
    assert str(ended.value) == (
        "nothing of robot_3 from the scripted system; expected a pose of every tracked robot "
        "within mocap.connect_timeout_s = 0.5 s (see mocap.bodies and the scripted system)"
    )
    assert events(run) == [
        (0.5, "robot_3", "no_pose", "nothing of robot_3 from the scripted system")
    ]


def test_of_several_silent_robots_the_first_in_fleet_order_is_named():
    run, _, _ = scripted(timeout_s=0.2)
    with pytest.raises(LiveSourceError, match=r"^nothing of robot_1 from"):
        run.kernel.run(1_000_000_000)


def test_once_every_robot_was_heard_silence_no_longer_ends_the_run():
    run, source, _ = scripted(timeout_s=0.3)
    source.arrivals[0] = [(0, 0, 2.0, 2.0, 0.0), (2, 0, 4.0, 1.0, 1.0)]
    run.kernel.run(3_000_000_000)
    assert len(source.polls) == 30 and events(run) == []


def test_closing_takes_the_counts_and_disconnects_once():
    run, source, _ = scripted(timeout_s=10.0)
    run.kernel.run(250_000_000)
    assert source.summary() == {}
    source.close()
    source.close()
    assert source.disconnects == 1
    assert source.summary() == {"mocap_connected": False, "mocap_scripted_polls": 3}


def test_closing_a_source_that_never_started_does_nothing():
    _, source, _ = scripted()
    fresh = Scripted(source.context)
    fresh.close()
    assert fresh.disconnects == 0 and fresh.summary() == {}


def test_a_subclass_must_say_what_arrived_and_what_it_listened_for():
    _, source, _ = scripted()
    bare = PolledSource(source.context)
    with pytest.raises(NotImplementedError):
        bare.take(0)
    with pytest.raises(NotImplementedError):
        bare.silence(0)
    assert bare.failure() is None and bare.counts() == {}


@pytest.mark.parametrize("timeout_s", [10.0, 1.0])
def test_a_run_ending_within_the_timeout_with_a_silent_robot_fails_at_its_last_poll(timeout_s):
    run, source, _ = scripted(timeout_s=timeout_s, duration_s=1.0)
    source.arrivals[100_000_000] = [(0, 90_000_000, 2.0, 2.0, 0.0)]
    run.kernel.run(900_000_000)  # the polls up to 0.8 s: still waiting
    with pytest.raises(LiveSourceError) as ended:
        run.kernel.run(1_000_000_000)
    assert str(ended.value) == (
        "nothing of robot_3 from the scripted system; the run ended at 1 s, within "
        f"mocap.connect_timeout_s = {timeout_s:g} s: expected a pose of every tracked robot "
        "before the run ends (see mocap.bodies and the scripted system)"
    )
    assert events(run) == [
        (0.9, "robot_3", "no_pose", "nothing of robot_3 from the scripted system")
    ]
    assert source.waited_s == 1.0  # what a source's silence() says it waited
    source.close()
    assert source.summary()["mocap_connected"] is True  # robot_1 was heard


def test_a_run_ending_within_the_timeout_whose_robots_were_all_heard_ends_as_planned():
    run, source, _ = scripted(timeout_s=10.0, duration_s=1.0)
    source.arrivals[500_000_000] = [(0, 0, 2.0, 2.0, 0.0), (2, 0, 4.0, 1.0, 1.0)]
    run.kernel.run(1_000_000_000)
    assert len(source.polls) == 10 and events(run) == []
    assert source.waited_s == 1.0


def test_a_run_longer_than_the_timeout_waits_the_timeout():
    _, source, _ = scripted(timeout_s=0.5, duration_s=1.0)
    assert source.waited_s == 0.5
