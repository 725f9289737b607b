"""What a run records for ROS 2 tools, set up after assembly and closed after the kernel.

:class:`RecordingPlan` says where the bag goes and whether the run is served live; it is
decided before the run so that every problem (an unknown topic pattern, a taken port)
is found before anything is written. :class:`RecordingSession` opens the sinks, taps the
bus and closes everything, even when the run fails or is interrupted: the bag is then
complete up to that moment.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from adapters.unity.server import UnityOptions, UnitySink
from cosim.core.bus import Advertisement, Bus
from cosim.recording.bag import BAG_DIR, BagSink
from cosim.recording.foxglove import LiveOptions, LiveSink
from cosim.recording.schemas import channel_specs
from cosim.recording.selection import select_topics
from cosim.recording.tap import RecordingTap, Sink
from cosim.scenario.model import Scenario


@dataclass(frozen=True)
class RecordingPlan:
    """Where a run's recording goes.

    Attributes:
        bag: the bag directory, or None for no bag.
        storage: ``"mcap"`` or ``"sqlite3"``.
        compression: ``"zstd"`` or ``"none"``.
        live: the live view's options, or None.
        unity: the Unity endpoint's options (``--unity``), or None.
    """

    bag: Path | None = None
    storage: str = "mcap"
    compression: str = "zstd"
    live: LiveOptions | None = None
    unity: UnityOptions | None = None

    @property
    def active(self) -> bool:
        """Whether anything is recorded or served."""
        return self.bag is not None or self.live is not None or self.unity is not None

    @property
    def realtime(self) -> bool:
        """Whether the run is served as it goes, so paced by the wall clock."""
        return self.live is not None or self.unity is not None

    @classmethod
    def for_run(
        cls,
        scenario: Scenario,
        out: Path | None,
        live: LiveOptions | None = None,
        unity: UnityOptions | None = None,
    ) -> RecordingPlan:
        """The bag in ``out/bag`` per ``record.bag`` (none without a folder), the live servers."""
        record = scenario.record
        bag = out / BAG_DIR if out is not None and record.bag != "none" else None
        return cls(bag, record.bag, record.compression, live, unity)


@dataclass
class RecordingSession:
    """The sinks of a run and the tap feeding them.

    Args:
        plan: what to record.
        topics: the selected topics (:meth:`topics_of`).
        bus: the run's bus.
    """

    plan: RecordingPlan
    topics: Mapping[str, Advertisement]
    bus: Bus
    bag: BagSink | None = field(init=False, default=None)
    live: LiveSink | None = field(init=False, default=None)
    unity: UnitySink | None = field(init=False, default=None)
    tap: RecordingTap | None = field(init=False, default=None)
    _closed: bool = field(init=False, default=False)

    @staticmethod
    def topics_of(scenario: Scenario, bus: Bus) -> dict[str, Advertisement]:
        """The advertised topics ``record.topics`` keeps.

        Raises:
            ConfigError: a pattern matches no topic of the run.
        """
        return select_topics(scenario.record.topics, bus.advertised(), origin=scenario.source)

    def open(self, *, before_bag: Callable[[], None] | None = None) -> None:
        """Start the live servers, create the bag and tap the bus.

        Args:
            before_bag: called once the live server listens and before the bag exists (the
                run folder is prepared there, so a taken port leaves it untouched).

        Raises:
            BridgeError: the live view or the Unity endpoint cannot listen on its port.
            ExportError: the bag cannot be created.
        """
        channels = channel_specs(self.topics)
        opened: list[Sink] = []
        try:
            if self.plan.live is not None:
                self.live = LiveSink(self.plan.live)
                self.live.open(channels)
                opened.append(self.live)
            if self.plan.unity is not None:
                self.unity = UnitySink(self.plan.unity, self.bus)
                self.unity.open(channels)
                opened.append(self.unity)
            if before_bag is not None:
                before_bag()
            if self.plan.bag is not None:
                self.bag = BagSink(
                    self.plan.bag, storage=self.plan.storage, compression=self.plan.compression
                )
                self.bag.open(channels)
                opened.append(self.bag)
        except BaseException:
            for sink in opened:
                sink.close()
            raise
        self.tap = RecordingTap(self.bus, channels, opened)

    def close(self) -> None:
        """Finish the bag and stop the live server (once; the counts stay)."""
        if self.tap is not None and not self._closed:
            self._closed = True
            self.tap.close()

    def counts(self) -> dict[str, int]:
        """Messages recorded per topic."""
        return self.tap.message_counts() if self.tap is not None else {}

    def summary(self) -> dict[str, int]:
        """What the live servers add to the run's summary (Unity's connections and frames)."""
        return self.unity.summary() if self.unity is not None else {}
