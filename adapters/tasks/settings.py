"""The ``[tasks]`` section: pick tasks at the shelves, created over time."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import ClassVar

from cosim.scenario.fields import Problem, param


@dataclass(frozen=True)
class TasksConfig:
    """``[tasks]``: pick tasks at the shelves, created over time by the task source.

    As in the paper, a new task appears whenever one is completed.
    """

    ORDER: ClassVar[int] = 70
    """Where the section comes in a resolved scenario and in the adapters' order."""

    initial: int = param(4, "tasks open at the start", ge=1, le=100_000, unit="count")
    max_total: int = param(
        0, "tasks created over the run, 0 = unlimited", ge=0, le=10_000_000, unit="count"
    )
    eligibility_prob: float = param(
        1.0,
        "probability that a robot may serve a task (ChoiRbot's example uses a subset)",
        gt=0,
        le=1,
    )
    dwell_s: float = param(2.0, "time a robot spends at a task to serve it (s)", ge=0)
    station_offset_m: float = param(
        0.25,
        "pick stations: free space between the footprint and the shelf face (m); a robot "
        "serves a shelf within reach of it; open tasks stand two footprints plus this apart",
        gt=0,
        le=5.0,
    )

    def problems(self) -> Iterator[Problem]:
        """A cap below the initial tasks would never be reached."""
        if 0 < self.max_total < self.initial:
            yield Problem("max_total", self.max_total, f"0 or at least initial ({self.initial})")
