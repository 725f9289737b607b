"""What the humans adapter records: ``tables/humans``, near misses, stops, summary keys.

``tables/humans`` has one row per person (or forklift) and sample: t_s, id, kind
(``person`` | ``forklift``), x_m, y_m, yaw_rad (``map``), speed_mps, at ``humans.record_hz``
(at most one per SUMO step). Near misses and stops caused by people are events
(``near_miss``, ``stopped_by_person``) with the person's id and the clearance.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from adapters.humans.settings import HumansConfig
from adapters.tasks.source import TaskSourceAdapter
from cosim.core.adapter import RunContext
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S, period_ns
from models.fleet.kinematics import FleetState
from models.humans.encounters import HALT_MPS, Encounters
from models.tasks.book import TaskStatus

if TYPE_CHECKING:
    from adapters.humans.crowd import People

_WITH_TASKS = "robots serve tasks (task_source runs)"
HUMANS_SUMMARY: Mapping[str, SummaryKey] = {
    "humans_tasks_met_people": SummaryKey(
        "count",
        "completed tasks whose robot had a near miss or a stop caused by people while serving them",
        when=_WITH_TASKS,
    ),
    "humans_task_latency_met_people_s": SummaryKey(
        "s", "mean task latency of those tasks (null: none)", when=_WITH_TASKS
    ),
    "humans_task_latency_clear_s": SummaryKey(
        "s", "mean task latency of the other completed tasks (null: none)", when=_WITH_TASKS
    ),
    "humans_seen": SummaryKey("count", "people and forklifts that took part at some time"),
    "humans_min_distance_m": SummaryKey(
        "m", "smallest distance between a robot and a person, footprint to footprint (null: none)"
    ),
    "humans_near_misses": SummaryKey(
        "count", "times a robot and a person came closer than humans.near_miss_m"
    ),
    "humans_robot_stops": SummaryKey(
        "count", "times a robot halted with a person within humans.stop_radius_m"
    ),
    "humans_collisions": SummaryKey("count", "contacts between a robot and a person or forklift"),
    "humans_collisions_robot_moving": SummaryKey(
        "count", "of those, contacts while the robot was driving"
    ),
}
"""The summary keys :meth:`HumanRecords.summary` writes."""

HUMANS = TableSpec(
    "humans",
    "Every person and forklift SUMO moves, sampled at humans.record_hz.",
    {
        "t_s": "sample time (s)",
        "id": "SUMO's id of the person or vehicle",
        "kind": "person or forklift",
        "x_m": "position x in map (m)",
        "y_m": "position y in map (m)",
        "yaw_rad": "heading in map (rad)",
        "speed_mps": "speed (m/s)",
    },
    categorical=("id", "kind"),
)
HUMAN_COLUMNS = tuple(HUMANS.columns)
PEOPLE_KINDS = ("person", "forklift")


class HumanRecords:
    """Samples people into the table and keeps the robot-person encounter metrics."""

    def __init__(self, run: RunContext, cfg: HumansConfig) -> None:
        self.fleet = run.service(FleetState)
        self.recorder = run.recorder
        self.table = run.recorder.table(HUMANS)
        self.encounters = Encounters(cfg.near_miss_m, cfg.stop_radius_m)
        self.record_ns = period_ns(cfg.record_hz)
        self.next_record_ns = 0
        self.near_misses = 0
        self.stops = 0
        self.robot_stops = np.zeros(len(self.fleet), dtype=np.int64)
        self.seen: set[str] = set()
        self.met: dict[str, list[int]] = {name: [] for name in self.fleet.names}
        """Per robot, the instants of its near misses and stops caused by people (ns)."""

    def sample(self, now_ns: int, people: People) -> None:
        """Take the people at ``now_ns`` into the table and the metrics."""
        t_s = now_ns / NS_PER_S
        if now_ns >= self.next_record_ns and people.names:
            n = len(people.names)
            self.table.extend(
                t_s=np.full(n, t_s),
                id=people.names,
                kind=people.kinds,
                x_m=people.x_m,
                y_m=people.y_m,
                yaw_rad=people.yaw_rad,
                speed_mps=people.speed_mps,
            )
            self.next_record_ns = now_ns + self.record_ns
        self.seen.update(people.names)
        fleet = self.fleet
        robots = np.column_stack([fleet.x, fleet.y, fleet.radius_m])
        began, stops = self.encounters.update(robots, fleet.v, people.discs, people.disc_names)
        for e in began + stops:
            self.met[fleet.names[e.robot]].append(now_ns)
        for e in began:
            self.near_misses += 1
            self.recorder.event(
                now_ns, fleet.names[e.robot], "near_miss", f"{e.person} at {e.clearance_m:.2f} m"
            )
        for e in stops:
            self.stops += 1
            self.robot_stops[e.robot] += 1
            self.recorder.event(
                now_ns,
                fleet.names[e.robot],
                "stopped_by_person",
                f"{e.person} at {e.clearance_m:.2f} m",
            )

    def _task_latencies(self, run: RunContext) -> dict[str, Any]:
        """Mean task latency (creation to completion, s) with and without people on the way.

        A task met people when its robot had a near miss or a stop caused by people between
        the task's assignment and its completion.
        """
        if not run.has_service(TaskSourceAdapter):
            return {}
        met: list[float] = []
        clear: list[float] = []
        for task in run.service(TaskSourceAdapter).book.tasks.values():
            if task.status is not TaskStatus.DONE or not task.server:
                continue
            latency = (task.completed_ns - task.created_ns) / NS_PER_S
            times = self.met.get(task.server, [])
            hit = any(task.assigned_ns <= t <= task.completed_ns for t in times)
            (met if hit else clear).append(latency)

        def mean(values: list[float]) -> float | None:
            return round(float(np.mean(values)), 6) if values else None

        return {
            "humans_tasks_met_people": len(met),
            "humans_task_latency_met_people_s": mean(met),
            "humans_task_latency_clear_s": mean(clear),
        }

    def summary(self, run: RunContext) -> dict[str, Any]:
        """Minimum distance, near misses, stops and contacts with people."""
        least = self.encounters.min_clearance_m
        contacts = driving = 0
        table = run.recorder.tables.get("collisions")
        if table is not None and len(table):
            people = np.isin(table.column("kind"), list(PEOPLE_KINDS))
            contacts = int(people.sum())
            driving = int((np.abs(table.column("speed_mps")[people]) >= HALT_MPS).sum())
        return {
            **self._task_latencies(run),
            "humans_seen": len(self.seen),
            "humans_min_distance_m": round(least, 4) if np.isfinite(least) else None,
            "humans_near_misses": self.near_misses,
            "humans_robot_stops": self.stops,
            "humans_collisions": contacts,
            # the robot was driving; the others are people walking into a robot at rest
            "humans_collisions_robot_moving": driving,
        }
