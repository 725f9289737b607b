"""``mocap.source = "simulated"``: a Vicon-like system measuring the simulated robots.

The ``mocap`` host samples the ground truth of the tracked robots (``mocap.robots``, or
all) at ``mocap.rate_hz`` (SENSING stage), adds Gaussian noise, drops bodies from frames
with probability ``mocap.dropout`` and sends each frame ``mocap.latency_ms`` after the
instant it shows, stamped with that instant (:mod:`models.mocap.sampling`). The robots
drive by their commands as usual; their software localizes by these poses.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from adapters.mocap.contract import SourceContext, Tracked, all_robots_or
from adapters.mocap.settings import MocapConfig
from cosim.core.adapter import RunContext
from cosim.core.kernel import Stage
from cosim.core.rng import BlockDraws
from cosim.core.timebase import ms_to_ns, period_ns
from models.fleet.kinematics import FleetState
from models.mocap.sampling import MocapParams, measure


class SimulatedSource:
    """Noisy, late, sometimes missing poses of the simulated robots (see the module)."""

    name: ClassVar[str] = "simulated"
    external: ClassVar[bool] = False
    live: ClassVar[bool] = False
    uses_dds: ClassVar[bool] = False
    keys: ClassVar[tuple[str, ...]] = ("robots",)

    @classmethod
    def tracks(cls, mocap: MocapConfig, outside: Mapping[str, str], names: list[str]) -> Tracked:
        """``mocap.robots``, or every robot."""
        return all_robots_or(mocap, names)

    @classmethod
    def describe(cls, mocap: MocapConfig, body: str) -> str:
        """The simulated system."""
        return "the simulated motion capture"

    def __init__(self, context: SourceContext) -> None:
        run, cfg = context.run, context.mocap
        self.intake = context.intake
        self.records = context.records
        self.fleet = run.service(FleetState)
        self.tracked = [index for index, _ in context.tracked]
        names = self.fleet.names
        self._normals = BlockDraws(
            [run.rng.stream(f"mocap/{names[i]}") for i in self.tracked], width=3
        )
        self._uniforms = BlockDraws(
            [run.rng.stream(f"mocap/dropout/{names[i]}") for i in self.tracked],
            width=1,
            kind="uniform",
        )
        self.params = MocapParams(
            rate_hz=cfg.rate_hz,
            latency_ms=cfg.latency_ms,
            noise_std_m=cfg.noise_std_m,
            noise_std_rad=cfg.noise_std_rad,
            dropout=cfg.dropout,
        )
        self.period_ns = period_ns(cfg.rate_hz)
        self.latency_ns = ms_to_ns(cfg.latency_ms)

    def start(self, run: RunContext) -> None:
        """Sample a frame every ``1 / mocap.rate_hz``."""
        self.kernel = run.kernel
        run.kernel.every(self.period_ns, self._frame, stage=Stage.SENSING)

    def _frame(self, now_ns: int) -> None:
        fleet = self.fleet
        idx = self.tracked
        truth = np.stack([fleet.x[idx], fleet.y[idx], fleet.yaw[idx]], axis=1)
        normals = np.asarray(self._normals.draw(), dtype=np.float64)
        uniforms = np.asarray(self._uniforms.draw()[:, 0], dtype=np.float64)
        m = measure(truth, normals, uniforms, self.params)
        self.records.count("dropouts", int((~m.seen).sum()))
        frame = [
            (idx[k], float(x), float(y), float(yaw))
            for k, ((x, y, yaw), seen) in enumerate(
                zip(m.poses.tolist(), m.seen.tolist(), strict=True)
            )
            if seen
        ]
        if not frame:
            return
        if self.latency_ns == 0:
            self._send(frame, now_ns)
        else:
            self.kernel.at(
                now_ns + self.latency_ns, lambda: self._send(frame, now_ns), stage=Stage.SENSING
            )

    def _send(self, frame: list[tuple[int, float, float, float]], stamp_ns: int) -> None:
        submit = self.intake.submit
        for index, x, y, yaw in frame:
            submit(index, stamp_ns, x, y, yaw, mirror=False)

    def close(self) -> None:
        """Nothing to disconnect."""

    def summary(self) -> Mapping[str, Any]:
        """Nothing of its own (dropouts are in the mocap records)."""
        return {}
