"""cosim's own action kinds, registered in ``cosim.agent_actions`` as a plugin's are.

An action takes effect at the instant it is decided, after the instant's physics and
sensing (it is published in the kernel's ``CONTROL`` stage, as a controller's would be).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import ClassVar

import numpy as np

from adapters.agents.contract import AgentView, BoxSpec, ChoiceSpec
from adapters.assignment.settings import AssignmentConfig
from adapters.fleet.topics import cmd_vel_topic
from adapters.navigation.topics import goal_topic, status_topic
from cosim.core.bus import Envelope
from cosim.core.errors import ConfigError
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import Message, NavGoal, NavStatus, Twist
from models.arrays import IntArray

ENDED = frozenset({"arrived", "stuck", "unreachable"})
"""Navigation states after which a goal is no longer driven to."""


class Velocity:
    """``velocity``: a forward speed (m/s) and a yaw rate (rad/s), within the drive limits.

    The robot's base follows it (with its acceleration limits) until the agent's next
    decision: a ``geometry_msgs/Twist`` on ``/<robot>/cmd_vel``.
    """

    name: ClassVar[str] = "velocity"
    adapters: ClassVar[tuple[str, ...]] = ()

    def __init__(self, view: AgentView) -> None:
        limits = view.limits
        self.spec = BoxSpec(
            (-limits.max_reverse_mps, -limits.max_yaw_rate_radps),
            (limits.max_speed_mps, limits.max_yaw_rate_radps),
            ("v_mps", "w_radps"),
        )
        self.topics = [cmd_vel_topic(name) for name in view.names]
        self.hosts = [HostId(name) for name in view.names]
        for topic in self.topics:
            view.run.bus.advertise(topic, Twist)

    def apply(self, view: AgentView, agents: IntArray, actions: np.ndarray) -> None:
        """Send each deciding agent's command to its base, clipped to the limits."""
        low, high = self.spec.low, self.spec.high
        commands = np.clip(np.asarray(actions, dtype=float).reshape(len(agents), 2), low, high)
        topics = [self.topics[int(i)] for i in agents]
        hosts = [self.hosts[int(i)] for i in agents]
        messages = [Twist(float(v), float(w)) for v, w in commands]
        run = view.run
        run.kernel.at(
            run.kernel.now_ns,
            lambda: run.bus.publish_many(topics, messages, hosts),
            stage=Stage.CONTROL,
        )


class GoalChoice:
    """``goal``: one of the places (``agents.places``, or ``navigation.goals``) to drive to.

    The robot's navigation (planner and controller, ``[navigation]``) drives there; a
    choice is sent as a goal when it differs from the one being driven to, or when the
    navigation ended the previous one (arrived, stuck, unreachable). The agents' goals are
    drawn among the same places.
    """

    name: ClassVar[str] = "goal"
    adapters: ClassVar[tuple[str, ...]] = ("navigation",)
    goals_at_places: ClassVar[bool] = True

    def __init__(self, view: AgentView) -> None:
        if not len(view.places):
            raise ConfigError(
                f"{view.run.scenario.source}: [agents] action = 'goal': expected free room "
                "for places in the first robot's region, or navigation.goals"
            )
        self.spec = ChoiceSpec(len(view.places))
        n = len(view)
        self.chosen = np.full(n, -1, dtype=np.int64)
        self.open = np.zeros(n, dtype=bool)
        self.sent = np.zeros(n, dtype=np.int64)
        self.topics = [goal_topic(name) for name in view.names]
        self.hosts = [HostId(name) for name in view.names]
        bus = view.run.bus
        for i, (name, host) in enumerate(zip(view.names, self.hosts, strict=True)):
            bus.advertise(self.topics[i], NavGoal)
            bus.subscribe(status_topic(name), host, self._on_status(i))

    def _on_status(self, i: int) -> Callable[[Message, Envelope], None]:
        def on_status(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, NavStatus)
            if message.goal_id == self.sent[i] - 1 and message.state in ENDED:
                self.open[i] = False

        return on_status

    def apply(self, view: AgentView, agents: IntArray, actions: np.ndarray) -> None:
        """Send a goal to each deciding agent whose choice is new or whose last one ended."""
        run = view.run
        now = run.kernel.now_ns
        picks = np.asarray(actions, dtype=np.int64).reshape(len(agents))
        due: list[tuple[str, NavGoal, HostId]] = []
        for agent, choice in zip(agents, picks, strict=True):
            i, pick = int(agent), int(choice)
            if not 0 <= pick < self.spec.n:
                raise ValueError(
                    f"goal action {pick} for {view.names[i]}: expected 0..{self.spec.n - 1}"
                )
            if pick == self.chosen[i] and self.open[i]:
                continue
            x, y = view.places[pick]
            due.append(
                (self.topics[i], NavGoal(now, int(self.sent[i]), float(x), float(y)), self.hosts[i])
            )
            self.chosen[i], self.open[i] = pick, True
            self.sent[i] += 1
        if due:
            topics, messages, hosts = (list(column) for column in zip(*due, strict=True))
            run.kernel.at(
                now, lambda: run.bus.publish_many(topics, messages, hosts), stage=Stage.CONTROL
            )


class Bid:
    """``bid``: a bid in [0, 1] for each of the first ``agents.task_slots`` open tasks (0 declines).

    The robots run the task assignment (task source, claims, navigation to the station,
    service) with ``assignment.protocol = "agent_bids"``: once an agent has bid after a new
    set of open tasks reached its robot, the robot claims the free task it bids highest for.
    The ``tasks`` observation part shows the slots; the ``tasks`` reward term counts what
    each agent's robot served.
    """

    name: ClassVar[str] = "bid"
    adapters: ClassVar[tuple[str, ...]] = ("navigation", "task_source", "dta")
    goals: ClassVar[bool] = False

    def __init__(self, view: AgentView) -> None:
        protocol = view.run.settings(AssignmentConfig).protocol
        if protocol != "agent_bids":
            raise ConfigError(
                f"{view.run.scenario.source}: [assignment] protocol = {protocol!r}: expected "
                "'agent_bids' with agents.action = 'bid' (the protocol that takes the bids)"
            )
        slots = view.settings.task_slots
        self.spec = BoxSpec((0.0,) * slots, (1.0,) * slots, tuple(f"bid_{k}" for k in range(slots)))

    def apply(self, view: AgentView, agents: IntArray, actions: np.ndarray) -> None:
        """Keep each deciding agent's bids (clipped to [0, 1]) for its robot's next claim."""
        rows = np.asarray(actions, dtype=float).reshape(len(agents), len(self.spec.low))
        view.bids[agents] = np.clip(rows, 0.0, 1.0)
