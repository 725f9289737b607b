"""A run's recording: planned before the run, opened after assembly, closed whatever happens."""

from __future__ import annotations

import re
from collections.abc import Sequence

import pytest

import cosim
from cosim.core.bus import Bus, TopicQos
from cosim.core.errors import ConfigError, ExportError
from cosim.core.hosts import HostId
from cosim.core.kernel import Kernel
from cosim.core.messages import Clock, Twist
from cosim.recording import setup
from cosim.recording.bag import BAG_DIR
from cosim.recording.foxglove import LiveOptions
from cosim.recording.schemas import ChannelSpec
from cosim.recording.setup import RecordingPlan, RecordingSession
from tests.bags import mcap_file, read_mcap

ROBOT, BASE = HostId("robot_1"), HostId("base")


def _scenario(**overrides: object) -> cosim.Scenario:
    return cosim.load_scenario("warehouse-random", overrides=overrides)


def _bus() -> tuple[Kernel, Bus]:
    kernel = Kernel()
    bus = Bus(kernel)
    bus.advertise("/clock", Clock, TopicQos.DEFAULT)
    bus.advertise("/robot_1/cmd_vel", Twist, TopicQos.DEFAULT)
    bus.advertise("/robot_1/odom_like", Twist, TopicQos.SENSOR)
    return kernel, bus


def test_a_run_with_a_folder_records_its_bag_in_the_bag_folder_as_record_says(tmp_path):
    scenario = _scenario(**{"record.bag": "sqlite3", "record.compression": "none"})
    plan = RecordingPlan.for_run(scenario, tmp_path)
    assert plan.bag == tmp_path / BAG_DIR
    assert (plan.storage, plan.compression) == ("sqlite3", "none")
    assert plan.active and not plan.realtime


def test_without_a_folder_or_with_record_bag_none_nothing_is_recorded(tmp_path):
    assert RecordingPlan.for_run(_scenario(), None) == RecordingPlan(None)
    off = RecordingPlan.for_run(_scenario(**{"record.bag": "none"}), tmp_path)
    assert off.bag is None and not off.active


def test_a_live_view_makes_a_run_active_and_paced_by_the_wall_clock_even_without_a_bag():
    plan = RecordingPlan.for_run(_scenario(), None, live=LiveOptions(port=0))
    assert plan.bag is None and plan.active and plan.realtime


def test_the_recorded_topics_are_those_record_topics_keeps_in_advertisement_order():
    _, bus = _bus()
    scenario = _scenario(**{"record.topics": ["/robot_1/*", "!/robot_1/odom_like", "/clock"]})
    topics = RecordingSession.topics_of(scenario, bus)
    assert list(topics) == ["/clock", "/robot_1/cmd_vel"]


def test_a_topic_pattern_matching_nothing_is_refused_naming_the_scenario_and_pattern():
    _, bus = _bus()
    scenario = _scenario(**{"record.topics": ["/clock", "/robot_1/scna"]})
    with pytest.raises(ConfigError) as refused:
        RecordingSession.topics_of(scenario, bus)
    assert str(refused.value) == (
        "preset warehouse-random: [record] topics: pattern '/robot_1/scna' matches no topic of "
        "this run; expected a glob over its topics (/clock, /robot_*/cmd_vel, /robot_*/odom_like)"
    )


def test_the_bag_is_made_after_before_bag_and_holds_every_recorded_message(tmp_path):
    kernel, bus = _bus()
    scenario = _scenario(**{"record.topics": ["*"]})
    plan = RecordingPlan.for_run(scenario, tmp_path)
    session = RecordingSession(plan, RecordingSession.topics_of(scenario, bus), bus)
    seen: list[bool] = []
    session.open(before_bag=lambda: seen.append((tmp_path / BAG_DIR).exists()))
    assert seen == [False] and (tmp_path / BAG_DIR).is_dir()
    kernel.at(5, lambda: bus.publish("/robot_1/cmd_vel", Twist(0.5, 0.0), ROBOT))
    kernel.at(7, lambda: bus.publish("/clock", Clock(7), BASE))
    kernel.run(10)
    session.close()
    session.close()  # once: a second close changes nothing
    assert session.counts() == {"/clock": 1, "/robot_1/cmd_vel": 1, "/robot_1/odom_like": 0}
    assert session.summary() == {}
    bag = read_mcap(mcap_file(tmp_path / BAG_DIR))
    assert dict(bag.log_ns) == {"/robot_1/cmd_vel": [5], "/clock": [7]}
    assert bag.types["/robot_1/cmd_vel"] == "geometry_msgs/msg/Twist"


def test_a_session_not_opened_has_no_counts_and_closes_quietly():
    _, bus = _bus()
    session = RecordingSession(RecordingPlan(None), {}, bus)
    session.close()
    assert session.counts() == {} and session.tap is None


class FakeLive:
    """A live view that opens without a server and remembers being closed."""

    def __init__(self, options: LiveOptions) -> None:
        self.options = options
        self.closed = False

    def open(self, channels: Sequence[ChannelSpec]) -> None:
        self.channels = list(channels)

    def write(self, channel: int, t_ns: int, data: bytes, src: str) -> None:
        pass

    def close(self) -> None:
        self.closed = True


@pytest.fixture
def live_views(monkeypatch: pytest.MonkeyPatch) -> list[FakeLive]:
    """The live views a session starts (fakes, listening nowhere)."""
    made: list[FakeLive] = []

    def make(options: LiveOptions) -> FakeLive:
        made.append(FakeLive(options))
        return made[-1]

    monkeypatch.setattr(setup, "LiveSink", make)
    return made


def test_a_bag_that_cannot_be_made_closes_the_live_view_already_started(tmp_path, live_views):
    blocker = tmp_path / "file"
    blocker.write_text("in the way", encoding="utf-8")
    _, bus = _bus()
    plan = RecordingPlan(bag=blocker / BAG_DIR, live=LiveOptions(port=0))
    session = RecordingSession(plan, dict(bus.advertised()), bus)
    with pytest.raises(
        ExportError, match=f"^{re.escape(str(blocker / BAG_DIR))}: cannot create the bag"
    ):
        session.open()
    (live,) = live_views
    assert live.closed and session.tap is None


def test_a_failing_before_bag_leaves_no_bag_and_closes_the_live_view(tmp_path, live_views):
    _, bus = _bus()
    plan = RecordingPlan(bag=tmp_path / BAG_DIR, live=LiveOptions(port=0))
    session = RecordingSession(plan, dict(bus.advertised()), bus)

    def refuse() -> None:
        raise ExportError(f"{tmp_path}: not empty")

    with pytest.raises(ExportError, match="not empty"):
        session.open(before_bag=refuse)
    (live,) = live_views
    assert live.closed
    assert not (tmp_path / BAG_DIR).exists()
