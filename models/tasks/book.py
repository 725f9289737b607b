"""The task source's book: tasks, claims, the right to serve, completions.

Safety rests here: whatever the network does, a task is served by at most one robot
(:meth:`TaskBook.request_service` grants a task once; later requests by another robot are
refused) and none is lost (a task stays open until the robot granted it reports it done,
and a claim not repeated within the timeout is released so another robot can take it).
Claims for the same task are resolved deterministically: the lower cost wins, equal costs
go to the robot earlier in the fleet order.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum


class TaskStatus(StrEnum):
    """Where a task is in its life."""

    OPEN = "open"
    SERVING = "serving"
    DONE = "done"


class ClaimOutcome(StrEnum):
    """What the book did with a claim."""

    ACCEPTED = "accepted"
    REFRESHED = "refreshed"
    REPLACED = "replaced"
    REJECTED = "rejected"
    CLOSED = "closed"


@dataclass(frozen=True, slots=True)
class Claim:
    """A robot's commitment to a task.

    Attributes:
        robot: the claiming robot.
        cost_m: its cost for the task (m).
        seen_ns: when the claim was last heard (ns).
    """

    robot: str
    cost_m: float
    seen_ns: int


@dataclass
class Task:
    """One task and its history (times in ns, -1 until they happen).

    Attributes:
        task_id: the id.
        x_m, y_m: the pick station in ``map`` (m).
        eligible: robots that may serve it.
        created_ns: creation time.
        status: open, serving or done.
        claim: the current claim, if any.
        server: the robot granted the service.
        assigned_ns: first time a claim was accepted.
        started_ns: service granted.
        completed_ns: reported done.
        reassignments: times the claim changed hands or was given up.
    """

    task_id: int
    x_m: float
    y_m: float
    eligible: frozenset[str]
    created_ns: int
    status: TaskStatus = TaskStatus.OPEN
    claim: Claim | None = None
    server: str | None = None
    assigned_ns: int = -1
    started_ns: int = -1
    completed_ns: int = -1
    reassignments: int = 0


@dataclass
class TaskBook:
    """All tasks of a run and the rules between them.

    Args:
        robots: the fleet, in the order that breaks ties between equal claims.
        claim_timeout_ns: a claim not heard again for this long is released.
        preemption: a claimant heading to its task may be re-assigned (robot side).
    """

    robots: list[str]
    claim_timeout_ns: int
    preemption: bool = False
    tasks: dict[int, Task] = field(default_factory=dict)
    conflicts: int = 0
    refused_services: int = 0

    def __post_init__(self) -> None:
        self._rank = {name: k for k, name in enumerate(self.robots)}

    def beats(self, a: Claim, b: Claim) -> bool:
        """Whether claim ``a`` wins over claim ``b`` (lower cost, then fleet order)."""
        return (a.cost_m, self._rank[a.robot]) < (b.cost_m, self._rank[b.robot])

    def create(
        self, task_id: int, x_m: float, y_m: float, eligible: frozenset[str], now_ns: int
    ) -> Task:
        """Open a new task."""
        if task_id in self.tasks:
            raise ValueError(f"task {task_id} exists already")
        task = Task(task_id, x_m, y_m, eligible, now_ns)
        self.tasks[task_id] = task
        return task

    def offered(self) -> list[Task]:
        """The tasks of the assignment problem, by id: every task not done yet.

        Tasks with a holder (see :meth:`holder`) stay in the problem: the holder's row
        commits it to its task, so the problem only changes when tasks come and go or a
        holder changes, not with every claim.
        """
        return [
            t
            for t in sorted(self.tasks.values(), key=lambda t: t.task_id)
            if t.status is not TaskStatus.DONE
        ]

    def holder(self, task: Task) -> str:
        """The robot committed to ``task``: its server, else its claimant, else ""."""
        if task.status is TaskStatus.SERVING and task.server is not None:
            return task.server
        return task.claim.robot if task.claim is not None else ""

    def claim(self, task_id: int, robot: str, cost_m: float, now_ns: int) -> ClaimOutcome:
        """Record ``robot``'s claim on a task."""
        task = self.tasks.get(task_id)
        if task is None or task.status is not TaskStatus.OPEN:
            return ClaimOutcome.CLOSED
        new = Claim(robot, cost_m, now_ns)
        current = task.claim
        if current is None:
            task.claim = new
            if task.assigned_ns < 0:
                task.assigned_ns = now_ns
            return ClaimOutcome.ACCEPTED
        if current.robot == robot:
            task.claim = new
            return ClaimOutcome.REFRESHED
        self.conflicts += 1
        if self.beats(new, current):
            task.claim = new
            task.reassignments += 1
            return ClaimOutcome.REPLACED
        return ClaimOutcome.REJECTED

    def release(self, task_id: int, robot: str) -> bool:
        """``robot`` gives its claim up; True if it held the claim."""
        task = self.tasks.get(task_id)
        if task is None or task.claim is None or task.claim.robot != robot:
            return False
        task.claim = None
        task.reassignments += 1
        return True

    def expire(self, now_ns: int) -> list[int]:
        """Release the claims not heard for the timeout; return their tasks."""
        expired = []
        for task in self.tasks.values():
            claim = task.claim
            silent = claim is not None and now_ns - claim.seen_ns > self.claim_timeout_ns
            if task.status is TaskStatus.OPEN and silent:
                task.claim = None
                task.reassignments += 1
                expired.append(task.task_id)
        return expired

    def request_service(self, task_id: int, robot: str, now_ns: int) -> bool:
        """Grant ``robot`` the right to serve the task, once and to one robot only.

        A request from the robot already serving is granted again (its first reply may
        have been lost). An open task is granted to its claimant, or to anyone when it is
        unclaimed (the requester then holds the claim).
        """
        task = self.tasks.get(task_id)
        if task is None or robot not in task.eligible:
            self.refused_services += 1
            return False
        if task.status is TaskStatus.SERVING and task.server == robot:
            return True
        if task.status is not TaskStatus.OPEN:
            self.refused_services += 1
            return False
        if task.claim is not None and task.claim.robot != robot:
            self.refused_services += 1
            return False
        if task.assigned_ns < 0:
            task.assigned_ns = now_ns
        task.status = TaskStatus.SERVING
        task.server = robot
        task.started_ns = now_ns
        return True

    def done(self, task_id: int, robot: str, now_ns: int) -> bool:
        """``robot`` reports the task served; True the first time, from its server."""
        task = self.tasks.get(task_id)
        if task is None or task.status is not TaskStatus.SERVING or task.server != robot:
            return False
        task.status = TaskStatus.DONE
        task.completed_ns = now_ns
        task.claim = None
        return True
