"""The task source on the base station, driven over the bus as robots would drive it."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pytest

import cosim
from adapters.tasks.contract import CentralOrders
from adapters.tasks.source import TASK_COLUMNS, TASKS_TABLE, TaskSourceAdapter
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
from cosim.core.errors import ScenarioError
from cosim.core.hosts import HostId
from cosim.core.messages import (
    Message,
    RobotState,
    ServiceRequest,
    TaskClaim,
    TaskDone,
    TaskInfo,
    TaskSet,
)
from cosim.core.timebase import s_to_ns
from cosim.runner.assembly import assemble
from models.world.warehouse import Warehouse
from tests.conftest import SMALL

ROBOTS = ["robot_1", "robot_2", "robot_3"]


class Source:
    """A small warehouse's task source, its requirements built, nothing else driving robots."""

    def __init__(self, **overrides: Any) -> None:
        settings = {**SMALL, "robots.driver": "tasks", **overrides}
        self.scenario = cosim.load_scenario("warehouse-random", settings)
        assembly = assemble(self.scenario, names=["task_source"])
        self.run = assembly.run
        self.adapters = assembly.adapters
        source = dict(assembly.adapters)["task_source"]
        assert isinstance(source, TaskSourceAdapter)
        self.source = source
        self.heard: dict[str, list[tuple[int, Message]]] = {}
        topics = [TASKS] + [f(r) for r in ROBOTS for f in (reply_topic, ack_topic, order_topic)]
        for topic in topics:
            self.run.bus.monitor(topic, self._keep)

    def _keep(self, topic: str, message: Message, _src: HostId, t_ns: int) -> None:
        self.heard.setdefault(topic, []).append((t_ns, message))

    def start(self) -> None:
        for _name, adapter in self.adapters:
            adapter.start(self.run)

    def at(self, t_s: float, topic: str, message: Message, robot: str) -> None:
        """Publish ``message`` from ``robot``'s host at ``t_s``."""
        publish = self.run.bus.publish
        self.run.kernel.at(s_to_ns(t_s), lambda: publish(topic, message, HostId(robot)))

    def until(self, t_s: float) -> None:
        self.run.kernel.run(s_to_ns(t_s))

    def sets(self) -> list[tuple[float, TaskSet]]:
        return [(t / 1e9, m) for t, m in self.heard.get(TASKS, []) if isinstance(m, TaskSet)]

    def last_set(self) -> TaskSet:
        return self.sets()[-1][1]

    def finish(self) -> Mapping[str, Any]:
        return self.source.finish(self.run)


def _claim(task: int, robot: str, cost: float, state: str = "claim") -> TaskClaim:
    return TaskClaim(0, 1, task, robot, cost, state)


def _holders(task_set: TaskSet) -> dict[int, str]:
    return {t.task_id: t.holder for t in task_set.tasks}


def test_the_tasks_table_declares_its_columns_with_units_in_map_and_seconds():
    assert TASKS_TABLE.name == "tasks" and TaskSourceAdapter.tables == (TASKS_TABLE,)
    assert "(m)" in TASKS_TABLE.columns["x_m"] and "map" in TASKS_TABLE.columns["x_m"]
    for column in TASK_COLUMNS:
        if column.startswith("t_"):
            assert column.endswith("_s") and "(s)" in TASKS_TABLE.columns[column], column
    assert set(TASKS_TABLE.categorical) <= set(TASKS_TABLE.columns) and not TASKS_TABLE.volatile


def test_the_first_tasks_are_opened_at_distinct_free_pick_stations_and_announced_at_once():
    s = Source()
    s.start()
    s.until(0.1)
    [(t_s, first)] = s.sets()
    assert (t_s, first.epoch) == (0.0, 1)
    assert [t.task_id for t in first.tasks] == [0, 1, 2, 3]  # tasks.initial
    assert all(t.eligible == tuple(ROBOTS) and t.holder == "" for t in first.tasks)
    spots = {(t.x_m, t.y_m) for t in first.tasks}
    assert len(spots) == 4
    stations = {(float(x), float(y)) for x, y, _ in s.source.stations}
    assert spots <= stations
    world = s.run.service(Warehouse)
    radius = s.scenario.robots.radius_m
    assert world.is_free(np.array(sorted(spots)), radius).all()


def test_an_unchanged_task_set_is_sent_again_every_rebroadcast_s_in_the_same_epoch():
    s = Source(**{"assignment.rebroadcast_s": 0.4})
    s.start()
    s.until(1.3)
    sets = s.sets()
    assert [t for t, _ in sets] == [0.0, 0.4, 0.8, 1.2]
    assert {m.epoch for _, m in sets} == {1}


def _events(s: Source, kind: str) -> list[str]:
    events = s.run.recorder.events.columns()
    return [d for k, d in zip(events["kind"], events["detail"], strict=True) if k == kind]


def test_an_accepted_claim_is_announced_with_its_holder_in_the_same_epoch():
    # robots agreed on it: nothing to solve again, the next set shows who holds the task
    s = Source()
    s.start()
    s.at(0.3, CLAIMS, _claim(2, "robot_3", 4.0), "robot_3")
    s.until(1.1)
    assert [(t, m.epoch, _holders(m)[2]) for t, m in s.sets()] == [
        (0.0, 1, ""),
        (1.0, 1, "robot_3"),
    ]


def test_a_conflicting_claim_goes_to_the_cheaper_robot_and_starts_a_new_epoch_at_once():
    s = Source()
    s.start()
    s.at(0.1, CLAIMS, _claim(1, "robot_1", 9.0), "robot_1")
    s.at(0.3, CLAIMS, _claim(1, "robot_2", 3.0), "robot_2")  # replaces robot_1's
    s.at(0.5, CLAIMS, _claim(1, "robot_3", 5.0), "robot_3")  # rejected
    s.until(0.7)
    assert [(t, m.epoch, _holders(m)[1]) for t, m in s.sets()] == [
        (0.0, 1, ""),
        (pytest.approx(0.4), 2, "robot_2"),  # the next 5 Hz check
        (pytest.approx(0.6), 3, "robot_2"),
    ]
    assert _events(s, "conflict") == ["task 1: robot_2 replaced", "task 1: robot_3 rejected"]
    assert s.finish()["conflicts"] == 2


def test_a_released_claim_frees_the_task_in_a_new_epoch():
    s = Source()
    s.start()
    s.at(0.1, CLAIMS, _claim(0, "robot_1", 2.0), "robot_1")
    s.at(0.5, CLAIMS, _claim(0, "robot_1", 2.0, "release"), "robot_1")
    s.at(0.7, CLAIMS, _claim(0, "robot_2", 2.0, "release"), "robot_2")  # held nothing
    s.until(1.1)
    assert [(t, m.epoch, _holders(m)[0]) for t, m in s.sets()] == [
        (0.0, 1, ""),
        (pytest.approx(0.6), 2, ""),
    ]


def test_a_claim_not_repeated_for_its_timeout_is_released():
    s = Source(**{"assignment.claim_timeout_s": 1.0})
    s.start()
    s.at(0.1, CLAIMS, _claim(0, "robot_1", 2.0), "robot_1")
    s.until(1.5)
    assert _holders(s.last_set())[0] == "robot_1"  # 0.9 s old at the check at 1 s
    s.until(2.5)
    assert (s.last_set().epoch, _holders(s.last_set())[0]) == (2, "")
    assert _events(s, "claim_expired") == ["task 0"]


def test_a_repeated_claim_is_kept():
    s = Source(**{"assignment.claim_timeout_s": 1.0})
    s.start()
    for t_s in (0.1, 0.8, 1.5, 2.2):
        s.at(t_s, CLAIMS, _claim(0, "robot_1", 2.0), "robot_1")
    s.until(3.1)
    assert _holders(s.last_set())[0] == "robot_1"
    assert _events(s, "claim_expired") == []


def test_exactly_one_robot_is_granted_service_of_a_task():
    s = Source()
    s.start()
    s.at(0.1, CLAIMS, _claim(3, "robot_2", 1.0), "robot_2")
    s.at(0.2, SERVICE_REQUESTS, ServiceRequest(0, 3, "robot_1"), "robot_1")
    s.at(0.3, SERVICE_REQUESTS, ServiceRequest(0, 3, "robot_2"), "robot_2")
    s.at(0.4, SERVICE_REQUESTS, ServiceRequest(0, 3, "robot_3"), "robot_3")
    s.until(0.5)
    granted = {
        robot: [m.granted for _, m in s.heard.get(reply_topic(robot), [])] for robot in ROBOTS
    }
    assert sum(g.count(True) for g in granted.values()) == 1
    assert all(len(g) == 1 for g in granted.values())  # every request answered, to its robot
    assert s.finish()["services_refused"] == 2


def test_a_task_done_is_acknowledged_every_time_and_replaced_by_a_new_one():
    s = Source()
    s.start()
    s.at(0.1, CLAIMS, _claim(0, "robot_1", 1.0), "robot_1")
    s.at(0.2, SERVICE_REQUESTS, ServiceRequest(0, 0, "robot_1"), "robot_1")
    s.at(1.0, DONE, TaskDone(0, 0, "robot_1"), "robot_1")
    s.at(1.1, DONE, TaskDone(0, 0, "robot_1"), "robot_1")  # the ack was lost: said again
    s.until(1.5)
    acks = s.heard[ack_topic("robot_1")]
    assert [(m.task_id, m.robot) for _, m in acks] == [(0, "robot_1"), (0, "robot_1")]
    assert [t.task_id for t in s.last_set().tasks] == [1, 2, 3, 4]
    summary = s.finish()
    assert (summary["tasks_created"], summary["tasks_completed"]) == (5, 1)
    assert summary["mean_task_latency_s"] == pytest.approx(1.0)


def test_the_tasks_table_has_a_row_per_task_with_its_life_in_seconds():
    s = Source()
    s.start()
    s.at(0.1, CLAIMS, _claim(0, "robot_1", 1.0), "robot_1")
    s.at(0.2, SERVICE_REQUESTS, ServiceRequest(0, 0, "robot_1"), "robot_1")
    s.at(1.0, DONE, TaskDone(0, 0, "robot_1"), "robot_1")
    s.until(1.5)
    s.finish()
    table = s.run.recorder.tables[TASKS_TABLE.name].columns()
    assert tuple(table) == TASK_COLUMNS
    assert list(table["task"]) == [0, 1, 2, 3, 4]
    first = {key: table[key][0] for key in TASK_COLUMNS}
    assert (first["t_created_s"], first["t_assigned_s"]) == (0.0, pytest.approx(0.1))
    assert (first["t_started_s"], first["t_completed_s"]) == (pytest.approx(0.2), 1.0)
    assert first["robot"] == "robot_1" and first["reassignments"] == 0
    assert math.isnan(table["t_completed_s"][1]) and table["robot"][1] == ""
    assert table["t_created_s"][4] == 1.0


def test_no_more_tasks_are_created_than_max_total():
    s = Source(**{"tasks.initial": 2, "tasks.max_total": 2})
    s.start()
    s.at(0.1, SERVICE_REQUESTS, ServiceRequest(0, 0, "robot_1"), "robot_1")
    s.at(0.2, DONE, TaskDone(0, 0, "robot_1"), "robot_1")
    s.until(0.5)
    assert [t.task_id for t in s.last_set().tasks] == [1]
    assert s.finish()["tasks_created"] == 2


def test_open_tasks_stand_two_footprints_and_the_free_space_apart():
    s = Source(**{"tasks.initial": 8})
    s.start()
    s.until(0.1)
    spots = np.array([(t.x_m, t.y_m) for t in s.last_set().tasks])
    apart = 2 * s.scenario.robots.radius_m + s.scenario.tasks.station_offset_m
    gaps = np.hypot(*(spots[:, None, :] - spots[None, :, :]).transpose(2, 0, 1))
    assert len(spots) >= 2 and gaps[np.triu_indices(len(spots), 1)].min() >= apart


def test_tasks_with_no_clear_station_left_wait_for_the_next_completion():
    s = Source(**{"tasks.initial": 30})
    s.start()
    s.until(0.1)
    opened = len(s.last_set().tasks)
    assert opened < 30 and s.source.owed == 30 - opened
    first = s.last_set().tasks[0].task_id
    s.at(0.2, SERVICE_REQUESTS, ServiceRequest(0, first, "robot_1"), "robot_1")
    s.at(0.3, DONE, TaskDone(0, first, "robot_1"), "robot_1")
    s.until(0.5)
    # the done task's station is clear again: one of the owed tasks (or its own) opens
    assert len(s.last_set().tasks) == opened and s.source.owed == 30 - opened


def test_every_task_may_be_served_by_at_least_one_robot_whatever_the_eligibility():
    s = Source(**{"tasks.eligibility_prob": 0.05, "tasks.initial": 6})
    s.start()
    s.until(0.1)
    tasks = s.last_set().tasks
    assert len(tasks) == 6
    assert all(1 <= len(t.eligible) <= 3 and set(t.eligible) <= set(ROBOTS) for t in tasks)
    assert any(len(t.eligible) < 3 for t in tasks)


def test_the_same_seed_opens_the_same_tasks_and_another_seed_others():
    def spots(seed: int) -> list[tuple[float, float]]:
        s = Source(**{"scenario.seed": seed})
        s.start()
        s.until(0.1)
        return [(t.x_m, t.y_m) for t in s.last_set().tasks]

    assert spots(3) == spots(3)
    assert spots(3) != spots(4)


def test_a_world_without_a_reachable_pick_station_is_refused_naming_the_keys():
    with pytest.raises(ScenarioError) as refused:
        Source(**{"world.shelf_count": 0})
    message = str(refused.value)
    assert "world.shelf_count = 0, tasks.station_offset_m = 0.25: no pick station" in message
    assert "expected shelves with room in front of them" in message


class Nearest:
    """A central solver: each free robot reported takes the first open task."""

    def __init__(self) -> None:
        self.asked: list[tuple[list[int], dict[str, tuple[float, float]]]] = []

    def orders(
        self, tasks: Sequence[TaskInfo], poses: Mapping[str, tuple[float, float]]
    ) -> dict[str, tuple[int, float]]:
        self.asked.append(([t.task_id for t in tasks], dict(poses)))
        return {robot: (tasks[k].task_id, 1.5) for k, robot in enumerate(sorted(poses))}


def test_a_central_solver_orders_the_free_robots_the_base_heard_from():
    s = Source(**{"assignment.protocol": "hungarian"})
    solver = Nearest()
    s.run.provide(CentralOrders(solver))
    s.start()
    report = RobotState(0, "robot_2", 3.0, 4.0, 0.0, 0.0, 0.3)
    s.at(0.1, REPORTS, report, "robot_2")
    s.until(1.1)
    assert solver.asked[0] == ([0, 1, 2, 3], {})  # at t = 0: no report yet
    assert ([0, 1, 2, 3], {"robot_2": (3.0, 4.0)}) in solver.asked
    orders = [(m.robot, m.task_id, m.cost_m) for _, m in s.heard[order_topic("robot_2")]]
    assert orders and set(orders) == {("robot_2", 0, 1.5)}
    assert order_topic("robot_1") not in s.heard
