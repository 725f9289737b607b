from collections.abc import Sequence

import numpy as np
import pandas as pd
import pytest

from cosim.core.bus import Bus, Envelope
from cosim.core.hosts import HostId
from cosim.core.kernel import Kernel, Stage
from cosim.core.link import AllDelivered, Later, Transfer
from cosim.core.messages import Message, Twist
from cosim.core.recorder import Recorder
from cosim.core.timebase import period_ns
from cosim.recording.dataframes import messages_frame
from models.network.delivery import DeliveryStatus

A, B, C = HostId("a"), HostId("b"), HostId("c")


class FixedDelayLink:
    """A test link: every message arrives a fixed delay later; drops towards 'c'."""

    def __init__(self, delay_ns: int) -> None:
        self.delay_ns = delay_ns
        self.calls: list[tuple[int, HostId, tuple[HostId, ...], int]] = []

    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> Sequence[Transfer]:
        self.calls.append((t_ns, src, tuple(dsts), nbytes))
        return [
            Transfer(d, DeliveryStatus.LOST, None)
            if d == C
            else Transfer(d, DeliveryStatus.DELIVERED, t_ns + self.delay_ns)
            for d in dsts
        ]


def _collect(into: list[tuple[int, Message, Envelope]], kernel: Kernel):
    def callback(message: Message, envelope: Envelope) -> None:
        into.append((kernel.now_ns, message, envelope))

    return callback


def test_a_10_hz_publisher_is_delivered_at_exactly_k_times_100_ms_on_its_host():
    kernel = Kernel()
    bus = Bus(kernel)
    got: list[tuple[int, Message, Envelope]] = []
    bus.subscribe("/cmd", A, _collect(got, kernel))
    kernel.every(
        period_ns(10), lambda now: bus.publish("/cmd", Twist(1.0, 0.0), A), stage=Stage.CONTROL
    )
    kernel.run(2_000_000_000)
    assert [t for t, _, _ in got] == [k * 100_000_000 for k in range(20)]
    assert all(env.t_sent_ns == env.t_recv_ns == t for t, _, env in got)


def test_a_remote_subscriber_receives_when_the_link_says():
    kernel = Kernel()
    link = FixedDelayLink(5_000_000)
    bus = Bus(kernel, link)
    got: list[tuple[int, Message, Envelope]] = []
    bus.subscribe("/cmd", B, _collect(got, kernel))
    kernel.every(
        period_ns(10), lambda now: bus.publish("/cmd", Twist(0.5, 0.1), A), stage=Stage.CONTROL
    )
    kernel.run(1_000_000_000)
    assert [t for t, _, _ in got] == [k * 100_000_000 + 5_000_000 for k in range(10)]
    assert got[0][2] == Envelope("/cmd", A, 0, 5_000_000)


def test_one_transmission_reaches_every_remote_host_once_however_many_subscribers():
    kernel = Kernel()
    link = FixedDelayLink(0)
    bus = Bus(kernel, link)
    got: list[tuple[int, Message, Envelope]] = []
    for _ in range(3):
        bus.subscribe("/t", B, _collect(got, kernel))
    bus.subscribe("/t", C, _collect(got, kernel))
    bus.publish("/t", Twist(0.0, 0.0), A)
    kernel.run(1)
    assert link.calls == [(0, A, (B, C), Twist(0.0, 0.0).size_bytes())]
    assert len(got) == 3  # three callbacks on b, none on c (lost)


def test_local_subscribers_are_called_at_once_in_subscription_order():
    kernel = Kernel()
    bus = Bus(kernel)
    order: list[str] = []
    bus.subscribe("/t", A, lambda m, e: order.append("first"))
    bus.subscribe("/t", A, lambda m, e: order.append("second"))
    bus.publish("/t", Twist(0.0, 0.0), A)
    assert order == ["first", "second"]


def test_the_recorder_sees_every_delivery_and_drop_with_exact_times():
    kernel = Kernel()
    recorder = Recorder()
    bus = Bus(kernel, FixedDelayLink(2_500_000), tap=recorder)
    bus.subscribe("/t", A, lambda m, e: None)
    bus.subscribe("/t", B, lambda m, e: None)
    bus.subscribe("/t", C, lambda m, e: None)
    kernel.at(1_000_000, lambda: bus.publish("/t", Twist(0.0, 0.0), A))
    kernel.run(10_000_000)
    frame = messages_frame(recorder).sort_values("dst_host").reset_index(drop=True)
    assert list(frame["dst_host"]) == ["a", "b", "c"]
    assert list(frame["status"]) == ["delivered", "delivered", "lost"]
    assert list(frame["t_sent_ns"]) == [1_000_000] * 3
    assert frame["t_recv_ns"][0] == 1_000_000
    assert frame["t_recv_ns"][1] == 3_500_000
    assert frame["t_recv_ns"].isna()[2]
    assert np.isnan(frame["t_recv_s"][2])
    assert set(frame["bytes"]) == {52}
    assert recorder.counts["lost"] == 1


def test_a_message_without_subscribers_goes_nowhere():
    kernel = Kernel()
    recorder = Recorder()
    bus = Bus(kernel, tap=recorder)
    bus.publish("/nobody", Twist(0.0, 0.0), A)
    assert len(messages_frame(recorder)) == 0
    assert bus.published == 1


def test_a_monitor_sees_every_publication_without_subscribing_or_adding_a_row():
    kernel = Kernel()
    recorder = Recorder()
    bus = Bus(kernel, FixedDelayLink(5_000_000), tap=recorder)
    seen: list[tuple[str, HostId, int]] = []
    bus.monitor("/cmd", lambda topic, _m, src, t_ns: seen.append((topic, src, t_ns)))
    kernel.every(
        period_ns(10), lambda now: bus.publish("/cmd", Twist(1.0, 0.0), A), stage=Stage.CONTROL
    )
    kernel.run(300_000_000)
    assert seen == [("/cmd", A, k * 100_000_000) for k in range(3)]
    assert len(messages_frame(recorder)) == 0  # nobody subscribed: nothing crossed the bus
    got: list[tuple[int, Message, Envelope]] = []
    bus.subscribe("/cmd", B, _collect(got, kernel))
    kernel.run(400_000_000)
    assert len(seen) == 4
    assert [t for t, _, _ in got] == [305_000_000]  # the subscriber's copy crossed the link
    assert len(messages_frame(recorder)) == 1


def test_a_topic_advertised_with_two_types_is_refused():
    bus = Bus(Kernel())
    bus.advertise("/cmd", Twist)
    bus.advertise("/cmd", Twist)  # a second publisher of the same type is fine
    with pytest.raises(ValueError, match="advertised as Twist"):
        bus.advertise("/cmd", Message)
    assert list(bus.advertised()) == ["/cmd"]


class ListedDelayLink:
    """A test link: host ``h`` receives ``delays[h]`` ns after sending (None: lost)."""

    def __init__(self, delays: dict[HostId, int | None]) -> None:
        self.delays = delays

    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> Sequence[Transfer]:
        out = []
        for d in dsts:
            delay = self.delays[d]
            if delay is None:
                out.append(Transfer(d, DeliveryStatus.LOST, None))
            else:
                out.append(Transfer(d, DeliveryStatus.DELIVERED, t_ns + delay))
        return out


def test_a_broadcast_arriving_at_one_instant_is_one_kernel_event_delivered_in_link_order():
    hosts = [HostId(f"h{i}") for i in range(6)]
    delays: dict[HostId, int | None] = {h: 0 for h in hosts}
    delays[hosts[2]] = None  # lost
    delays[hosts[4]] = 3_000_000  # later
    kernel = Kernel()
    bus = Bus(kernel, ListedDelayLink(delays))
    got: list[tuple[int, str, Envelope]] = []
    for h in hosts:
        bus.subscribe("/t", h, lambda m, e, h=h: got.append((kernel.now_ns, h, e)))
    # another delivery at the same instant and stage, scheduled after the broadcast
    bus.publish("/t", Twist(0.0, 0.0), hosts[0])
    kernel.at(
        0, lambda: got.append((kernel.now_ns, "after", Envelope("", A, 0, 0))), Stage.DELIVERY
    )
    kernel.run(10_000_000)
    assert [(t, h) for t, h, _ in got] == [
        (0, "h0"),  # the publisher's own subscriber, at once
        (0, "h1"),
        (0, "h3"),
        (0, "h5"),
        (0, "after"),
        (3_000_000, "h4"),
    ]
    assert got[1][2] == Envelope("/t", hosts[0], 0, 0)
    assert got[-1][2] == Envelope("/t", hosts[0], 0, 3_000_000)
    assert kernel.events_processed == 3  # the instant's deliveries, 'after', the late one


def test_a_host_subscribing_while_a_broadcast_is_delivered_gets_it_if_it_arrives_later():
    kernel = Kernel()
    bus = Bus(kernel, ListedDelayLink({B: 0, C: 1_000}))
    got: list[str] = []

    def on_b(message: Message, envelope: Envelope) -> None:
        got.append("b")
        bus.subscribe("/t", C, lambda m, e: got.append("c late"))

    bus.subscribe("/t", B, on_b)
    bus.subscribe("/t", C, lambda m, e: got.append("c"))
    bus.publish("/t", Twist(0.0, 0.0), A)
    kernel.run(10_000)
    assert got == ["b", "c", "c late"]


def _traffic(batched: bool) -> tuple[list[tuple[int, str, str, Envelope]], list[str], object]:
    """Three topics from three hosts, local and remote subscribers, a monitor and a drop."""
    kernel = Kernel()
    recorder = Recorder()
    bus = Bus(kernel, FixedDelayLink(1_000), tap=recorder)
    got: list[tuple[int, str, str, Envelope]] = []
    seen: list[str] = []
    for topic_name, hosts in (("/x", (A, B)), ("/y", (B, C)), ("/z", ())):
        for host in hosts:
            bus.subscribe(
                topic_name, host, lambda m, e, h=host: got.append((kernel.now_ns, h, str(m), e))
            )
    bus.monitor("/y", lambda t, m, src, now: seen.append(f"{t} {m} {src} {now}"))
    topics = ["/x", "/y", "/z", "/x"]
    messages = [Twist(float(k), 0.0) for k in range(4)]
    sources = [A, A, B, C]

    def send() -> None:
        if batched:
            bus.publish_many(topics, messages, sources)
        else:
            for t, m, s in zip(topics, messages, sources, strict=True):
                bus.publish(t, m, s)

    kernel.at(5_000, send)
    kernel.run(10_000)
    return got, seen, messages_frame(recorder)


def test_publishing_many_at_once_is_publishing_each_in_turn():
    got, seen, frame = _traffic(batched=True)
    want_got, want_seen, want_frame = _traffic(batched=False)
    assert got == want_got and seen == want_seen
    assert len(got) == 5  # /x: a at once, b remote; /y: b remote (c lost); /x from c: a, b
    assert frame.equals(want_frame)


@pytest.mark.parametrize(
    ("topics", "messages", "sources"),
    [
        (["/x", "/x"], [Twist(0.0, 0.0)], [A, A]),
        (["/x"], [Twist(0.0, 0.0)], [A, B]),
        ([], [Twist(0.0, 0.0)], []),
    ],
)
def test_publishing_many_with_unmatched_lists_is_refused_before_anything_is_sent(
    topics, messages, sources
):
    kernel = Kernel()
    recorder = Recorder()
    bus = Bus(kernel, FixedDelayLink(0), tap=recorder)
    got: list[Message] = []
    bus.subscribe("/x", A, lambda m, e: got.append(m))
    bus.subscribe("/x", B, lambda m, e: got.append(m))
    with pytest.raises(ValueError, match=r"one topic and one source per message: got \d+ topics"):
        bus.publish_many(topics, messages, sources)
    kernel.run(1_000)
    assert got == [] and bus.published == 0 and sum(recorder.counts.values()) == 0


class SameTimeLink:
    """A test link delivering every copy ``delay_ns`` after sending: as one outcome or each."""

    def __init__(self, delay_ns: int, *, all_at_once: bool) -> None:
        self.delay_ns = delay_ns
        self.all_at_once = all_at_once

    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> Sequence[Transfer] | AllDelivered:
        if self.all_at_once:
            return AllDelivered(t_ns + self.delay_ns)
        return [Transfer(d, DeliveryStatus.DELIVERED, t_ns + self.delay_ns) for d in dsts]


def _broadcasts(all_at_once: bool, delay_ns: int = 1_000) -> tuple[list[object], Recorder]:
    """Broadcasts to several hosts (one reply sent on arrival), chunks of 2 rows."""
    kernel = Kernel()
    recorder = Recorder()
    bus = Bus(kernel, SameTimeLink(delay_ns, all_at_once=all_at_once), tap=recorder)
    hosts = [HostId(f"h{k}") for k in range(5)]
    got: list[object] = []
    for host in hosts:
        bus.subscribe("/x", host, lambda m, e, h=host: got.append((kernel.now_ns, h, str(m), e)))
    bus.subscribe("/y", hosts[0], lambda m, e: got.append((kernel.now_ns, "y", str(m), e)))
    bus.subscribe("/x", hosts[3], lambda m, e: bus.publish("/y", Twist(9.0, 0.0), HostId("h3")))
    kernel.at(5_000, lambda: bus.publish_many(["/x", "/x"], [Twist(1.0, 0.0)] * 2, hosts[:2]))
    kernel.at(5_000, lambda: bus.publish("/x", Twist(2.0, 0.0), hosts[4]))
    kernel.run(20_000)
    return got, recorder


def test_a_link_delivering_every_copy_at_once_delivers_and_records_as_copy_by_copy(
    monkeypatch,
):
    monkeypatch.setattr("cosim.core.recorder._FLUSH_ROWS", 2)
    got, recorder = _broadcasts(all_at_once=True)
    want_got, want = _broadcasts(all_at_once=False)
    assert got == want_got and len(got) == 18  # 3 broadcasts: 4 remote, 1 local; 3 replies
    pd.testing.assert_frame_equal(messages_frame(recorder), messages_frame(want))
    assert recorder.counts == want.counts and recorder.counts["delivered"] == 18
    assert (recorder.network_messages, recorder.network_bytes) == (
        want.network_messages,
        want.network_bytes,
    )


@pytest.mark.parametrize("all_at_once", [True, False])
def test_a_link_delivering_before_sending_is_refused_either_way(all_at_once):
    with pytest.raises(ValueError, match="before it was sent"):
        _broadcasts(all_at_once, delay_ns=-1)


# -- a topic carries the type it was advertised with -----------------------------------------
def test_a_message_of_another_type_than_advertised_is_refused_before_anyone_sees_it():
    from cosim.core.messages import NavGoal
    from cosim.core.plugins import PluginError

    kernel = Kernel()
    bus = Bus(kernel, link=FixedDelayLink(5), tap=Recorder())
    seen: list[str] = []
    bus.advertise("/cmd", Twist)
    bus.monitor("/cmd", lambda topic, message, src, t: seen.append("monitor"))
    bus.subscribe("/cmd", A, lambda message, envelope: seen.append("local"))
    bus.subscribe("/cmd", B, lambda message, envelope: seen.append("remote"))
    with pytest.raises(PluginError) as caught:
        bus.publish("/cmd", NavGoal(0, 1, 2.0, 3.0), A)
    kernel.run(1_000)
    assert seen == []
    assert caught.value.plugin is None  # the runner names it from the calling frames
    assert str(caught.value) == (
        "a plugin published a message of type cosim.core.messages.navigation.NavGoal on '/cmd', "
        "advertised as cosim.core.messages.ros.Twist; expected Twist messages only (a topic "
        "carries the one type it was advertised with) while publishing on '/cmd'"
    )


def test_publish_many_publishes_the_messages_before_one_of_the_wrong_type_and_none_after():
    from cosim.core.messages import NavGoal
    from cosim.core.plugins import PluginError

    kernel = Kernel()
    bus = Bus(kernel)
    got: list[tuple[int, Message, Envelope]] = []
    bus.advertise("/cmd", Twist)
    bus.subscribe("/cmd", A, _collect(got, kernel))
    messages: list[Message] = [Twist(1.0, 0.0), NavGoal(0, 1, 2.0, 3.0), Twist(2.0, 0.0)]
    with pytest.raises(PluginError, match=r"published a message of type .*NavGoal on '/cmd'"):
        bus.publish_many(["/cmd"] * 3, messages, [A] * 3)
    assert [m for _, m, _ in got] == [Twist(1.0, 0.0)]


def test_a_topic_advertised_after_its_first_publication_is_checked_from_then_on():
    from cosim.core.messages import NavGoal
    from cosim.core.plugins import PluginError

    bus = Bus(Kernel())
    bus.subscribe("/cmd", A, lambda message, envelope: None)
    bus.publish("/cmd", NavGoal(0, 1, 2.0, 3.0), A)  # not advertised: anything goes
    bus.advertise("/cmd", Twist)
    with pytest.raises(PluginError, match=r"advertised as cosim\.core\.messages\.ros\.Twist"):
        bus.publish("/cmd", NavGoal(0, 2, 2.0, 3.0), A)


def test_a_subclass_of_a_declared_message_is_refused_when_advertised():
    from cosim.core.plugins import PluginError

    class Padded(Twist):  # inherits Twist's declaration: its bytes and size are Twist's
        def size_bytes(self) -> int:
            return 1_000

    with pytest.raises(PluginError) as caught:
        Bus(Kernel()).advertise("/cmd", Padded)
    assert "advertised '/cmd' as tests.cosim.core.test_bus." in str(caught.value)
    assert (
        "Padded, a subclass of the declared cosim.core.messages.ros.Twist that is not declared "
        "itself; expected a message declared with cosim.core.messages.ros_message"
    ) in str(caught.value)


class OdometryAsGoals:
    """A plugin adapter sending a NavGoal on robot_1's odometry topic (Odometry) at 0.5 s."""

    name = "odometry_as_goals"
    requires = ("fleet",)

    def __init__(self, run) -> None:
        pass

    def start(self, run) -> None:
        from cosim.core.messages import NavGoal

        goal = NavGoal(0, 1, 2.0, 3.0)
        run.kernel.at(500_000_000, lambda: run.bus.publish("/robot_1/odom", goal, A))

    def finish(self, run) -> dict[str, float]:
        return {}


def test_a_plugin_publishing_the_wrong_type_in_a_run_is_refused_from_its_own_call():
    import traceback

    import cosim
    from cosim.core.plugins import PluginError
    from cosim.core.registry import registered
    from tests.conftest import SMALL

    overrides = {**SMALL, "scenario.adapters": [OdometryAsGoals.name]}
    with (
        registered("cosim.adapters", OdometryAsGoals.name, OdometryAsGoals),
        pytest.raises(PluginError) as caught,
    ):
        cosim.run(cosim.load_scenario("warehouse-random", overrides))
    line = str(caught.value)
    assert "published a message of type cosim.core.messages.navigation.NavGoal on " in line
    assert "'/robot_1/odom', advertised as cosim.core.messages.ros.Odometry; expected " in line
    assert "Odometry messages only" in line
    # the runner names the plugin from the frames the error came through: its own is there,
    # right above the bus
    frames = [frame for frame, _ in traceback.walk_tb(caught.value.__cause__.__traceback__)]
    assert [f.f_code.co_name for f in frames[-2:]] == ["publish", "publish_many"]
    assert frames[-3].f_globals["__name__"] == __name__


class WindowLink:
    """A test link that tells every fate later, as a radio simulator stepping in windows."""

    def __init__(self) -> None:
        self.waiting: list[tuple[int, int, tuple[HostId, ...]]] = []

    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> Later:
        self.waiting.append((len(self.waiting), t_ns, tuple(dsts)))
        return Later(len(self.waiting) - 1)


def test_a_fate_told_later_is_delivered_at_its_time_or_at_once_if_that_has_passed():
    kernel = Kernel()
    link = WindowLink()
    recorder = Recorder()
    bus = Bus(kernel, link, recorder)
    got: list[tuple[int, Message, Envelope]] = []
    bus.subscribe("/x", B, _collect(got, kernel))
    bus.subscribe("/x", C, _collect(got, kernel))
    kernel.at(10_000_000, lambda: bus.publish("/x", Twist(1.0, 0.0), A))
    kernel.at(20_000_000, lambda: bus.publish("/x", Twist(2.0, 0.0), A))

    def window_end() -> None:  # at 50 ms the link knows: one copy arrived at 12 ms, one will
        assert bus.unsettled() == 2
        bus.settle(0, [Transfer(B, "delivered", 12_000_000), Transfer(C, "lost", None)])
        bus.settle(1, [Transfer(B, "delivered", 70_000_000), Transfer(C, "delivered", 21_000_000)])

    kernel.at(50_000_000, window_end)
    kernel.run(100_000_000)
    assert [(t, m.linear_x_mps, e.t_sent_ns, e.t_recv_ns) for t, m, e in got] == [
        (50_000_000, 1.0, 10_000_000, 50_000_000),
        (50_000_000, 2.0, 20_000_000, 50_000_000),
        (70_000_000, 2.0, 20_000_000, 70_000_000),
    ]
    assert bus.unsettled() == 0
    rows = messages_frame(recorder)
    # the tap keeps the link's own arrival times
    assert sorted(rows.t_recv_s.dropna().round(3)) == [0.012, 0.021, 0.07]
    assert (rows.status == "lost").sum() == 1


def test_settling_an_unknown_ticket_or_other_hosts_is_refused():
    kernel = Kernel()
    bus = Bus(kernel, WindowLink())
    bus.subscribe("/x", B, lambda m, e: None)
    kernel.at(0, lambda: bus.publish("/x", Twist(1.0, 0.0), A))
    kernel.run(1)
    with pytest.raises(ValueError, match="ticket 5"):
        bus.settle(5, [])
    with pytest.raises(ValueError, match="settled it for"):
        bus.settle(0, [Transfer(C, "delivered", 1)])
