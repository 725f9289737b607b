"""Dynamic task assignment on the robots: the fleet-management layer of the paper.

Every robot hears the task source's :class:`~cosim.core.messages.TaskSet` (an *epoch*: the open
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
from typing import Any, ClassVar

import numpy as np

from adapters.assignment.answers import CheckedAgent, CheckedOrders
from adapters.assignment.commitments import Commitments, RobotTasks
from adapters.assignment.contract import (
    EpochView,
    ProtocolFleet,
    protocol_registry,
)
from adapters.assignment.settings import AssignmentConfig
from adapters.assignment.tables import ASSIGNMENTS, DTA_SUMMARY, DtaRecords
from adapters.assignment.topics import ASSIGNMENT
from adapters.fleet.topics import odom_topic
from adapters.navigation.topics import goal_topic, status_topic
from adapters.network.contract import NetworkView
from adapters.tasks.contract import CentralOrders
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
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import (
    Message,
    NavGoal,
    NavStatus,
    Odometry,
    RobotState,
    ServiceReply,
    ServiceRequest,
    TaskAssignment,
    TaskClaim,
    TaskDone,
    TaskInfo,
    TaskOrder,
    TaskSet,
)
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import period_ns, s_to_ns
from models.assignment.problem import AssignmentProblem
from models.fleet.kinematics import FleetState
from models.navigation.costmap import StaticCostmap
from models.navigation.planner import shortest_path_length_m
from models.network.topology import diameter
from models.world.warehouse import Warehouse


class DtaAdapter:
    """Runs the assignment protocol, claims, navigation goals and service on every robot."""

    name: ClassVar[str] = "dta"
    requires: ClassVar[tuple[str, ...]] = ("fleet", "network", "navigation", "task_source")
    tables: ClassVar[tuple[TableSpec, ...]] = (ASSIGNMENTS,)
    """The tables it writes (documented in the table reference)."""
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = DTA_SUMMARY
    """The summary keys :meth:`finish` writes; the protocol's own ``summary()`` keys are
    declared by the protocol class (documented in the summary reference)."""

    def __init__(self, run: RunContext) -> None:
        self.cfg = run.settings(AssignmentConfig)
        fleet = run.service(FleetState)
        self.fleet = fleet
        self.robots = [RobotTasks(i, n) for i, n in enumerate(fleet.names)]
        self.names = list(fleet.names)
        self.hosts = [HostId(n) for n in self.names]
        self.pose = np.stack([fleet.x, fleet.y], axis=1)
        self.static = run.service(StaticCostmap)
        view = run.service(NetworkView)
        robots, edges = view.robot_graph()
        bound = self.cfg.diameter_bound or diameter(robots, edges)
        self.diameter = int(bound) if math.isfinite(bound) else len(robots) - 1
        self.period_ns = period_ns(1000.0 / self.cfg.period_ms)
        self.rebroadcast_ns = s_to_ns(self.cfg.rebroadcast_s)
        protocol_type = protocol_registry().get(self.cfg.protocol)
        fleet_view = ProtocolFleet(
            run, tuple(self.names), self.diameter, run.service(Warehouse).size_m
        )
        self.protocol = protocol_type(fleet_view)
        if protocol_type.central:
            run.provide(CentralOrders(CheckedOrders(self.protocol, self.names)))
        self.records = DtaRecords(
            run.recorder, self.names, compare=protocol_type.compare_to_optimum
        )
        self.duties = Commitments(
            self.names,
            self.hosts,
            self.pose,
            self.records,
            self._cost,
            dwell_ns=s_to_ns(run.settings(TasksConfig).dwell_s),
            rebroadcast_ns=self.rebroadcast_ns,
            preemption=self.cfg.preemption,
        )
        self._advertise(run)

    def _advertise(self, run: RunContext) -> None:
        bus = run.bus
        for name in self.names:
            bus.advertise(goal_topic(name), NavGoal)
        bus.advertise(CLAIMS, TaskClaim)
        bus.advertise(SERVICE_REQUESTS, ServiceRequest)
        bus.advertise(DONE, TaskDone)
        protocol = self.protocol
        if protocol.topic is not None and protocol.message is not None:
            bus.advertise(protocol.topic, protocol.message)
        if protocol.central:
            bus.advertise(REPORTS, RobotState)
        bus.advertise(ASSIGNMENT, TaskAssignment)

    # -- wiring ---------------------------------------------------------------------------
    def start(self, run: RunContext) -> None:
        """Subscribe every robot to tasks, claims, protocol messages and its navigation."""
        bus = run.bus
        for robot, host in zip(self.robots, self.hosts, strict=True):
            # one handler per topic: each topic carries one advertised type (the bus refuses
            # others), so a message is handed on without asking what it is
            on = self._handlers(run, robot)
            bus.subscribe(TASKS, host, on["tasks"])
            bus.subscribe(CLAIMS, host, on["claim"])
            if self.protocol.topic is not None:
                bus.subscribe(self.protocol.topic, host, on["exchanged"])
            bus.subscribe(reply_topic(robot.name), host, on["reply"])
            bus.subscribe(ack_topic(robot.name), host, on["done"])
            bus.subscribe(order_topic(robot.name), host, on["order"])
            bus.subscribe(status_topic(robot.name), host, on["nav"])
            bus.subscribe(odom_topic(robot.name), host, on["odom"])
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
        if self.protocol.central:  # the base station decides from the robots' poses
            run.kernel.every(s_to_ns(1.0), lambda now: self._report(run, now), stage=Stage.CONTROL)

    def _handlers(
        self, run: RunContext, robot: RobotTasks
    ) -> dict[str, Callable[[Message, Envelope], None]]:
        """``robot``'s handler of each topic it hears, by what the topic carries."""
        exchanged = self.protocol.message
        duties = self.duties
        pose = self.pose
        index = robot.index

        def odom(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, Odometry)
            pose[index] = (message.x_m, message.y_m)

        def tasks(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, TaskSet)
            self._on_tasks(run, robot, message)

        def protocol(message: Message, _envelope: Envelope) -> None:
            if exchanged is None or not isinstance(message, exchanged):
                return
            sender: Any = message  # the contract: protocol messages carry epoch and robot
            if sender.epoch == robot.epoch and sender.robot != robot.name:
                robot.inbox.append(message)

        def claim(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, TaskClaim)
            duties.on_claim(run, robot, message)

        def nav(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, NavStatus)
            duties.on_nav(run, robot, message)

        def reply(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, ServiceReply)
            duties.on_reply(run, robot, message)

        def done(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, TaskDone)
            if robot.phase == "reporting" and message.task_id == robot.task:
                duties.become_idle(robot)  # the source acknowledged

        def order(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, TaskOrder)
            duties.on_order(run, robot, message)

        return {
            "odom": odom,
            "tasks": tasks,
            "exchanged": protocol,
            "claim": claim,
            "nav": nav,
            "reply": reply,
            "done": done,
            "order": order,
        }

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
        taken = frozenset(
            j
            for j, t in enumerate(tasks.tasks)
            if (t.holder and t.holder != robot.name)
            or (t.task_id in robot.claims and robot.claims[t.task_id][0] != robot.name)
        )
        view = EpochView(problem, robot.index, robot.name, tasks.epoch, tasks.tasks, taken)
        agent = self.protocol.agent(view)  # None: orders come from the base station
        robot.protocol = (
            None if agent is None else CheckedAgent(agent, self.protocol, view, len(self.names))
        )
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
        self.duties.keep_promises(run, robot, now_ns)
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
            assert self.protocol.topic is not None, f"{self.cfg.protocol} sent with no topic"
            run.bus.publish(self.protocol.topic, message, self.hosts[robot.index])
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
            self.duties.act(run, robot, protocol.task())

    def _announce(
        self, run: RunContext, robot: RobotTasks, now_ns: int, index: int | None, rounds: int
    ) -> None:
        """Publish the robot's decision on ``/fleet/assignment`` (for tools and bags)."""
        task_id, cost = -1, math.nan
        if index is not None and index < len(robot.tasks):
            task_id, cost = robot.tasks[index].task_id, robot.costs[index]
        decision = TaskAssignment(now_ns, robot.epoch, robot.name, task_id, cost, rounds)
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
        summary.update(self.protocol.summary())
        return summary
