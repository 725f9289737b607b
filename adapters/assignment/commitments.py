"""A robot's commitment to a task: claim it, drive there, be granted service, serve, report.

Once its protocol has decided, a robot with a task claims it (a broadcast
:class:`~cosim.core.messages.TaskClaim`, repeated while it holds it) and drives there
through its navigation; at the task it asks the task source for the right to serve
(granted to one robot only), dwells ``tasks.dwell_s``, and reports the task done until the
source acknowledges. Conflicting claims are resolved the same way everywhere (lower cost,
then fleet order); a robot whose navigation reports ``stuck`` or ``unreachable`` gives its
claim up and keeps away from that task for :data:`BLOCKED_S`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from adapters.assignment.contract import ProtocolAgent
from adapters.assignment.tables import DtaRecords
from adapters.assignment.topics import ASSIGNMENT
from adapters.navigation.topics import goal_topic
from adapters.tasks.topics import CLAIMS, DONE, SERVICE_REQUESTS
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.messages import (
    Message,
    NavGoal,
    NavStatus,
    ServiceReply,
    ServiceRequest,
    TaskAssignment,
    TaskClaim,
    TaskDone,
    TaskInfo,
    TaskOrder,
)
from cosim.core.timebase import s_to_ns
from models.arrays import FloatArray

RETRY_S = 1.0
"""Period of service requests and done reports until answered (s)."""
BLOCKED_S = 60.0
"""A task a robot got stuck on is not its to take for this long (s)."""


@dataclass
class RobotTasks:
    """One robot's view of the tasks and what it is doing about them."""

    index: int
    name: str
    phase: str = "idle"  # idle | heading | requesting | serving | reporting
    task: int = -1
    task_cost: float = 0.0
    goal_id: int = 0
    until_ns: int = 0
    last_sent_ns: int = -(1 << 62)
    epoch: int = 0
    tasks: tuple[TaskInfo, ...] = ()
    costs: tuple[float, ...] = ()
    protocol: ProtocolAgent | None = None
    acted: bool = False
    inbox: list[Message] = field(default_factory=list)
    claims: dict[int, tuple[str, float]] = field(default_factory=dict)
    blocked: dict[int, int] = field(default_factory=dict)
    last_broadcast_ns: int = -(1 << 62)


class Commitments:
    """Claims, navigation goals, service and reports of every robot.

    Args:
        names: the robots, in fleet order (the tie-break of conflicting claims).
        hosts: every robot's host.
        pose: (n, 2) every robot's position (m, ``map``), kept up to date by the caller.
        records: the assignment tables.
        cost: a robot's cost (m) of a task from a position (x_m, y_m).
        dwell_ns: how long serving a task takes (ns).
        rebroadcast_ns: a held task's claim is repeated this often (ns).
        preemption: a robot heading to a task may be re-assigned.
    """

    def __init__(
        self,
        names: list[str],
        hosts: list[HostId],
        pose: FloatArray,
        records: DtaRecords,
        cost: Callable[[float, float, TaskInfo], float],
        *,
        dwell_ns: int,
        rebroadcast_ns: int,
        preemption: bool,
    ) -> None:
        self.rank = {n: i for i, n in enumerate(names)}
        self.hosts = hosts
        self.pose = pose
        self.records = records
        self.cost = cost
        self.dwell_ns = dwell_ns
        self.rebroadcast_ns = rebroadcast_ns
        self.preemption = preemption

    def act(self, run: RunContext, robot: RobotTasks, index: int | None) -> None:
        """Act on the protocol's decision: task ``index`` of the epoch, or none."""
        task = robot.tasks[index] if index is not None and index < len(robot.tasks) else None
        if robot.phase in ("requesting", "serving", "reporting"):
            return  # at the task already: finish it
        if robot.phase == "heading":
            if task is not None and task.task_id == robot.task:
                return
            gone = self.gone(robot)
            if not (self.preemption or gone):
                return
            self._release(run, robot, gone or "re-assigned")
            if task is None:  # re-assigned to nothing: stop driving to the task given up
                self._cancel(run, robot)
        if task is None:
            return
        x, y = self.pose[robot.index]
        self._take(run, robot, task, self.cost(x, y, task))

    @staticmethod
    def gone(robot: RobotTasks) -> str:
        """Why the task ``robot`` heads to is no longer its to serve, or "" if it still is.

        A new epoch's task set without it (another robot served it: the epoch was cut
        before that robot's claim reached this one) or naming another robot its holder. A
        robot that kept heading there would drive to a task that no longer exists and stand
        on its station in the way of the next robot sent there.
        """
        for info in robot.tasks:
            if info.task_id == robot.task:
                return "held by " + info.holder if info.holder not in ("", robot.name) else ""
        return "no longer open"

    def _take(self, run: RunContext, robot: RobotTasks, task: TaskInfo, cost: float) -> None:
        now = run.kernel.now_ns
        robot.phase = "heading"
        robot.task = task.task_id
        robot.task_cost = cost
        robot.goal_id += 1
        self._claim(run, robot, now)
        goal = NavGoal(now, robot.goal_id, task.x_m, task.y_m)
        run.bus.publish(goal_topic(robot.name), goal, self.hosts[robot.index])

    def _claim(self, run: RunContext, robot: RobotTasks, now_ns: int) -> None:
        claim = TaskClaim(now_ns, robot.epoch, robot.task, robot.name, robot.task_cost, "claim")
        robot.last_sent_ns = now_ns
        robot.claims[robot.task] = (robot.name, robot.task_cost)
        run.bus.publish(CLAIMS, claim, self.hosts[robot.index])

    def _release(self, run: RunContext, robot: RobotTasks, why: str) -> None:
        now = run.kernel.now_ns
        release = TaskClaim(now, robot.epoch, robot.task, robot.name, robot.task_cost, "release")
        run.bus.publish(CLAIMS, release, self.hosts[robot.index])
        robot.claims.pop(robot.task, None)
        self.records.released(now, robot.index, robot.task, why)
        self.become_idle(robot)

    def _cancel(self, run: RunContext, robot: RobotTasks) -> None:
        robot.goal_id += 1
        cancel = NavGoal(run.kernel.now_ns, robot.goal_id, math.nan, math.nan)
        run.bus.publish(goal_topic(robot.name), cancel, self.hosts[robot.index])

    def become_idle(self, robot: RobotTasks) -> None:
        """The robot holds no task any more."""
        robot.phase = "idle"
        robot.task = -1

    def keep_promises(self, run: RunContext, robot: RobotTasks, now_ns: int) -> None:
        """Repeat claims while holding a task; retry requests and reports; end dwells."""
        host = self.hosts[robot.index]
        due = now_ns - robot.last_sent_ns >= s_to_ns(RETRY_S)
        if robot.phase == "heading" and now_ns - robot.last_sent_ns >= self.rebroadcast_ns:
            self._claim(run, robot, now_ns)
        elif robot.phase == "requesting" and due:
            robot.last_sent_ns = now_ns
            run.bus.publish(SERVICE_REQUESTS, ServiceRequest(now_ns, robot.task, robot.name), host)
        elif robot.phase == "serving" and now_ns >= robot.until_ns:
            robot.phase = "reporting"
            robot.last_sent_ns = -(1 << 62)
        if robot.phase == "reporting" and now_ns - robot.last_sent_ns >= s_to_ns(RETRY_S):
            robot.last_sent_ns = now_ns
            run.bus.publish(DONE, TaskDone(now_ns, robot.task, robot.name), host)

    def on_claim(self, run: RunContext, robot: RobotTasks, claim: TaskClaim) -> None:
        """Another robot claims or releases a task; the cheaper claim wins a conflict."""
        if claim.robot == robot.name:
            return
        if claim.state == "release":
            if robot.claims.get(claim.task_id, ("", 0.0))[0] == claim.robot:
                robot.claims.pop(claim.task_id, None)
            return
        robot.claims[claim.task_id] = (claim.robot, claim.cost_m)
        if robot.phase == "heading" and claim.task_id == robot.task:
            theirs = (claim.cost_m, self.rank[claim.robot])
            mine = (robot.task_cost, robot.index)
            if theirs < mine:  # they win: give way, the fleet re-assigns
                self.records.conflict(run.kernel.now_ns, robot.index, robot.task, claim.robot)
                self._cancel(run, robot)
                self.become_idle(robot)
                robot.claims[claim.task_id] = (claim.robot, claim.cost_m)

    def on_nav(self, run: RunContext, robot: RobotTasks, status: NavStatus) -> None:
        """The robot's navigation reports: arrived at the task, or given up on the way."""
        if robot.phase != "heading" or status.goal_id != robot.goal_id:
            return
        now = run.kernel.now_ns
        if status.state == "arrived":
            robot.phase = "requesting"
            robot.last_sent_ns = -(1 << 62)
            self.keep_promises(run, robot, now)
        elif status.state in ("stuck", "unreachable"):
            robot.blocked[robot.task] = now + s_to_ns(BLOCKED_S)
            self._release(run, robot, status.state)

    def on_reply(self, run: RunContext, robot: RobotTasks, reply: ServiceReply) -> None:
        """The task source grants service, or refuses it (another robot serves)."""
        if robot.phase != "requesting" or reply.task_id != robot.task:
            return
        if reply.granted:
            robot.phase = "serving"
            robot.until_ns = run.kernel.now_ns + self.dwell_ns
        else:
            self.records.released(run.kernel.now_ns, robot.index, robot.task, "refused")
            robot.claims.pop(robot.task, None)
            self.become_idle(robot)

    def on_order(self, run: RunContext, robot: RobotTasks, order: TaskOrder) -> None:
        """The base station orders an idle robot to a task (centralized assignment)."""
        match = [t for t in robot.tasks if t.task_id == order.task_id]
        if order.robot == robot.name and robot.phase == "idle" and match:
            self._take(run, robot, match[0], order.cost_m)
            decision = TaskAssignment(
                run.kernel.now_ns, order.epoch, robot.name, order.task_id, order.cost_m, 0
            )
            run.bus.publish(ASSIGNMENT, decision, self.hosts[robot.index])
