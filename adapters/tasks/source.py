"""The task source on the base station: tasks appear, are announced, claimed, served, closed.

It opens ``tasks.initial`` tasks at pick stations (shelf faces) at the start and a new one
whenever one is completed (as in the paper), up to ``tasks.max_total``. Open tasks stand
at stations at least two footprints plus ``tasks.station_offset_m`` apart, so that their
robots never serve in each other's way; a task with no such station left waits for the
next completion. The open tasks are broadcast as a :class:`~cosim.core.messages.TaskSet`
over the network whenever they change (a new *epoch*) and every
``assignment.rebroadcast_s``. It keeps the book of claims and is the one authority on
service: a robot at a task asks for the right to serve it, and only one robot ever gets it
(see :mod:`models.tasks.book`). How claims are kept is the assignment's to say
(:mod:`adapters.tasks.contract`); with a central solver (a protocol whose ``central`` is
true, such as ``hungarian``) it also asks the solver, at every announcement, for the free
robots' tasks from their reported poses and sends each robot its order over the network.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, ClassVar

import numpy as np
from scipy import ndimage

from adapters.tasks.contract import CentralOrders, CentralSolver, claim_rules
from adapters.tasks.settings import TasksConfig
from adapters.tasks.topics import (
    CLAIMS,
    DONE,
    REPORTS,
    SERVICE_REQUESTS,
    TASKS,
    ack_topic,
    order_topic,
    reply_topic,
)
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.errors import ScenarioError
from cosim.core.hosts import BASE_HOST
from cosim.core.kernel import Stage
from cosim.core.messages import (
    Message,
    RobotState,
    ServiceReply,
    ServiceRequest,
    TaskClaim,
    TaskDone,
    TaskInfo,
    TaskOrder,
    TaskSet,
)
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S, period_ns, s_to_ns
from cosim.scenario.sections import RobotsConfig, WorldConfig
from models.fleet.kinematics import FleetState
from models.navigation.costmap import INSCRIBED, StaticCostmap
from models.tasks.book import ClaimOutcome, TaskBook, TaskStatus
from models.tasks.stations import clear_of, pick_stations
from models.world.warehouse import Warehouse

TASKS_TABLE = TableSpec(
    "tasks",
    "One row per task the source created, with its life: created, assigned, started, done.",
    {
        "task": "the task's id",
        "x_m": "its pick station's x in map (m)",
        "y_m": "its pick station's y in map (m)",
        "t_created_s": "when it appeared (s)",
        "t_assigned_s": "when a robot first claimed it (s); empty if never",
        "robot": "the robot that served it (empty if none did)",
        "t_started_s": "when the source granted that robot service, at the task (s)",
        "t_completed_s": "when the robot reported it done (s); empty if not done",
        "reassignments": "how often its claim passed from one robot to another",
    },
    categorical=("robot",),
    units={"task": "id", "reassignments": "count"},
)
TASK_COLUMNS = tuple(TASKS_TABLE.columns)
ANNOUNCE_HZ = 5.0
"""How often the source checks whether a new epoch must be announced (Hz)."""


class TaskSourceAdapter:
    """Creates, announces and closes tasks; grants service; orders of a central protocol."""

    name: ClassVar[str] = "task_source"
    requires: ClassVar[tuple[str, ...]] = ("world", "fleet", "network", "navigation")
    tables: ClassVar[tuple[TableSpec, ...]] = (TASKS_TABLE,)
    """The tables it writes (documented in the table reference)."""
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "tasks_created": SummaryKey("count", "tasks created over the run"),
        "tasks_completed": SummaryKey("count", "tasks served to the end"),
        "tasks_per_min": SummaryKey(
            "1/min", "tasks completed per minute of simulated time (null: no time ran)"
        ),
        "mean_task_latency_s": SummaryKey(
            "s",
            "time from a task's creation to its completion, mean over completed tasks (null: none)",
        ),
        "conflicts": SummaryKey(
            "count", "claims on a task another robot held (the better claim kept)"
        ),
        "services_refused": SummaryKey(
            "count", "requests to serve a task refused (not eligible, taken, claimed by another)"
        ),
        "epochs": SummaryKey("count", "task sets announced to the robots"),
    }
    """The summary keys :meth:`finish` writes (documented in the summary reference)."""

    def __init__(self, run: RunContext) -> None:
        self.cfg = run.settings(TasksConfig)
        self.rules = claim_rules(run.scenario.sections)
        world = run.service(Warehouse)
        fleet = run.service(FleetState)
        self.robots = list(fleet.names)
        self.stations = _reachable_stations(run, world, run.service(StaticCostmap), fleet)
        if not len(self.stations):
            raise ScenarioError(
                f"{run.scenario.source}: world.shelf_count = "
                f"{run.settings(WorldConfig).shelf_count}, tasks.station_offset_m = "
                f"{self.cfg.station_offset_m:g}: no pick station (a robot's spot that far from "
                "a shelf face) is free and reachable by the fleet; expected shelves with "
                "room in front of them (tasks are served at shelves)"
            )
        self.apart_m = 2.0 * run.settings(RobotsConfig).radius_m + self.cfg.station_offset_m
        """Least distance between two stations with open tasks (m): two footprints, the space."""
        self.owed = 0
        """Tasks not opened for want of a clear station, opened at the next completion."""
        self.central = self.rules.central
        self.rng = run.rng.stream("tasks")
        self.book = TaskBook(
            self.robots, s_to_ns(self.rules.claim_timeout_s), self.rules.preemption
        )
        self.next_id = 0
        self.epoch = 0
        self.dirty = True
        self.last_announce_ns = -(1 << 62)
        self.poses: dict[str, tuple[float, float]] = {}
        self.solver: CentralSolver | None = None
        self.orders: dict[str, tuple[int, float]] = {}
        run.provide(self)
        run.bus.advertise(TASKS, TaskSet)
        for robot in self.robots:
            run.bus.advertise(reply_topic(robot), ServiceReply)
            run.bus.advertise(ack_topic(robot), TaskDone)
            if self.central:
                run.bus.advertise(order_topic(robot), TaskOrder)

    # -- life of tasks ---------------------------------------------------------------
    def start(self, run: RunContext) -> None:
        """Open the first tasks and start announcing."""
        bus = run.bus
        bus.subscribe(CLAIMS, BASE_HOST, self._handler(run, self._on_claim))
        bus.subscribe(SERVICE_REQUESTS, BASE_HOST, self._handler(run, self._on_request))
        bus.subscribe(DONE, BASE_HOST, self._handler(run, self._on_done))
        self.solver = run.service(CentralOrders).solver if self.central else None
        if self.central:
            bus.subscribe(REPORTS, BASE_HOST, self._handler(run, self._on_report))
        for _ in range(self.cfg.initial):
            self._create(run)
        run.kernel.every(
            period_ns(ANNOUNCE_HZ), lambda now: self._announce(run, now), stage=Stage.CONTROL
        )
        run.kernel.every(s_to_ns(1.0), lambda now: self._expire(run, now), stage=Stage.CONTROL)

    def _handler(
        self, run: RunContext, fn: Callable[[RunContext, Any], None]
    ) -> Callable[[Message, Envelope], None]:
        def handle(message: Message, _envelope: Envelope) -> None:
            fn(run, message)

        return handle

    def _create(self, run: RunContext) -> None:
        cap = self.cfg.max_total
        if cap and self.next_id >= cap:
            return
        used = [(t.x_m, t.y_m) for t in self.book.tasks.values() if t.status is not TaskStatus.DONE]
        free = np.flatnonzero(clear_of(self.stations, np.array(used), self.apart_m))
        if not len(free):
            self.owed += 1
            return
        x, y, _ = self.stations[free[int(self.rng.integers(len(free)))]]
        eligible = frozenset(self._eligible())
        task = self.book.create(self.next_id, float(x), float(y), eligible, run.kernel.now_ns)
        self.next_id += 1
        self.dirty = True
        run.recorder.event(
            run.kernel.now_ns,
            "task_source",
            "task",
            f"task {task.task_id} at "
            f"({task.x_m:.2f}, {task.y_m:.2f}), {len(eligible)} robots eligible",
        )

    def _eligible(self) -> list[str]:
        p = self.cfg.eligibility_prob
        while True:
            draws = self.rng.random(len(self.robots))
            chosen = [name for name, u in zip(self.robots, draws, strict=True) if u < p]
            if chosen:  # a task nobody may serve would never be served
                return chosen

    def _announce(self, run: RunContext, now_ns: int) -> None:
        due = now_ns - self.last_announce_ns >= s_to_ns(self.rules.rebroadcast_s)
        if not (self.dirty or due):
            return
        if self.dirty:
            self.epoch += 1
            self.dirty = False
        if self.solver is not None:
            # re-solved at every announcement: robot poses arrive over time
            self._solve_centrally(self.solver)
        self.last_announce_ns = now_ns
        tasks = tuple(
            TaskInfo(
                t.task_id,
                t.x_m,
                t.y_m,
                tuple(sorted(t.eligible, key=self.robots.index)),
                self.book.holder(t),
            )
            for t in self.book.offered()
        )
        run.bus.publish(TASKS, TaskSet(now_ns, self.epoch, tasks), BASE_HOST)
        for robot, (task_id, cost) in self.orders.items():
            order = TaskOrder(now_ns, self.epoch, robot, task_id, cost)
            run.bus.publish(order_topic(robot), order, BASE_HOST)

    def _expire(self, run: RunContext, now_ns: int) -> None:
        for task_id in self.book.expire(now_ns):
            self.dirty = True
            run.recorder.event(now_ns, "task_source", "claim_expired", f"task {task_id}")

    # -- messages from robots ----------------------------------------------------------
    def _on_claim(self, run: RunContext, claim: TaskClaim) -> None:
        now = run.kernel.now_ns
        if claim.state == "release":
            if self.book.release(claim.task_id, claim.robot):
                self.dirty = True
            return
        outcome = self.book.claim(claim.task_id, claim.robot, claim.cost_m, now)
        if outcome in (ClaimOutcome.REPLACED, ClaimOutcome.REJECTED):
            self.dirty = True  # robots decided differently: let them solve again
        if outcome in (ClaimOutcome.REPLACED, ClaimOutcome.REJECTED):
            run.recorder.event(
                now,
                "task_source",
                "conflict",
                f"task {claim.task_id}: {claim.robot} {outcome.value}",
            )

    def _on_request(self, run: RunContext, request: ServiceRequest) -> None:
        now = run.kernel.now_ns
        granted = self.book.request_service(request.task_id, request.robot, now)
        reply = ServiceReply(now, request.task_id, request.robot, granted)
        run.bus.publish(reply_topic(request.robot), reply, BASE_HOST)

    def _on_done(self, run: RunContext, done: TaskDone) -> None:
        now = run.kernel.now_ns
        # acknowledge every report (the robot repeats it until acknowledged)
        run.bus.publish(ack_topic(done.robot), TaskDone(now, done.task_id, done.robot), BASE_HOST)
        if self.book.done(done.task_id, done.robot, now):
            run.recorder.event(now, "task_source", "done", f"task {done.task_id} by {done.robot}")
            self.dirty = True
            owed, self.owed = self.owed + 1, 0
            for _ in range(owed):
                self._create(run)

    def _on_report(self, run: RunContext, state: RobotState) -> None:
        self.poses[state.robot] = (state.x_m, state.y_m)

    # -- a central solver ------------------------------------------------------------------
    def _solve_centrally(self, solver: CentralSolver) -> None:
        """The solver's orders for the robots whose pose the base knows and are free."""
        held = {t.task_id: self.book.holder(t) for t in self.book.offered()}
        tasks = [
            TaskInfo(t.task_id, t.x_m, t.y_m, tuple(sorted(t.eligible, key=self.robots.index)), "")
            for t in self.book.offered()
            if not held[t.task_id]
        ]
        busy = {holder for holder in held.values() if holder}
        poses = {r: self.poses[r] for r in self.robots if r in self.poses and r not in busy}
        self.orders = {r: order for r, order in self.orders.items() if r in busy}
        self.orders.update(solver.orders(tasks, poses))

    # -- records ---------------------------------------------------------------------------
    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """The tasks table and the task metrics."""
        table = run.recorder.table(TASKS_TABLE)
        completed = []
        for task in sorted(self.book.tasks.values(), key=lambda t: t.task_id):
            table.append(
                task=task.task_id,
                x_m=task.x_m,
                y_m=task.y_m,
                t_created_s=_s(task.created_ns),
                t_assigned_s=_s(task.assigned_ns),
                robot=task.server or "",
                t_started_s=_s(task.started_ns),
                t_completed_s=_s(task.completed_ns),
                reassignments=task.reassignments,
            )
            if task.status is TaskStatus.DONE:
                completed.append((task.completed_ns - task.created_ns) / NS_PER_S)
        minutes = run.kernel.now_ns / NS_PER_S / 60.0
        return {
            "tasks_created": len(self.book.tasks),
            "tasks_completed": len(completed),
            "tasks_per_min": round(len(completed) / minutes, 6) if minutes > 0 else None,
            "mean_task_latency_s": round(float(np.mean(completed)), 6) if completed else None,
            "conflicts": self.book.conflicts,
            "services_refused": self.book.refused_services,
            "epochs": self.epoch,
        }


def _s(t_ns: int) -> float:
    return t_ns / NS_PER_S if t_ns >= 0 else float("nan")


def _reachable_stations(
    run: RunContext, world: Warehouse, static: StaticCostmap, fleet: FleetState
) -> np.ndarray:
    """Pick stations where a robot can stand clear of everything and the fleet can reach."""
    stations = pick_stations(
        world.shelves,
        run.settings(RobotsConfig).radius_m,
        run.settings(TasksConfig).station_offset_m,
        world.is_free,
    )
    labels, _ = ndimage.label(static.cost < INSCRIBED, structure=np.ones((3, 3)))
    regions = {
        labels[static.world_to_cell((x, y))[::-1]] for x, y in zip(fleet.x, fleet.y, strict=True)
    }
    keep = []
    for x, y, _ in stations:
        cell = static.world_to_cell((x, y))
        keep.append(static.in_bounds(cell) and labels[cell[1], cell[0]] in regions - {0})
    return stations[np.array(keep, dtype=bool)] if len(stations) else stations
