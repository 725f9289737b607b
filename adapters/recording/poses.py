"""The pose sampler: writes every robot's ground-truth pose into ``tables/poses``.

Other recorders that sample the ground truth at the same rate (the ROS interface's
``/tf`` and ``/robot_i/ground_truth``) join its tick with :meth:`PosesAdapter.on_sample`
instead of scheduling their own, so recording more adds no kernel event.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, ClassVar

from cosim.core.adapter import RunContext
from cosim.core.kernel import Stage
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S, period_ns
from cosim.scenario.sections import RecordConfig
from models.fleet.kinematics import FleetState

POSES = TableSpec(
    "poses",
    "Every robot's ground truth, sampled at record.pose_rate_hz.",
    {
        "t_s": "sample time (s)",
        "robot": "the robot",
        "x_m": "position x in map (m)",
        "y_m": "position y in map (m)",
        "yaw_rad": "heading in map (rad, counter-clockwise from x)",
        "v_mps": "forward speed (m/s)",
        "w_radps": "yaw rate (rad/s)",
    },
    categorical=("robot",),
)
POSE_COLUMNS = tuple(POSES.columns)


class PosesAdapter:
    """Samples ground-truth poses at ``record.pose_rate_hz`` (RECORD stage, one batch per tick)."""

    name: ClassVar[str] = "poses"
    requires: ClassVar[tuple[str, ...]] = ("fleet",)
    tables: ClassVar[tuple[TableSpec, ...]] = (POSES,)

    def __init__(self, run: RunContext) -> None:
        self.fleet = run.service(FleetState)
        self.table = run.recorder.table(POSES)
        self.period_ns = period_ns(run.settings(RecordConfig).pose_rate_hz)
        self._listeners: list[Callable[[int], None]] = []
        run.provide(self)

    def on_sample(self, listener: Callable[[int], None]) -> None:
        """Call ``listener(now_ns)`` after every sample (RECORD stage)."""
        self._listeners.append(listener)

    def start(self, run: RunContext) -> None:
        """Start sampling at time 0."""
        run.kernel.every(self.period_ns, self._sample, stage=Stage.RECORD)

    def _sample(self, now_ns: int) -> None:
        fleet = self.fleet
        self.table.extend(
            t_s=now_ns / NS_PER_S,
            robot=fleet.names,
            x_m=fleet.x.copy(),
            y_m=fleet.y.copy(),
            yaw_rad=fleet.yaw.copy(),
            v_mps=fleet.v.copy(),
            w_radps=fleet.w.copy(),
        )
        for listener in self._listeners:
            listener(now_ns)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Nothing to add to the summary."""
        return {}
