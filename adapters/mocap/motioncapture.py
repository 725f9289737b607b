"""``mocap.source = "motioncapture"``: a live system through the ``motioncapture`` library.

Rigid bodies of a Vicon, OptiTrack, Qualisys or VRPN system (or the library's ``mock``
backend), one per tracked robot, read by :class:`~adapters.mocap.feed.MotionCaptureFeed`
in a worker process and stamped on arrival (wall clock). By default each robot posed
from outside (a physical robot) is tracked by a rigid body of its own name.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any, ClassVar

from adapters.mocap.contract import SourceContext, Tracked, bodies_or
from adapters.mocap.feed import SYSTEMS, MotionCaptureFeed, mock_bodies
from adapters.mocap.live import LIVE_SUMMARY, PolledSource, Sample
from adapters.mocap.settings import MocapConfig
from cosim.core.adapter import RunContext
from cosim.core.summary import SummaryKey
from cosim.scenario.fields import Problem
from models.fleet.kinematics import FleetState


class MotionCaptureSource(PolledSource):
    """Rigid bodies of a live mocap system, one per tracked robot (see the module)."""

    name: ClassVar[str] = "motioncapture"
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        **LIVE_SUMMARY,
        "mocap_missing_bodies": SummaryKey("count", "tracked rigid bodies never seen in a frame"),
    }
    """The summary keys :meth:`summary` writes (documented in the summary reference)."""
    uses_dds: ClassVar[bool] = False
    keys: ClassVar[tuple[str, ...]] = ("bodies",)
    settings_hint: ClassVar[str] = "mocap.system, mocap.hostname and mocap.bodies"

    @classmethod
    def problems(cls, mocap: MocapConfig) -> Iterator[Problem]:
        """A backend the library knows, and the address of a real system."""
        if mocap.system not in SYSTEMS:
            yield Problem("system", mocap.system, f"one of {', '.join(SYSTEMS)}")
        elif mocap.system != "mock" and not mocap.hostname.strip():
            yield Problem("hostname", mocap.hostname, f"the {mocap.system} server's address")
        if any(c.isspace() for c in mocap.hostname):
            yield Problem("hostname", mocap.hostname, "an address without spaces")

    @classmethod
    def tracks(cls, mocap: MocapConfig, outside: Mapping[str, str], names: list[str]) -> Tracked:
        """``mocap.bodies``, or each robot posed from outside by a body of its name."""
        return bodies_or(mocap, outside, lambda robot: robot)

    @classmethod
    def describe(cls, mocap: MocapConfig, body: str) -> str:
        """The rigid body, the system and its host."""
        host = mocap.hostname or "no host"
        return f"rigid body {body!r} of the {mocap.system} motion capture at {host!r}"

    def __init__(self, context: SourceContext) -> None:
        super().__init__(context)
        self.body = {index: body for index, body in context.tracked}
        self.index = {body: index for index, body in context.tracked}

    def connect(self, run: RunContext) -> None:
        """Start the feed's worker (it connects on its own time)."""
        cfg = self.cfg
        options = {}
        if cfg.system == "mock":
            # a mock system holds each body where its robot starts (demos and tests)
            fleet = run.service(FleetState)
            options["rigid_bodies"] = mock_bodies(
                {body: (fleet.x[i], fleet.y[i], fleet.yaw[i]) for body, i in self.index.items()}
            )
        self.kernel = run.kernel
        self.feed = MotionCaptureFeed(
            cfg.system, hostname=cfg.hostname, bodies=list(self.index), options=options
        )

    def take(self, now_ns: int) -> list[Sample]:
        """Frames since the last poll, stamped on arrival (wall clock)."""
        sim_ns = self.kernel.sim_ns
        return [
            (self.index[body], sim_ns(t_ns), x, y, yaw)
            for t_ns, body, x, y, yaw in self.feed.drain()
            if body in self.index
        ]

    def disconnect(self) -> None:
        """Stop the feed's worker."""
        self.feed.close()

    def counts(self) -> Mapping[str, Any]:
        """Bodies never seen."""
        return {"mocap_missing_bodies": len(self.feed.missing_bodies())}

    def where(self) -> str:
        """``the vicon motion capture at '10.0.0.5'``."""
        host = f" at {self.cfg.hostname!r}" if self.cfg.hostname else ""
        return f"the {self.cfg.system} motion capture{host}"

    def failure(self) -> str | None:
        """The library's or the worker's last words, naming the system and its host."""
        failure = self.feed.failure()
        if failure is None:
            return None
        return f"{self.where()}: {failure}"

    def silence(self, index: int) -> str:
        """Not connected, connected but no frame, or frames without this robot's body."""
        feed, waited = self.feed, f"{self.waited_s:g} s"
        if not feed.connected:
            return f"{self.where()} did not answer within {waited} (no connection)"
        if feed.frames == 0:
            return f"{self.where()} accepted the connection but sent no frame within {waited}"
        occluded = f", {feed.occluded} times occluded" if feed.occluded else ""
        return (
            f"no pose of {self.names[index]} within {waited} from {self.where()}: "
            f"listened for rigid body {self.body[index]!r} ({feed.frames} frames came, none "
            f"with it{occluded})"
        )
