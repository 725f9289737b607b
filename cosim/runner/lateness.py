"""How late a real-time run kept its events: ``tables/realtime`` and its summary keys."""

from __future__ import annotations

from typing import Any

import numpy as np

from cosim.core.kernel import Lateness
from cosim.core.recorder import Recorder
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S

REALTIME = TableSpec(
    "realtime",
    "Real-time runs only: one row per batch of events due at one simulated instant.",
    {
        "t_s": "the batch's simulated instant (s)",
        "lateness_ms": "wall-clock time past the instant it was due (ms; volatile)",
        "events": "events processed in the batch",
    },
    volatile=("lateness_ms",),
    units={"events": "count"},
)


def record_lateness(lateness: Lateness, recorder: Recorder) -> dict[str, Any]:
    """Write ``tables/realtime`` (one row per event batch) and return the summary keys.

    Columns: t_s (the batch's simulated instant), lateness_ms (wall-clock ms past the
    instant it was due), events (in the batch). Wall-clock figures: volatile. A run stopped
    in the middle of a batch leaves that batch out (its events were not all counted).
    """
    batches = min(len(lateness.t_ns), len(lateness.late_ns), len(lateness.events))
    late_ms = np.frombuffer(lateness.late_ns, dtype=np.int64)[:batches] / 1e6
    table = recorder.table(REALTIME)
    table.extend(
        t_s=np.frombuffer(lateness.t_ns, dtype=np.int64)[:batches] / NS_PER_S,
        lateness_ms=late_ms,
        events=np.frombuffer(lateness.events, dtype=np.int64)[:batches],
    )
    if late_ms.size == 0:
        return {"max_lateness_ms": None, "p99_lateness_ms": None, "late_batches": 0}
    return {
        "max_lateness_ms": round(float(late_ms.max()), 3),
        "p99_lateness_ms": round(float(np.percentile(late_ms, 99)), 3),
        "late_batches": int((late_ms > 1.0).sum()),
    }
