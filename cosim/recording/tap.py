"""The recording tap: bus publications, serialized once, fanned out to the bag and the live view.

It monitors the selected topics on the bus (:meth:`cosim.core.bus.Bus.monitor`), so a recorded
run delivers, drops and tabulates exactly what an unrecorded one does. Each publication
is encoded to CDR once (:meth:`cosim.core.messages.Message.to_cdr`) and handed to every sink
with its publication time in simulation nanoseconds, which is also the message's log
time: stamps in a bag equal the simulation clock.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

from cosim.core.bus import Bus, Monitor
from cosim.core.hosts import HostId
from cosim.core.messages import Message
from cosim.recording.schemas import ChannelSpec


class Sink(Protocol):
    """Where recorded messages go (a bag, a live view)."""

    def open(self, channels: Sequence[ChannelSpec]) -> None:
        """Prepare the channels; message ``channel`` arguments index this list."""
        ...

    def write(self, channel: int, t_ns: int, data: bytes, src: str) -> None:
        """Take one CDR-encoded message published by host ``src`` at ``t_ns`` (simulation ns)."""
        ...

    def close(self) -> None:
        """Finish: nothing is written after this."""
        ...


class RecordingTap:
    """Connects the selected topics of a bus to sinks.

    Args:
        bus: the run's bus, its adapters constructed (topics advertised).
        channels: the recorded topics (:func:`cosim.recording.schemas.channel_specs`).
        sinks: the sinks, already opened with ``channels``.
    """

    def __init__(self, bus: Bus, channels: Sequence[ChannelSpec], sinks: Sequence[Sink]) -> None:
        self.channels = list(channels)
        self.sinks = list(sinks)
        self.counts = [0] * len(self.channels)
        for index, spec in enumerate(self.channels):
            bus.monitor(spec.topic, self._monitor(index))

    def _monitor(self, index: int) -> Monitor:
        writes: list[Callable[[int, int, bytes, str], None]] = [s.write for s in self.sinks]
        counts = self.counts

        def record(_topic: str, message: Message, src: HostId, t_ns: int) -> None:
            data = message.to_cdr()
            counts[index] += 1
            for write in writes:
                write(index, t_ns, data, src)

        return record

    def close(self) -> None:
        """Close every sink (the first error is raised once all were tried)."""
        first: Exception | None = None
        for sink in self.sinks:
            try:
                sink.close()
            except Exception as error:  # close the others before reporting
                first = first or error
        if first is not None:
            raise first

    def message_counts(self) -> dict[str, int]:
        """Messages recorded per topic."""
        return {spec.topic: count for spec, count in zip(self.channels, self.counts, strict=True)}
