"""The recording tap: each publication of a recorded topic encoded once, handed to every sink."""

from __future__ import annotations

from collections.abc import Sequence

import pytest

from cosim.core.bus import Bus, TopicQos
from cosim.core.hosts import HostId
from cosim.core.kernel import Kernel
from cosim.core.messages import Clock, Message, Twist
from cosim.recording.schemas import ChannelSpec, channel_specs
from cosim.recording.tap import RecordingTap

A, B = HostId("robot_1"), HostId("base")


class ListSink:
    """A sink that keeps what it is given."""

    def __init__(self, fail_on_close: Exception | None = None) -> None:
        self.channels: list[ChannelSpec] = []
        self.written: list[tuple[int, int, bytes, str]] = []
        self.closed = False
        self.fail_on_close = fail_on_close

    def open(self, channels: Sequence[ChannelSpec]) -> None:
        self.channels = list(channels)

    def write(self, channel: int, t_ns: int, data: bytes, src: str) -> None:
        self.written.append((channel, t_ns, data, src))

    def close(self) -> None:
        self.closed = True
        if self.fail_on_close is not None:
            raise self.fail_on_close


def _bus() -> tuple[Kernel, Bus]:
    kernel = Kernel()
    bus = Bus(kernel)
    bus.advertise("/robot_1/cmd_vel", Twist, TopicQos.DEFAULT)
    bus.advertise("/clock", Clock, TopicQos.DEFAULT)
    bus.advertise("/unrecorded", Twist, TopicQos.SENSOR)
    return kernel, bus


def _tap(bus: Bus, *sinks: ListSink) -> RecordingTap:
    advertised = bus.advertised()
    channels = channel_specs({t: advertised[t] for t in ("/robot_1/cmd_vel", "/clock")})
    for sink in sinks:
        sink.open(channels)
    return RecordingTap(bus, channels, sinks)


def _publish_at(kernel: Kernel, bus: Bus, t_ns: int, topic: str, message: Message, src: HostId):
    kernel.at(t_ns, lambda: bus.publish(topic, message, src))


def test_every_sink_gets_each_recorded_publication_as_cdr_at_its_simulation_time():
    kernel, bus = _bus()
    first, second = ListSink(), ListSink()
    tap = _tap(bus, first, second)
    _publish_at(kernel, bus, 100_000_000, "/robot_1/cmd_vel", Twist(0.5, -0.1), A)
    _publish_at(kernel, bus, 200_000_007, "/clock", Clock(200_000_007), B)
    kernel.run(1_000_000_000)
    expected = [
        (0, 100_000_000, Twist(0.5, -0.1).to_cdr(), "robot_1"),
        (1, 200_000_007, Clock(200_000_007).to_cdr(), "base"),
    ]
    assert first.written == expected and second.written == expected
    assert tap.message_counts() == {"/robot_1/cmd_vel": 1, "/clock": 1}


def test_a_topic_not_selected_is_not_recorded_and_a_silent_one_counts_zero():
    kernel, bus = _bus()
    sink = ListSink()
    tap = _tap(bus, sink)
    _publish_at(kernel, bus, 0, "/unrecorded", Twist(1.0, 0.0), A)
    _publish_at(kernel, bus, 1, "/robot_1/cmd_vel", Twist(1.0, 0.0), A)
    _publish_at(kernel, bus, 2, "/robot_1/cmd_vel", Twist(0.0, 0.0), A)
    kernel.run(10)
    assert [channel for channel, *_ in sink.written] == [0, 0]
    assert tap.message_counts() == {"/robot_1/cmd_vel": 2, "/clock": 0}


def test_recording_changes_nothing_that_subscribers_receive():
    received: dict[bool, list[tuple[int, Message]]] = {}
    for recorded in (False, True):
        kernel, bus = _bus()
        got: list[tuple[int, Message]] = []
        bus.subscribe("/robot_1/cmd_vel", B, lambda m, e, got=got: got.append((e.t_recv_ns, m)))
        if recorded:
            _tap(bus, ListSink())
        for k in range(3):
            _publish_at(kernel, bus, k * 1000, "/robot_1/cmd_vel", Twist(0.1 * k, 0.0), A)
        kernel.run(10_000)
        received[recorded] = got
    assert received[True] == received[False] and len(received[True]) == 3


def test_closing_closes_every_sink_and_raises_the_first_error_after_trying_all():
    _, bus = _bus()
    sinks = [ListSink(OSError("disk full")), ListSink(ValueError("second")), ListSink()]
    tap = _tap(bus, *sinks)
    with pytest.raises(OSError, match="disk full"):
        tap.close()
    assert all(sink.closed for sink in sinks)


def test_a_tap_without_sinks_still_counts_what_it_would_record():
    kernel, bus = _bus()
    tap = _tap(bus)
    _publish_at(kernel, bus, 0, "/clock", Clock(0), B)
    kernel.run(10)
    tap.close()
    assert tap.message_counts()["/clock"] == 1
