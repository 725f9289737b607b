"""A motion-capture source: an RTK GNSS receiver on every robot (outdoors, or a big hall).

Each robot's receiver fixes its position ``gnss.rate_hz`` times a second with Gaussian
noise ``gnss.noise_std_m`` per axis and the heading of a dual-antenna set-up with
``gnss.noise_std_rad``; every fix goes through the pose intake from the ``mocap`` host
like any measured pose. With ``mocap.source = "gnss"`` it is one class registered in
``cosim.mocap_sources`` and its own settings section, nothing else.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

from adapters.mocap.contract import SourceContext, Tracked
from adapters.mocap.settings import MocapConfig
from cosim.core.adapter import RunContext
from cosim.core.kernel import Stage
from cosim.core.summary import SummaryKey
from cosim.core.timebase import period_ns
from cosim.scenario.fields import param
from models.fleet.kinematics import FleetState


@dataclass(frozen=True)
class GnssSettings:
    """``[gnss]``: the source ``mocap.source = "gnss"``."""

    rate_hz: float = param(10.0, "fixes per second (Hz)", gt=0, le=100)
    noise_std_m: float = param(0.02, "position noise per axis (m)", ge=0)
    noise_std_rad: float = param(0.01, "heading noise (rad)", ge=0)


class GnssSource:
    """An RTK GNSS fix of every robot (see the module)."""

    name: ClassVar[str] = "gnss"
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "gnss_fixes": SummaryKey("count", "position fixes taken, every robot's"),
    }
    external: ClassVar[bool] = False
    live: ClassVar[bool] = False
    uses_dds: ClassVar[bool] = False

    @classmethod
    def tracks(cls, mocap: MocapConfig, outside: Mapping[str, str], names: list[str]) -> Tracked:
        """Every robot carries a receiver."""
        return [(robot, "") for robot in names]

    @classmethod
    def describe(cls, mocap: MocapConfig, body: str) -> str:
        """The robot's receiver."""
        return "the robot's GNSS receiver"

    def __init__(self, context: SourceContext) -> None:
        self.settings = context.run.settings(GnssSettings)
        self.intake = context.intake
        self.fleet = context.run.service(FleetState)
        self.tracked = [index for index, _ in context.tracked]
        self.rng = context.run.rng.stream("gnss")
        self.fixes = 0

    def start(self, run: RunContext) -> None:
        """A fix of every robot every ``1 / gnss.rate_hz``."""
        run.kernel.every(period_ns(self.settings.rate_hz), self._fix, stage=Stage.SENSING)

    def _fix(self, now_ns: int) -> None:
        s, fleet = self.settings, self.fleet
        noise = self.rng.normal(size=(len(self.tracked), 3))
        for k, index in enumerate(self.tracked):
            x = float(fleet.x[index] + s.noise_std_m * noise[k, 0])
            y = float(fleet.y[index] + s.noise_std_m * noise[k, 1])
            yaw = float(fleet.yaw[index] + s.noise_std_rad * noise[k, 2])
            self.intake.submit(index, now_ns, x, y, yaw, mirror=False)
        self.fixes += len(self.tracked)

    def close(self) -> None:
        """Nothing to disconnect."""

    def summary(self) -> Mapping[str, Any]:
        """Fixes taken."""
        return {"gnss_fixes": self.fixes}
