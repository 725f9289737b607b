"""Motion-capture records: ``tables/mocap`` rows and the summary counts.

Rows are the exceptions, not the stream: rejected poses (a jump beyond what the robot can
drive, a stamp out of order, a sample that is not a pose), a robot's poses leaving the
world and coming back (one row each way, however many poses fell outside), and the robots
stopped because their newest pose was too old, and when they got a fresh one again.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping
from typing import Any

from cosim.core.adapter import RunContext
from cosim.core.summary import SummaryKey
from cosim.core.table import Table, TableSpec
from cosim.core.timebase import NS_PER_S

MOCAP = TableSpec(
    "mocap",
    "Measured poses rejected, and robots whose poses went stale or fresh again.",
    {
        "t_s": "when (s)",
        "robot": "the robot",
        "event": "jump, out_of_order or invalid (a pose rejected), off_map (the first of "
        "the poses outside the world, all rejected) or on_map (back inside), stale or fresh",
        "detail": "the particulars (the jump's size, the pose's age, ...)",
    },
    categorical=("robot", "event"),
)
MOCAP_COLUMNS = tuple(MOCAP.columns)

MOCAP_SUMMARY: Mapping[str, SummaryKey] = {
    "mocap_poses": SummaryKey("count", "measured poses accepted and published"),
    "mocap_dropouts": SummaryKey(
        "count", "bodies missing from a frame (simulated source: mocap.dropout)"
    ),
    "mocap_rejected_jumps": SummaryKey(
        "count", "poses rejected as a jump beyond what the robot can drive"
    ),
    "mocap_rejected_out_of_order": SummaryKey("count", "poses rejected as stamped out of order"),
    "mocap_invalid": SummaryKey("count", "samples rejected as no pose (NaN, not finite)"),
    "mocap_rejected_off_map": SummaryKey("count", "poses rejected as outside the world"),
    "mocap_stale_stops": SummaryKey(
        "count", "robots stopped because their newest pose was older than mocap.max_age_ms"
    ),
}
"""The summary keys :meth:`MocapRecords.summary` writes (once, to the first adapter that
asks: ``mocap``, or ``physical`` when no mocap adapter runs)."""

EVENTS = ("jump", "out_of_order", "invalid", "off_map", "on_map", "stale", "fresh")
"""The events of ``tables/mocap``."""


class MocapRecords:
    """The ``mocap`` table and counters, shared by the pose source and the robots' software.

    Get it with :meth:`of`, whichever adapter asks first creates it.
    """

    def __init__(self, run: RunContext) -> None:
        self.table: Table = run.recorder.table(MOCAP)
        self.counts: Counter[str] = Counter()
        self._reported = False

    @classmethod
    def of(cls, run: RunContext) -> MocapRecords:
        """The run's records, created on first use."""
        if not run.has_service(cls):
            run.provide(cls(run))
        return run.service(cls)

    def row(self, t_ns: int, robot: str, event: str, detail: str = "") -> None:
        """Record one event (one of :data:`EVENTS`)."""
        if event not in EVENTS:
            raise ValueError(f"unknown mocap event {event!r}; expected one of {EVENTS}")
        self.table.append(t_s=t_ns / NS_PER_S, robot=robot, event=event, detail=detail)
        self.counts[event] += 1

    def count(self, key: str, n: int = 1) -> None:
        """Count something that gets no row (poses published, dropouts)."""
        self.counts[key] += n

    def summary(self) -> dict[str, Any]:
        """``mocap_*`` summary keys; only to the first adapter that asks (they are shared)."""
        if self._reported:
            return {}
        self._reported = True
        c = self.counts
        return {
            "mocap_poses": c["poses"],
            "mocap_dropouts": c["dropouts"],
            "mocap_rejected_jumps": c["jump"],
            "mocap_rejected_out_of_order": c["out_of_order"],
            "mocap_invalid": c["invalid"],
            "mocap_rejected_off_map": c["off_map_poses"],
            "mocap_stale_stops": c["stale"],
        }
