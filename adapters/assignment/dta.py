"""Dynamic task assignment on the robots: the fleet-management layer of the paper.

Every robot hears the task source's :class:`~cosim.messages.TaskSet` (an *epoch*: the open
tasks), computes its own costs from its own pose, and runs ``assignment.protocol`` with
its neighbours over the network, one round every ``assignment.period_ms`` (a robot whose
protocol has halted skips the round until it hears from a neighbour or its state is due
to be sent again, as a halted agent of distributed simplex does nothing). Once its
protocol has decided, a robot with a task claims it (a broadcast :class:`TaskClaim`,
repeated while it holds it) and drives there through its navigation; at the task it asks
the task source for the right to serve (granted to one robot only), dwells
``tasks.dwell_s``, and reports the task done until the source acknowledges. Conflicting
claims are resolved the same way everywhere (lower cost, then fleet order); a robot whose
navigation reports ``stuck`` or ``unreachable`` gives its claim up, and the fleet
re-assigns in the next epoch (the paper's Scenario 3, 20-30 s). Messages of an older
epoch are ignored; lost or late ones just leave a robot with what it has.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from adapters.assignment.protocols import (
    AssignmentProtocol,
    BasisDecoder,
    CbbaProtocol,
    GreedyProtocol,
    SimplexProtocol,
)
from adapters.assignment.records import DtaRecords
from adapters.assignment.topics import (
    ASSIGNMENT,
    BASES,
    BIDS,
    CLAIMS,
    DONE,
    REPORTS,
    SERVICE_REQUESTS,
    TASKS,
    ack_topic,
    order_topic,
    reply_topic,
)
from adapters.naming import topic
from adapters.network.link import NetworkView
from cosim.adapter import RunContext
from cosim.bus import Envelope
from cosim.hosts import HostId
from cosim.kernel import Stage
from cosim.messages import (
    AuctionBids,
    Message,
    NavGoal,
    NavStatus,
    Odometry,
    RobotState,
    ServiceReply,
    ServiceRequest,
    SimplexBasis,
    TaskAssignment,
    TaskClaim,
    TaskDone,
    TaskInfo,
    TaskOrder,
    TaskSet,
)
from cosim.timebase import period_ns, s_to_ns
from models.assignment.problem import AssignmentProblem
from models.kinematics import FleetState
from models.navigation.costmap import StaticCostmap
from models.navigation.planner import shortest_path_length_m
from models.network.topology import diameter
from models.world import Warehouse

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
    protocol: AssignmentProtocol | None = None
    acted: bool = False
    inbox: list[Message] = field(default_factory=list)
    claims: dict[int, tuple[str, float]] = field(default_factory=dict)
    blocked: dict[int, int] = field(default_factory=dict)
    last_broadcast_ns: int = -(1 << 62)


class DtaAdapter:
    """Runs the assignment protocol, claims, navigation goals and service on every robot."""

    name: ClassVar[str] = "dta"
    requires: ClassVar[tuple[str, ...]] = ("fleet", "network", "navigation", "task_source")

    def __init__(self, run: RunContext) -> None:
        self.cfg = run.scenario.assignment
        self.dwell_ns = s_to_ns(run.scenario.tasks.dwell_s)
        fleet = run.service(FleetState)
        self.fleet = fleet
        self.robots = [RobotTasks(i, n) for i, n in enumerate(fleet.names)]
        self.names = list(fleet.names)
        self.rank = {n: i for i, n in enumerate(self.names)}
        self.hosts = [HostId(n) for n in self.names]
        self.pose = np.stack([fleet.x, fleet.y], axis=1)
        self.static = run.service(StaticCostmap)
        view = run.service(NetworkView)
        robots, edges = view.robot_graph()
        bound = self.cfg.diameter_bound or diameter(robots, edges)
        self.diameter = int(bound) if math.isfinite(bound) else len(robots) - 1
        self.decoder = BasisDecoder()
        self.period_ns = period_ns(1000.0 / self.cfg.period_ms)
        self.rebroadcast_ns = s_to_ns(self.cfg.rebroadcast_s)
        # a common bid reward above any travel cost in the hall (paths included)
        width, height = run.service(Warehouse).size_m
        self.reward_m = 10.0 * float(math.hypot(width, height))
        self.records = DtaRecords(
            run.recorder, self.names, compare=self.cfg.protocol in ("distributed_simplex", "cbba")
        )
        self._advertise(run)

    def _advertise(self, run: RunContext) -> None:
        bus = run.bus
        for name in self.names:
            bus.advertise(topic(name, "nav/goal"), NavGoal)
        bus.advertise(CLAIMS, TaskClaim)
        bus.advertise(SERVICE_REQUESTS, ServiceRequest)
        bus.advertise(DONE, TaskDone)
        protocol = self.cfg.protocol
        if protocol == "distributed_simplex":
            bus.advertise(BASES, SimplexBasis)
        elif protocol == "cbba":
            bus.advertise(BIDS, AuctionBids)
        elif protocol == "hungarian":
            bus.advertise(REPORTS, RobotState)
        bus.advertise(ASSIGNMENT, TaskAssignment)

    # -- wiring ---------------------------------------------------------------------------
    def start(self, run: RunContext) -> None:
        """Subscribe every robot to tasks, claims, protocol messages and its navigation."""
        bus = run.bus
        for robot, host in zip(self.robots, self.hosts, strict=True):
            on = self._on(run, robot)
            bus.subscribe(TASKS, host, on)
            bus.subscribe(CLAIMS, host, on)
            bus.subscribe(BASES, host, on)
            bus.subscribe(BIDS, host, on)
            bus.subscribe(reply_topic(robot.name), host, on)
            bus.subscribe(ack_topic(robot.name), host, on)
            bus.subscribe(order_topic(robot.name), host, on)
            bus.subscribe(topic(robot.name, "nav/status"), host, on)
            bus.subscribe(topic(robot.name, "odom"), host, on)
        if self.cfg.round_phase == "aligned":
            run.kernel.every(self.period_ns, lambda now: self._round(run, now), stage=Stage.CONTROL)
        else:
            # independent timers: each robot's rounds start at its own phase of the period, so
            # a message arrives a varying time before the receiver's next round and latency
            # below one period still delays convergence (it would not with aligned timers)
            phases = run.rng.stream("dta.round_phase").integers(0, self.period_ns, len(self.robots))
            now_ns = run.kernel.now_ns
            for robot, phase in zip(self.robots, phases, strict=True):
                run.kernel.every(
                    self.period_ns,
                    self._robot_round(run, robot),
                    stage=Stage.CONTROL,
                    start_ns=now_ns + int(phase),
                )
        if self.cfg.protocol == "hungarian":
            run.kernel.every(s_to_ns(1.0), lambda now: self._report(run, now), stage=Stage.CONTROL)

    def _on(self, run: RunContext, robot: RobotTasks) -> Callable[[Message, Envelope], None]:
        def on(message: Message, envelope: Envelope) -> None:
            if isinstance(message, Odometry):
                self.pose[robot.index] = (message.x_m, message.y_m)
            elif isinstance(message, TaskSet):
                self._on_tasks(run, robot, message)
            elif isinstance(message, SimplexBasis | AuctionBids):
                if message.epoch == robot.epoch and message.robot != robot.name:
                    robot.inbox.append(message)
            elif isinstance(message, TaskClaim):
                self._on_claim(run, robot, message)
            elif isinstance(message, NavStatus):
                self._on_nav(run, robot, message)
            elif isinstance(message, ServiceReply):
                self._on_reply(run, robot, message)
            elif isinstance(message, TaskDone):
                if robot.phase == "reporting" and message.task_id == robot.task:
                    self._become_idle(robot)  # the source acknowledged
            elif isinstance(message, TaskOrder):
                self._on_order(run, robot, message)

        return on

    # -- epochs and rounds -------------------------------------------------------------------
    def _on_tasks(self, run: RunContext, robot: RobotTasks, tasks: TaskSet) -> None:
        if tasks.epoch <= robot.epoch:
            return
        robot.epoch = tasks.epoch
        robot.tasks = tasks.tasks
        robot.inbox = []
        robot.acted = False
        now = run.kernel.now_ns
        robot.blocked = {t: until for t, until in robot.blocked.items() if until > now}
        problem = self._problem(robot, tasks.tasks)
        robot.costs = tuple(problem.cost[robot.index].tolist())
        protocol = self.cfg.protocol
        if protocol == "distributed_simplex":
            robot.protocol = SimplexProtocol(
                problem, robot.index, robot.name, tasks.epoch, self.diameter, self.decoder
            )
        elif protocol == "cbba":
            robot.protocol = CbbaProtocol(
                problem, robot.index, robot.name, tasks.epoch, self.diameter, self.reward_m
            )
        elif protocol == "greedy":
            taken = {
                j
                for j, t in enumerate(tasks.tasks)
                if (t.holder and t.holder != robot.name)
                or (t.task_id in robot.claims and robot.claims[t.task_id][0] != robot.name)
            }
            robot.protocol = GreedyProtocol(problem, robot.index, taken)
        else:
            robot.protocol = None  # orders come from the base station
        self.records.epoch_seen(robot.index, tasks.epoch, tasks.stamp_ns, problem)

    def _problem(self, robot: RobotTasks, tasks: tuple[TaskInfo, ...]) -> AssignmentProblem:
        """This robot's row of costs (the other rows are other robots' business)."""
        cost = np.full((len(self.names), len(tasks)), math.inf)
        row = cost[robot.index]
        committed = robot.phase != "idle" and not (self.cfg.preemption and robot.phase == "heading")
        mine = [j for j, task in enumerate(tasks) if task.task_id == robot.task]
        if committed and mine:
            row[mine[0]] = 0.0  # held: the robot's row commits it to its task
        elif not committed:
            x, y = self.pose[robot.index]
            for j, task in enumerate(tasks):
                if robot.name in task.eligible and task.task_id not in robot.blocked:
                    row[j] = self._cost(x, y, task)
        return AssignmentProblem(tuple(self.names), tuple(t.task_id for t in tasks), cost)

    def _cost(self, x: float, y: float, task: TaskInfo) -> float:
        if self.cfg.cost == "path":
            length = shortest_path_length_m(self.static, (x, y), (task.x_m, task.y_m))
            return length
        return float(math.hypot(task.x_m - x, task.y_m - y))

    def _round(self, run: RunContext, now_ns: int) -> None:
        """One round of every robot at the same instant (aligned timers)."""
        for robot in self.robots:
            self._round_of(run, robot, now_ns)

    def _robot_round(self, run: RunContext, robot: RobotTasks) -> Callable[[int], None]:
        return lambda now_ns: self._round_of(run, robot, now_ns)

    def _round_of(self, run: RunContext, robot: RobotTasks, now_ns: int) -> None:
        """One protocol round of ``robot``: keep its promises, step, broadcast, act."""
        self._keep_promises(run, robot, now_ns)
        protocol = robot.protocol
        if protocol is None:
            return
        inbox, robot.inbox = robot.inbox, []
        was_decided = protocol.decided
        if (
            was_decided
            and robot.acted
            and not inbox
            and now_ns - robot.last_broadcast_ns < self.rebroadcast_ns
        ):
            return  # halted, nothing heard, nothing to send again yet: the round is idle
        message, changed = protocol.round(inbox, now_ns)
        send = message is not None and (
            changed or not was_decided or now_ns - robot.last_broadcast_ns >= self.rebroadcast_ns
        )
        if send and message is not None:
            host = self.hosts[robot.index]
            run.bus.publish(BASES if isinstance(message, SimplexBasis) else BIDS, message, host)
            robot.last_broadcast_ns = now_ns
        if not was_decided or changed:
            self.records.round(
                now_ns,
                robot.index,
                robot.epoch,
                protocol,
                changed,
                message.size_bytes() if send and message else 0,
            )
        if protocol.decided and (not robot.acted or changed):
            robot.acted = True
            self.records.decided(robot.index, robot.epoch, now_ns, protocol)
            self._announce(run, robot, now_ns, protocol.task(), protocol.rounds)
            self._act(run, robot, protocol.task())

    def _announce(
        self, run: RunContext, robot: RobotTasks, now_ns: int, index: int | None, rounds: int
    ) -> None:
        """Publish the robot's decision on ``/fleet/assignment`` (for tools and bags)."""
        task_id, cost = -1, math.nan
        if index is not None and index < len(robot.tasks):
            task_id, cost = robot.tasks[index].task_id, robot.costs[index]
        decision = TaskAssignment(now_ns, robot.epoch, robot.name, task_id, cost, rounds)
        run.bus.publish(ASSIGNMENT, decision, self.hosts[robot.index])

    # -- acting on a decision ------------------------------------------------------------------
    def _act(self, run: RunContext, robot: RobotTasks, index: int | None) -> None:
        task = robot.tasks[index] if index is not None and index < len(robot.tasks) else None
        if robot.phase in ("requesting", "serving", "reporting"):
            return  # at the task already: finish it
        if robot.phase == "heading":
            if task is not None and task.task_id == robot.task:
                return
            if not self.cfg.preemption:
                return
            self._release(run, robot, "re-assigned")
        if task is None:
            if robot.phase == "heading":
                self._cancel(run, robot)
            return
        x, y = self.pose[robot.index]
        self._take(run, robot, task, self._cost(x, y, task))

    def _take(self, run: RunContext, robot: RobotTasks, task: TaskInfo, cost: float) -> None:
        now = run.kernel.now_ns
        robot.phase = "heading"
        robot.task = task.task_id
        robot.task_cost = cost
        robot.goal_id += 1
        self._claim(run, robot, now)
        goal = NavGoal(now, robot.goal_id, task.x_m, task.y_m)
        run.bus.publish(topic(robot.name, "nav/goal"), goal, self.hosts[robot.index])

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
        self._become_idle(robot)

    def _cancel(self, run: RunContext, robot: RobotTasks) -> None:
        robot.goal_id += 1
        cancel = NavGoal(run.kernel.now_ns, robot.goal_id, math.nan, math.nan)
        run.bus.publish(topic(robot.name, "nav/goal"), cancel, self.hosts[robot.index])

    def _become_idle(self, robot: RobotTasks) -> None:
        robot.phase = "idle"
        robot.task = -1

    def _keep_promises(self, run: RunContext, robot: RobotTasks, now_ns: int) -> None:
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

    # -- messages -------------------------------------------------------------------------------
    def _on_claim(self, run: RunContext, robot: RobotTasks, claim: TaskClaim) -> None:
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
                self._become_idle(robot)
                robot.claims[claim.task_id] = (claim.robot, claim.cost_m)

    def _on_nav(self, run: RunContext, robot: RobotTasks, status: NavStatus) -> None:
        if robot.phase != "heading" or status.goal_id != robot.goal_id:
            return
        now = run.kernel.now_ns
        if status.state == "arrived":
            robot.phase = "requesting"
            robot.last_sent_ns = -(1 << 62)
            self._keep_promises(run, robot, now)
        elif status.state in ("stuck", "unreachable"):
            robot.blocked[robot.task] = now + s_to_ns(BLOCKED_S)
            self._release(run, robot, status.state)

    def _on_reply(self, run: RunContext, robot: RobotTasks, reply: ServiceReply) -> None:
        if robot.phase != "requesting" or reply.task_id != robot.task:
            return
        if reply.granted:
            robot.phase = "serving"
            robot.until_ns = run.kernel.now_ns + self.dwell_ns
        else:
            self.records.released(run.kernel.now_ns, robot.index, robot.task, "refused")
            robot.claims.pop(robot.task, None)
            self._become_idle(robot)

    def _on_order(self, run: RunContext, robot: RobotTasks, order: TaskOrder) -> None:
        match = [t for t in robot.tasks if t.task_id == order.task_id]
        if order.robot == robot.name and robot.phase == "idle" and match:
            self._take(run, robot, match[0], order.cost_m)
            decision = TaskAssignment(
                run.kernel.now_ns, order.epoch, robot.name, order.task_id, order.cost_m, 0
            )
            run.bus.publish(ASSIGNMENT, decision, self.hosts[robot.index])

    def _report(self, run: RunContext, now_ns: int) -> None:
        """Centralized baseline: every robot reports its pose to the base station."""
        for robot, host in zip(self.robots, self.hosts, strict=True):
            x, y = self.pose[robot.index]
            state = RobotState(now_ns, robot.name, float(x), float(y), 0.0, 0.0, 0.0)
            run.bus.publish(REPORTS, state, host)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Convergence, rounds, optimality gap, conflicts seen by robots."""
        summary = self.records.summary()
        if self.cfg.protocol == "hungarian":
            summary["optimality_gap"] = 0.0  # the optimum of the base's instance, by construction
        return summary
