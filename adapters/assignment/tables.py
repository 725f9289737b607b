"""Records of dynamic task assignment: ``tables/assignments`` and the protocol summary.

Per epoch, the recorder keeps what each robot decided and when. Once every robot that could
take a task has decided in an epoch (robots busy with a task have nothing to decide), the
epoch's instance (every robot's own cost row) is solved centrally with the Hungarian method
and the fleet's assignment is compared with that optimum: the optimality gap. Epochs in which
the fleet serves fewer tasks than the optimum (robots halted on partial information) are
counted as incomplete instead of adding big-M terms to the gap. Robots only
ever see their own row; this is bookkeeping for the analysis. Greedy robots decide alone,
and their first choices collide before claims sort them out, so no gap is computed for
greedy (its conflicts are its measure).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from adapters.assignment.contract import ProtocolAgent
from cosim.core.recorder import Recorder
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S
from models.assignment.problem import AssignmentProblem, hungarian, objective

ASSIGNMENTS = TableSpec(
    "assignments",
    "One row per protocol round of a robot that had not decided, or whose state changed.",
    {
        "epoch": "the epoch (the task set the round works on)",
        "t_s": "when (s)",
        "robot": "the robot",
        "round": "the robot's rounds in this epoch so far",
        "basis_changed": "whether the robot's protocol state changed in the round",
        "cost": "the robot's view of the assignment's objective (m, big-M terms included)",
        "converged": "whether the robot's protocol has decided",
        "messages": "protocol messages the robot has sent in this epoch",
        "bytes": "bytes of those messages",
    },
    categorical=("robot",),
    units={"epoch": "id", "round": "count", "cost": "m", "messages": "count", "bytes": "bytes"},
)
ASSIGNMENT_COLUMNS = tuple(ASSIGNMENTS.columns)


@dataclass
class _Epoch:
    start_ns: int
    rows: dict[int, np.ndarray] = field(default_factory=dict)
    problem: AssignmentProblem | None = None
    decided_ns: dict[int, int] = field(default_factory=dict)
    views: dict[int, dict[int, int]] = field(default_factory=dict)
    rounds: dict[int, int] = field(default_factory=dict)
    messages: dict[int, int] = field(default_factory=dict)
    nbytes: dict[int, int] = field(default_factory=dict)
    closed: bool = False
    takers: frozenset[int] | None = None  # robots with a finite cost, once every row is in


DTA_SUMMARY: Mapping[str, SummaryKey] = {
    "mean_convergence_time_s": SummaryKey(
        "s",
        "time from an epoch's announcement until every robot that could take a task had "
        "decided, mean over decided epochs (null: none)",
    ),
    "mean_rounds": SummaryKey(
        "count", "protocol rounds a robot took to decide an epoch, mean (null: none decided)"
    ),
    "optimality_gap": SummaryKey(
        "ratio",
        "excess of the robots' assignment cost over the central optimum of the same "
        "instance (0.1: 10 % costlier), mean over compared epochs (null: none compared)",
    ),
    "epochs_compared": SummaryKey("count", "epochs whose decisions were compared with the optimum"),
    "epochs_incomplete": SummaryKey(
        "count",
        "epochs where robots halted on partial information and left tasks the optimum "
        "serves (left out of the gap)",
    ),
    "conflicts_seen_by_robots": SummaryKey(
        "count", "times a robot saw another robot's better claim on its task and gave way"
    ),
    "claims_released": SummaryKey("count", "times a robot gave its task up"),
}
"""The summary keys :meth:`DtaRecords.summary` writes."""


class DtaRecords:
    """The assignments table and the statistics behind the DTA summary."""

    def __init__(self, recorder: Recorder, names: list[str], *, compare: bool = True) -> None:
        self.table = recorder.table(ASSIGNMENTS)
        self.recorder = recorder
        self.names = names
        self.epochs: dict[int, _Epoch] = {}
        self.convergence_s: list[float] = []
        self.rounds_to_decide: list[int] = []
        self.gaps: list[float] = []
        self.conflicts_seen = 0
        self.releases = 0
        self.incomplete = 0
        self.compare = compare

    def epoch_seen(
        self, robot: int, epoch: int, announced_ns: int, problem: AssignmentProblem
    ) -> None:
        """A robot starts working on ``epoch`` with its own cost row.

        Args:
            robot: fleet index of the robot.
            epoch: the epoch it received.
            announced_ns: send time of the copy of the task set it received (ns). The epoch
                starts at the earliest such time: convergence is measured from the source's
                announcement, so network latency counts, as it does for the fleet.
            problem: the robot's view of the problem (its own row filled).
        """
        record = self.epochs.setdefault(epoch, _Epoch(announced_ns))
        record.start_ns = min(record.start_ns, announced_ns)
        record.rows[robot] = np.array(problem.cost[robot])
        record.takers = None
        if record.problem is None:
            record.problem = problem

    def round(
        self,
        now_ns: int,
        robot: int,
        epoch: int,
        protocol: ProtocolAgent,
        changed: bool,
        nbytes: int,
    ) -> None:
        """One protocol round of a robot."""
        record = self.epochs.get(epoch)
        if record is not None and nbytes:
            record.messages[robot] = record.messages.get(robot, 0) + 1
            record.nbytes[robot] = record.nbytes.get(robot, 0) + nbytes
        self.table.append(
            epoch=epoch,
            t_s=now_ns / NS_PER_S,
            robot=self.names[robot],
            round=protocol.rounds,
            basis_changed=changed,
            cost=protocol.cost(),
            converged=protocol.decided,
            messages=record.messages.get(robot, 0) if record else 0,
            bytes=record.nbytes.get(robot, 0) if record else 0,
        )

    def decided(self, robot: int, epoch: int, now_ns: int, protocol: ProtocolAgent) -> None:
        """A robot's protocol decided (or changed its decision) in ``epoch``."""
        record = self.epochs.get(epoch)
        if record is None:
            return
        first = robot not in record.decided_ns
        record.decided_ns[robot] = now_ns
        record.views[robot] = protocol.view()
        record.rounds[robot] = protocol.rounds
        if first:
            self.rounds_to_decide.append(protocol.rounds)
        if first and not record.closed and self._settled(record):
            record.closed = True
            self._close(record)

    def _settled(self, record: _Epoch) -> bool:
        """Every robot has seen the epoch, and every robot that could take a task decided."""
        if len(record.rows) != len(self.names):
            return False
        if record.takers is None:
            record.takers = frozenset(i for i, row in record.rows.items() if np.isfinite(row).any())
        takers = record.takers
        return bool(takers) and all(i in record.decided_ns for i in takers)

    def _close(self, record: _Epoch) -> None:
        takers = [t for i, t in record.decided_ns.items() if np.isfinite(record.rows[i]).any()]
        self.convergence_s.append((max(takers) - record.start_ns) / NS_PER_S)
        if record.problem is None or not self.compare:
            return
        base = record.problem
        cost = np.vstack([record.rows[i] for i in range(len(self.names))])
        problem = AssignmentProblem(base.robots, base.tasks, cost, base.unserved_cost)
        best, optimum = hungarian(problem)
        found = _fleet_assignment(record.views, cost)
        if len(found) < len(best):
            # robots halted on partial information (lost or late bases) and leave tasks
            # the optimum serves: counted apart, not folded into the gap through big-M terms
            self.incomplete += 1
            return
        try:
            value = objective(problem, found)
        except ValueError:  # views that still disagree: no gap for this epoch
            return
        if optimum > 0 and math.isfinite(value):
            self.gaps.append((value - optimum) / optimum)

    def released(self, now_ns: int, robot: int, task: int, why: str) -> None:
        """A robot gave its task up."""
        self.releases += 1
        self.recorder.event(now_ns, self.names[robot], "release", f"task {task}: {why}")

    def conflict(self, now_ns: int, robot: int, task: int, winner: str) -> None:
        """A robot saw another robot's better claim on its task and gave way."""
        self.conflicts_seen += 1
        self.recorder.event(now_ns, self.names[robot], "conflict", f"task {task} goes to {winner}")

    def summary(self) -> dict[str, Any]:
        """Assignment metrics for ``summary.json``."""
        return {
            "mean_convergence_time_s": _mean(self.convergence_s),
            "mean_rounds": _mean([float(r) for r in self.rounds_to_decide]),
            "optimality_gap": _mean(self.gaps),
            "epochs_compared": len(self.gaps),
            "epochs_incomplete": self.incomplete,
            "conflicts_seen_by_robots": self.conflicts_seen,
            "claims_released": self.releases,
        }


def _mean(values: list[float]) -> float | None:
    return round(float(np.mean(values)), 6) if values else None


def _fleet_assignment(views: dict[int, dict[int, int]], cost: np.ndarray) -> dict[int, int]:
    """One assignment from the robots' views: each robot's own entry, conflicts to the cheaper."""
    chosen: dict[int, tuple[float, int]] = {}
    for robot, view in sorted(views.items()):
        task = view.get(robot)
        if task is None:
            continue
        candidate = (float(cost[robot, task]), robot)
        if task not in chosen or candidate < chosen[task]:
            chosen[task] = candidate
    return {robot: task for task, (_, robot) in chosen.items()}
