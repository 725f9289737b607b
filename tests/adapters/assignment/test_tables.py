import math
from dataclasses import dataclass, field

import numpy as np
import pytest

from adapters.assignment.dta import DtaAdapter
from adapters.assignment.tables import ASSIGNMENT_COLUMNS, ASSIGNMENTS, DtaRecords
from cosim.core.recorder import Recorder
from cosim.recording.dataframes import table_frame
from models.assignment.problem import AssignmentProblem

INF = math.inf
NAMES = ["robot_1", "robot_2"]
COSTS = np.array([[1.0, 10.0], [2.0, 3.0]])
"""Two robots, two tasks: the optimum is robot_1 -> task 0, robot_2 -> task 1 (4 m)."""


@dataclass
class Agent:
    """What the records read of a robot's protocol agent."""

    choice: dict[int, int] = field(default_factory=dict)
    rounds: int = 1
    decided: bool = True
    objective: float = 0.0

    def view(self) -> dict[int, int]:
        return self.choice

    def cost(self) -> float:
        return self.objective


def own_row(costs: np.ndarray, robot: int) -> AssignmentProblem:
    """A robot's view of the problem: its own row, inf elsewhere."""
    view = np.full_like(costs, INF)
    view[robot] = costs[robot]
    return AssignmentProblem(tuple(NAMES), (10, 11), view)


def records(compare: bool = True) -> DtaRecords:
    return DtaRecords(Recorder(), NAMES, compare=compare)


def see(rec: DtaRecords, costs: np.ndarray, epoch: int = 1, at_ns: tuple[int, int] = (0, 0)):
    for robot in (0, 1):
        rec.epoch_seen(robot, epoch, at_ns[robot], own_row(costs, robot))


def test_the_assignments_table_has_the_documented_columns():
    assert ASSIGNMENTS.name == "assignments"
    assert ASSIGNMENT_COLUMNS == (
        "epoch",
        "t_s",
        "robot",
        "round",
        "basis_changed",
        "cost",
        "converged",
        "messages",
        "bytes",
    )
    assert ASSIGNMENTS.columns["t_s"].endswith("(s)")
    assert "(m" in ASSIGNMENTS.columns["cost"]
    assert set(ASSIGNMENTS.categorical) == {"robot"} <= set(ASSIGNMENTS.columns)
    assert set(ASSIGNMENTS.volatile) <= set(ASSIGNMENTS.columns)
    assert ASSIGNMENTS in DtaAdapter.tables


def test_each_round_is_a_row_with_the_messages_and_bytes_sent_so_far_in_the_epoch():
    rec = records()
    see(rec, COSTS, epoch=3)
    rec.round(100_000_000, 0, 3, Agent(rounds=1, decided=False, objective=12.0), True, 40)
    rec.round(200_000_000, 0, 3, Agent(rounds=2, decided=True, objective=4.0), False, 0)
    rec.round(200_000_000, 1, 3, Agent(rounds=1, decided=False, objective=5.0), True, 60)
    rec.round(300_000_000, 0, 9, Agent(rounds=1), True, 80)  # an epoch it never saw
    rows = table_frame(rec.table)
    assert list(rows.epoch) == [3, 3, 3, 9]
    assert list(rows.t_s) == [0.1, 0.2, 0.2, 0.3]
    assert list(rows.robot) == ["robot_1", "robot_1", "robot_2", "robot_1"]
    assert list(rows["round"]) == [1, 2, 1, 1]
    assert list(rows.basis_changed) == [True, False, True, True]
    assert list(rows.cost) == [12.0, 4.0, 5.0, 0.0]
    assert list(rows.converged) == [False, True, False, True]
    assert list(rows.messages) == [1, 1, 1, 0]  # a round that sent nothing adds nothing
    assert list(rows.bytes) == [40, 40, 60, 0]


def test_an_epoch_converges_when_every_robot_decided_timed_from_the_first_announcement():
    rec = records()
    see(rec, COSTS, at_ns=(100_000_000, 50_000_000))
    rec.decided(0, 1, 300_000_000, Agent({0: 0}, rounds=3))
    assert rec.convergence_s == []  # robot_2 has not decided
    rec.decided(1, 1, 450_000_000, Agent({1: 1}, rounds=4))
    assert rec.convergence_s == [pytest.approx(0.4)]
    assert rec.rounds_to_decide == [3, 4]
    assert rec.gaps == [0.0]
    rec.decided(1, 1, 900_000_000, Agent({1: 1}, rounds=9))  # changed its mind: counted once
    assert rec.convergence_s == [pytest.approx(0.4)] and rec.rounds_to_decide == [3, 4]


def test_a_fleet_assignment_worse_than_the_optimum_is_its_relative_gap():
    rec = records()
    see(rec, COSTS)
    rec.decided(0, 1, 1, Agent({0: 1}))
    rec.decided(1, 1, 2, Agent({1: 0}))
    assert rec.gaps == [pytest.approx((12.0 - 4.0) / 4.0)]
    assert rec.summary()["optimality_gap"] == pytest.approx(2.0)


def test_conflicting_views_go_to_the_cheaper_robot_and_a_task_left_unserved_is_incomplete():
    rec = records()
    see(rec, COSTS)
    rec.decided(0, 1, 1, Agent({0: 0}))
    rec.decided(1, 1, 2, Agent({1: 0}))  # both on task 0: robot_1 is cheaper, task 1 unserved
    assert rec.gaps == [] and rec.incomplete == 1
    assert rec.summary()["epochs_incomplete"] == 1


def test_views_that_pick_a_task_a_robot_cannot_serve_give_no_gap():
    costs = np.array([[1.0, 5.0], [INF, 2.0]])
    rec = records()
    see(rec, costs)
    rec.decided(0, 1, 1, Agent({0: 1}))
    rec.decided(1, 1, 2, Agent({1: 0}))
    assert rec.gaps == [] and rec.incomplete == 0 and len(rec.convergence_s) == 1


def test_a_robot_that_can_take_no_task_is_not_waited_for():
    costs = np.array([[1.0, 10.0], [INF, INF]])  # robot_2 is busy
    rec = records()
    see(rec, costs)
    rec.decided(0, 1, 200_000_000, Agent({0: 0}))
    assert rec.convergence_s == [0.2]
    assert rec.gaps == [0.0]


def test_an_epoch_is_not_settled_before_every_robot_has_seen_it():
    rec = records()
    rec.epoch_seen(0, 1, 0, own_row(COSTS, 0))
    rec.decided(0, 1, 1, Agent({0: 0}))
    assert rec.convergence_s == []
    rec.decided(1, 1, 2, Agent({1: 1}))  # robot_2 decided on an epoch it never announced
    assert rec.convergence_s == []


def test_without_comparison_convergence_is_timed_but_no_gap_computed():
    rec = records(compare=False)
    see(rec, COSTS)
    rec.decided(0, 1, 1, Agent({0: 1}))
    rec.decided(1, 1, 2, Agent({1: 0}))
    assert len(rec.convergence_s) == 1 and rec.gaps == [] and rec.incomplete == 0


def test_releases_and_conflicts_are_events_and_counted():
    recorder = Recorder()
    rec = DtaRecords(recorder, NAMES)
    rec.released(1_000, 1, 7, "stuck")
    rec.conflict(2_000, 0, 3, "robot_2")
    events = table_frame(recorder.events)
    assert list(events.source) == ["robot_2", "robot_1"]
    assert list(events.kind) == ["release", "conflict"]
    assert list(events.detail) == ["task 7: stuck", "task 3 goes to robot_2"]
    summary = rec.summary()
    assert (summary["claims_released"], summary["conflicts_seen_by_robots"]) == (1, 1)


def test_a_run_without_epochs_reports_none_for_its_means():
    assert records().summary() == {
        "mean_convergence_time_s": None,
        "mean_rounds": None,
        "optimality_gap": None,
        "epochs_compared": 0,
        "epochs_incomplete": 0,
        "conflicts_seen_by_robots": 0,
        "claims_released": 0,
    }
