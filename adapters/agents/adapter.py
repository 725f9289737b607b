"""The agents adapter: robots a learning environment drives (``robots.driver = "agents"``).

It gives every agent a goal and keeps what observation parts, action kinds and reward
terms read (:class:`~adapters.agents.contract.AgentView`, a service of the run):

- **goals**: a free place of the robot's region of the static map (as the ``goals``
  adapter draws them, from the agent's own random stream), or ``navigation.goals`` in
  turn; an agent within ``agents.goal_tolerance_m`` of its goal has arrived (a row of
  ``tables/agent_arrivals``) and gets the next one. Under an action kind that chooses
  among places (``goal``), goals are drawn among the places;
- **what an agent hears**: every agent broadcasts a
  :class:`~cosim.core.messages.RobotState` on ``/agents/states`` at ``agents.share_hz``
  over the scenario's network; what reaches an agent, when and from whom, is kept;
- **its senses**: each agent's latest lidar ranges, and its contacts.

The environment (:mod:`cosim.envs`) applies the agents' actions between kernel steps.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, ClassVar

import numpy as np

from adapters.agents.boundary import action_problem, observe_all
from adapters.agents.contract import (
    ACTIONS,
    OBSERVATIONS,
    POLICIES,
    REWARDS,
    AgentParts,
    AgentView,
    Policy,
)
from adapters.agents.settings import AgentsConfig
from adapters.fleet.collisions import ContactCounts
from adapters.fleet.motion import drive_limits
from adapters.navigation.goals import goal_cells
from adapters.navigation.layers import static_costmap
from adapters.navigation.settings import NavigationConfig
from adapters.sensing.topics import scan_topic
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import LaserScan, Message, RobotState
from cosim.core.plugins import refuse
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S, period_ns
from cosim.scenario.sections import LidarConfig, RobotsConfig, WorldConfig
from models.arrays import Float32Array, FloatArray, IntArray
from models.fleet.kinematics import FleetState

AGENT_STATES = "/agents/states"
"""Every agent's pose, broadcast to the others over the network."""
ARRIVALS = TableSpec(
    "agent_arrivals",
    "One row per goal a learning agent reached.",
    {
        "t_s": "when it arrived (s)",
        "robot": "the agent's robot",
        "goal_x_m": "the goal, x in map (m)",
        "goal_y_m": "the goal, y in map (m)",
        "took_s": "time since the goal was set (s)",
        "straight_m": "the straight-line distance when it was set (m)",
    },
    categorical=("robot",),
)


class AgentsAdapter:
    """Goals, arrivals, the agents' pose broadcasts and senses, for a learning environment."""

    name: ClassVar[str] = "agents"
    requires: ClassVar[tuple[str, ...]] = ("world", "fleet", "collisions")
    tables: ClassVar[tuple[TableSpec, ...]] = (ARRIVALS,)
    """The tables it writes (documented in the table reference)."""
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "agent_arrivals": SummaryKey("count", "goals the learning agents reached"),
        "agent_poses_sent": SummaryKey("count", "poses the agents broadcast to each other"),
        "agent_poses_heard": SummaryKey("count", "poses that reached another agent"),
    }
    """The summary keys :meth:`finish` writes (documented in the summary reference)."""

    def __init__(self, run: RunContext) -> None:
        cfg = run.settings(AgentsConfig)
        fleet = run.service(FleetState)
        self.fleet = fleet
        self.cfg = cfg
        names = list(fleet.names)
        n = len(names)
        self.hosts = [HostId(name) for name in names]
        radius = run.settings(RobotsConfig).radius_m
        static = static_costmap(run, radius)
        self.static = static
        self.cells = goal_cells(static, radius, fleet)
        self.series = run.settings(NavigationConfig).goals
        kind = ACTIONS.installed().get(cfg.action)
        self.at_places = bool(getattr(kind, "goals_at_places", False))
        self.goals = bool(getattr(kind, "goals", True))
        """Whether agents have goals of this adapter's (not under the bid action)."""
        movable = [self.goals and (bool(len(c)) or bool(self.series)) for c in self.cells]
        self.movable = np.array(movable, dtype=bool)
        """Robots with somewhere to go (one walled in stays, and never arrives)."""
        # the goals adapter's streams and rule: with the same seed, cosim's own navigation
        # (robots.driver = "navigation") is sent to the same goals in the same order
        self.rngs = [run.rng.stream(f"goals/{name}") for name in names]
        width, height = run.settings(WorldConfig).size_m
        lidar = run.settings(LidarConfig)
        beams = lidar.beams
        self.view = AgentView(
            run=run,
            settings=cfg,
            names=names,
            fleet=fleet,
            limits=drive_limits(run),
            room_m=(width, height),
            goal_xy=np.zeros((n, 2)),
            goal_start_m=np.zeros(n),
            progress_base_m=np.zeros(n),
            arrivals=np.zeros(n, dtype=np.int64),
            contacts=run.service(ContactCounts).by_robot,
            sent=np.zeros(n, dtype=np.int64),
            received=np.zeros(n, dtype=np.int64),
            places=self._places(run, cfg.places),
            ranges_m=np.full((n, beams), lidar.range_max_m),
            range_max_m=lidar.range_max_m,
            heard_xy=np.zeros((n, n, 2)),
            heard_stamp_ns=np.full((n, n), -1, dtype=np.int64),
            heard_recv_ns=np.full((n, n), -1, dtype=np.int64),
            decided_ns=np.zeros(n, dtype=np.int64),
            woken_ns=np.full(n, -1, dtype=np.int64),
            bids=np.zeros((n, cfg.task_slots)),
            epochs=[None] * n,
            epoch_ns=np.full(n, -1, dtype=np.int64),
        )
        self.set_ns = np.zeros(n, dtype=np.int64)
        self.goals_set = np.zeros(n, dtype=np.int64)
        self.table = run.recorder.table(ARRIVALS)
        run.provide(self.view)
        run.bus.advertise(AGENT_STATES, RobotState)
        self._share_topics = [AGENT_STATES] * n
        for i in range(n):
            self._next_goal(i, 0)
        observations, rewards = OBSERVATIONS.installed(), REWARDS.installed()
        terms = [rewards.get(term) for term in cfg.rewards]
        weights = cfg.reward_weights or [float(getattr(term, "weight", 1.0)) for term in terms]
        self.parts = AgentParts(
            action=kind(self.view),
            observations=tuple(observations.get(part)(self.view) for part in cfg.observe),
            rewards=tuple(term(self.view) for term in terms),
            weights=np.array(weights, dtype=float),
        )
        run.provide(self.parts)
        self.size = sum(len(part.low) for part in self.parts.observations)
        self.policy: Policy | None = None
        if cfg.policy != "none":
            policy = POLICIES.installed().get(cfg.policy)
            self.policy = policy(self.view, self.parts, self.size)

    def _places(self, run: RunContext, count: int) -> FloatArray:
        """The places an agent may choose: ``navigation.goals``, else free cells drawn once."""
        if self.series:
            return np.array(self.series, dtype=float)
        cells = self.cells[0]
        if not len(cells):
            return np.zeros((0, 2))
        rng = run.rng.stream("agents/places")
        picked = cells[rng.choice(len(cells), size=min(count, len(cells)), replace=False)]
        xy = [self.static.cell_to_world((int(ix), int(iy))) for iy, ix in picked]
        return np.array(xy, dtype=float).reshape(-1, 2)

    def _next_goal(self, i: int, now_ns: int) -> None:
        view, fleet = self.view, self.fleet
        k = int(self.goals_set[i])
        if not self.goals:  # the bid action: an agent's tasks are its goals
            x, y = fleet.x[i], fleet.y[i]
        elif self.at_places and len(view.places):
            choices = len(view.places)
            pick = (i + k) % choices if self.series else int(self.rngs[i].integers(choices))
            x, y = view.places[pick]
        elif self.series:
            x, y = self.series[(i + k) % len(self.series)]
        elif len(self.cells[i]):
            iy, ix = self.cells[i][int(self.rngs[i].integers(len(self.cells[i])))]
            x, y = self.static.cell_to_world((int(ix), int(iy)))
        else:  # a robot with no free place in its region stays where it is
            x, y = fleet.x[i], fleet.y[i]
        view.goal_xy[i] = (x, y)
        view.goal_start_m[i] = float(np.hypot(x - fleet.x[i], y - fleet.y[i]))
        self.set_ns[i] = now_ns
        self.goals_set[i] += 1

    def start(self, run: RunContext) -> None:
        """Hear the others and the lidar; share poses; check arrivals at the physics rate."""
        for i, (name, host) in enumerate(zip(self.view.names, self.hosts, strict=True)):
            run.bus.subscribe(AGENT_STATES, host, self._on_state(run, i))
            if self.view.ranges_m.shape[1]:
                run.bus.subscribe(scan_topic(name), host, self._on_scan(i))
        if self.cfg.share_hz > 0:
            run.kernel.every(
                period_ns(self.cfg.share_hz), lambda now: self._share(run, now), stage=Stage.CONTROL
            )
        physics = period_ns(run.settings(RobotsConfig).control_hz)
        run.kernel.every(physics, lambda now: self._arrivals(run, now), stage=Stage.SENSING)
        if "contact" in self.cfg.wake_on:
            self._contacts_seen = self.view.contacts.copy()
        if self.policy is not None:
            observations = np.zeros((len(self.view), self.size), dtype=np.float32)
            everyone = np.arange(len(self.view))
            run.kernel.every(
                period_ns(self.cfg.decision_hz),
                lambda now: self._decide(now, self.policy, observations, everyone),
                stage=Stage.DECISION,
            )

    def _decide(
        self, now_ns: int, policy: Policy | None, observations: Float32Array, everyone: IntArray
    ) -> None:
        """The policy's decision for every agent, checked, applied (a plain run's)."""
        assert policy is not None
        view = self.view
        observe_all(self.parts, view, observations)
        actions = np.asarray(policy.act(observations))
        problem = action_problem(self.parts.action.spec, actions, view.names)
        if problem is not None:
            raise refuse(policy, f"act() returned {problem}").at(now_ns)
        self.parts.action.apply(view, everyone, actions)
        view.decided_ns[:] = now_ns

    def _on_state(self, run: RunContext, i: int) -> Callable[[Message, Envelope], None]:
        index = {name: j for j, name in enumerate(self.view.names)}
        view = self.view
        wake = "message" in self.cfg.wake_on

        def on_state(message: Message, envelope: Envelope) -> None:
            assert isinstance(message, RobotState)
            j = index.get(message.robot)
            if j is None or j == i:
                return
            view.heard_xy[i, j] = (message.x_m, message.y_m)
            view.heard_stamp_ns[i, j] = message.stamp_ns
            view.heard_recv_ns[i, j] = envelope.t_recv_ns
            view.received[i] += 1
            if wake:
                view.woken_ns[i] = envelope.t_recv_ns

        return on_state

    def _on_scan(self, i: int) -> Callable[[Message, Envelope], None]:
        ranges = self.view.ranges_m
        range_max = self.view.range_max_m

        def on_scan(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, LaserScan)
            row = np.asarray(message.ranges_m, dtype=float)
            # no return (inf) and a dropped beam (nan) read as the lidar's range
            ranges[i] = np.where(np.isfinite(row), np.minimum(row, range_max), range_max)

        return on_scan

    def _share(self, run: RunContext, now_ns: int) -> None:
        fleet = self.fleet
        radius = float(fleet.radius_m[0]) if len(fleet) else 0.0
        x, y, yaw, v = fleet.x.tolist(), fleet.y.tolist(), fleet.yaw.tolist(), fleet.v.tolist()
        states = [
            RobotState(now_ns, name, x[i], y[i], yaw[i], v[i], radius)
            for i, name in enumerate(fleet.names)
        ]
        # one publication for the fleet, as each robot's own in turn (the bus's batch)
        run.bus.publish_many(self._share_topics, states, self.hosts)
        self.view.sent += 1

    def _arrivals(self, run: RunContext, now_ns: int) -> None:
        view = self.view
        if "contact" in self.cfg.wake_on:
            touched = np.flatnonzero(view.contacts != self._contacts_seen)
            view.woken_ns[touched] = now_ns
            self._contacts_seen[touched] = view.contacts[touched]
        distance = view.goal_distance_m()
        arrived = np.flatnonzero((distance <= self.cfg.goal_tolerance_m) & self.movable)
        for index in arrived:
            i = int(index)
            x, y = view.goal_xy[i]
            self.table.append(
                t_s=now_ns / NS_PER_S,
                robot=view.names[i],
                goal_x_m=float(x),
                goal_y_m=float(y),
                took_s=(now_ns - int(self.set_ns[i])) / NS_PER_S,
                straight_m=float(view.goal_start_m[i]),
            )
            view.arrivals[i] += 1
            view.progress_base_m[i] += view.goal_start_m[i] - distance[i]
            if "arrival" in self.cfg.wake_on:
                view.woken_ns[i] = now_ns
            self._next_goal(i, now_ns)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Arrivals, poses shared and heard."""
        return {
            "agent_arrivals": int(self.view.arrivals.sum()),
            "agent_poses_sent": int(self.view.sent.sum()),
            "agent_poses_heard": int(self.view.received.sum()),
        }
