"""Every robot's navigation on the bus: what it hears and what it says, per robot.

In, on the robot's host: goals (:class:`~cosim.core.messages.NavGoal` on
``/<robot>/nav/goal``), the robot's scans (``/<robot>/scan``) and, when robots map, its
own map (``/<robot>/map``). Out, from the robot's host: its goal's status
(``/<robot>/nav/status``), its velocity commands (``/<robot>/cmd_vel``, a
:class:`~cosim.core.messages.Twist` in ``base_link``) and its global plans
(``/<robot>/plan``, a :class:`~cosim.core.messages.Path` in ``map``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from adapters.fleet.topics import cmd_vel_topic
from adapters.mapping.topics import map_topic
from adapters.navigation.goal_tracking import GoalTracker
from adapters.navigation.layers import StaticLayers
from adapters.navigation.scan_memory import ScanMemory
from adapters.navigation.topics import goal_topic, plan_topic, status_topic
from adapters.sensing.topics import scan_topic
from cosim.core.adapter import RunContext
from cosim.core.batches import InstantBatch
from cosim.core.bus import Bus, Envelope
from cosim.core.hosts import HostId
from cosim.core.messages import LaserScan, Message, NavGoal, NavStatus, Path, Twist
from cosim.core.messages import OccupancyGrid as GridMessage
from models.arrays import FloatArray
from models.navigation.costmap import StaticCostmap

Handler = Callable[[Message, Envelope], None]
"""A bus subscriber's callback."""


@dataclass(frozen=True)
class NavWiring:
    """The topics of every robot's navigation, and the wiring of what it hears.

    Attributes:
        names: the robots, in fleet order.
        hosts: each robot's host (it hears and speaks there).
        status: each robot's ``/<robot>/nav/status``.
        cmd: each robot's ``/<robot>/cmd_vel``.
        plan: each robot's ``/<robot>/plan``.
    """

    names: list[str]
    hosts: list[HostId]
    status: list[str]
    cmd: list[str]
    plan: list[str]

    @classmethod
    def of(cls, names: list[str], hosts: list[HostId]) -> NavWiring:
        """The topics of the robots ``names`` on their ``hosts``."""
        return cls(
            names,
            hosts,
            [status_topic(n) for n in names],
            [cmd_vel_topic(n) for n in names],
            [plan_topic(n) for n in names],
        )

    def advertise(self, bus: Bus) -> None:
        """Declare every robot's status, command and plan topics, robot by robot."""
        for status, cmd, path in zip(self.status, self.cmd, self.plan, strict=True):
            bus.advertise(status, NavStatus)
            bus.advertise(cmd, Twist)
            bus.advertise(path, Path)

    def subscribe(
        self,
        run: RunContext,
        goals: GoalTracker,
        memory: ScanMemory,
        pose: FloatArray,
        layers: StaticLayers,
        *,
        mapping: bool,
    ) -> None:
        """Hand every robot's goals to ``goals``, its scans to ``memory``, its map to ``layers``.

        Robot by robot: its goal, its scan and (when robots map) its map topic.

        Args:
            run: the run (goals are taken in it).
            goals: the goal tracker.
            memory: the scans each robot keeps, each at the pose the robot believed it had
                when the scan arrived.
            pose: (n, 3) every robot's pose estimate in ``map`` (m, rad), read on arrival.
            layers: every robot's static layer (its own map when robots map).
            mapping: robots build their own maps (their ``map`` topic updates ``layers``:
                the maps of one tick are inflated together on the run's threads as soon
                as the tick has published them).
        """
        bus = run.bus
        costmaps: InstantBatch[tuple[int, GridMessage], StaticCostmap] = InstantBatch(
            run.kernel,
            run.workers,
            lambda item: layers.build(*item),
            lambda item, layer: layers.set(item[0], layer),
        )
        for i, (name, host) in enumerate(zip(self.names, self.hosts, strict=True)):
            bus.subscribe(goal_topic(name), host, _on_goal(run, goals, i))
            bus.subscribe(scan_topic(name), host, _on_scan(memory, pose, i))
            if mapping:
                bus.subscribe(map_topic(name), host, _on_map(costmaps, i))

    def publish_commands(self, run: RunContext, v: FloatArray, w: FloatArray) -> None:
        """Every robot's command: speed ``v`` (m/s) and yaw rate ``w`` (rad/s), ``base_link``."""
        commands = [Twist(vi, wi) for vi, wi in zip(v.tolist(), w.tolist(), strict=True)]
        run.bus.publish_many(self.cmd, commands, self.hosts)


def _on_goal(run: RunContext, goals: GoalTracker, i: int) -> Handler:
    def on_goal(message: Message, _envelope: Envelope) -> None:
        assert isinstance(message, NavGoal)
        goals.accept(run, i, message)

    return on_goal


def _on_scan(memory: ScanMemory, pose: FloatArray, i: int) -> Handler:
    def on_scan(message: Message, _envelope: Envelope) -> None:
        assert isinstance(message, LaserScan)
        memory.add(i, pose[i].copy(), message.ranges_m)

    return on_scan


def _on_map(costmaps: InstantBatch[tuple[int, GridMessage], StaticCostmap], i: int) -> Handler:
    def on_map(message: Message, _envelope: Envelope) -> None:
        assert isinstance(message, GridMessage)
        costmaps.add((i, message))

    return on_map
