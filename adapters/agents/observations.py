"""cosim's own observation parts, registered in ``cosim.agent_observations`` as a plugin's are.

Every part writes all agents' values at once; its bounds are exact (values are clipped to
them). Positions of other things are given in the agent's body frame (x ahead, y to the
left, m; REP 103), so a policy learnt in one place of the room holds in another.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from adapters.agents.contract import AgentView
from cosim.core.errors import ConfigError
from cosim.core.timebase import NS_PER_S
from models.agents.features import sector_minima, to_body
from models.arrays import Float32Array, FloatArray


def _bounds(low: list[float], high: list[float]) -> tuple[FloatArray, FloatArray]:
    return np.array(low, dtype=np.float32), np.array(high, dtype=np.float32)


def _diagonal(view: AgentView) -> float:
    return float(np.hypot(*view.room_m))


class Pose:
    """``pose``: the agent's own pose in ``map``: x, y (m), cos and sin of its heading."""

    name: ClassVar[str] = "pose"

    def __init__(self, view: AgentView) -> None:
        width, height = view.room_m
        self.low, self.high = _bounds([0.0, 0.0, -1.0, -1.0], [width, height, 1.0, 1.0])

    def observe(self, view: AgentView, out: Float32Array) -> None:
        """x, y, cos(yaw), sin(yaw) of every agent."""
        fleet = view.fleet
        out[:, 0], out[:, 1] = fleet.x, fleet.y
        out[:, 2], out[:, 3] = np.cos(fleet.yaw), np.sin(fleet.yaw)
        np.clip(out, self.low, self.high, out=out)


class Velocity:
    """``velocity``: the agent's forward speed (m/s) and yaw rate (rad/s)."""

    name: ClassVar[str] = "velocity"

    def __init__(self, view: AgentView) -> None:
        limits = view.limits
        self.low, self.high = _bounds(
            [-limits.max_reverse_mps, -limits.max_yaw_rate_radps],
            [limits.max_speed_mps, limits.max_yaw_rate_radps],
        )

    def observe(self, view: AgentView, out: Float32Array) -> None:
        """V and w of every agent."""
        out[:, 0], out[:, 1] = view.fleet.v, view.fleet.w
        np.clip(out, self.low, self.high, out=out)


class Goal:
    """``goal``: the agent's goal ahead and to its left (m, body frame) and its distance (m)."""

    name: ClassVar[str] = "goal"

    def __init__(self, view: AgentView) -> None:
        reach = _diagonal(view)
        self.low, self.high = _bounds([-reach, -reach, 0.0], [reach, reach, reach])

    def observe(self, view: AgentView, out: Float32Array) -> None:
        """Where every agent's goal is, seen from the agent."""
        fleet = view.fleet
        dx, dy = view.goal_xy[:, 0] - fleet.x, view.goal_xy[:, 1] - fleet.y
        out[:, 0], out[:, 1] = to_body(dx, dy, fleet.yaw)
        out[:, 2] = np.hypot(dx, dy)
        np.clip(out, self.low, self.high, out=out)


class Lidar:
    """``lidar``: the nearest return in each of ``agents.lidar_bins`` sectors of the scan (m).

    Sectors follow the beams' order (REP 117: counter-clockwise from ``lidar.fov``'s start);
    no return reads as the lidar's range. The latest scan the agent's lidar published.
    """

    name: ClassVar[str] = "lidar"

    def __init__(self, view: AgentView) -> None:
        if view.ranges_m.shape[1] == 0:
            raise ConfigError(
                f"{view.run.scenario.source}: [agents] observe has 'lidar': expected "
                "lidar.beams > 0 (the robots have no lidar)"
            )
        bins = view.settings.lidar_bins
        self.low = np.zeros(bins, dtype=np.float32)
        self.high = np.full(bins, view.range_max_m, dtype=np.float32)

    def observe(self, view: AgentView, out: Float32Array) -> None:
        """Every agent's sector minima."""
        out[:] = sector_minima(view.ranges_m, len(self.low))


class Inbox:
    """``inbox``: what the agent heard of each other agent over the network.

    For every other agent, in fleet order: where it was when it sent its latest pose the
    agent received (ahead, left; m, body frame), how old that news is now (s: the time
    since it was sent, network latency included) and whether it arrived since the agent's
    previous decision (1) or not (0). News older than ``agents.inbox_max_age_s``, or none,
    reads ``0, 0, inbox_max_age_s, 0``. 4 x (agents - 1) numbers.
    """

    name: ClassVar[str] = "inbox"

    def __init__(self, view: AgentView) -> None:
        n = len(view)
        reach, age = _diagonal(view), view.settings.inbox_max_age_s
        self.max_age_s = age
        self.low, self.high = _bounds(
            [-reach, -reach, 0.0, 0.0] * (n - 1), [reach, reach, age, 1.0] * (n - 1)
        )
        self.others = ~np.eye(n, dtype=bool)

    def observe(self, view: AgentView, out: Float32Array) -> None:
        """Every agent's news of the others."""
        n = len(view)
        if n < 2:
            return
        fleet, now = view.fleet, view.now_ns
        others = self.others
        stamp = view.heard_stamp_ns[others].reshape(n, n - 1)
        recv = view.heard_recv_ns[others].reshape(n, n - 1)
        xy = view.heard_xy[others].reshape(n, n - 1, 2)
        age_s = (now - stamp) / NS_PER_S
        known = (stamp >= 0) & (age_s <= self.max_age_s)
        ahead, left = to_body(
            xy[..., 0] - fleet.x[:, None], xy[..., 1] - fleet.y[:, None], fleet.yaw
        )
        rows = out.reshape(n, n - 1, 4)
        rows[..., 0] = np.where(known, ahead, 0.0)
        rows[..., 1] = np.where(known, left, 0.0)
        rows[..., 2] = np.where(known, age_s, self.max_age_s)
        rows[..., 3] = known & (recv > view.decided_ns[:, None])
        np.clip(out, self.low, self.high, out=out)


class Places:
    """``places``: where each place of the goal action is, ahead and left of the agent (m).

    2 x ``agents.places`` numbers (or 2 per ``navigation.goals`` point), in the places' order.
    """

    name: ClassVar[str] = "places"

    def __init__(self, view: AgentView) -> None:
        k, reach = len(view.places), _diagonal(view)
        self.low, self.high = _bounds([-reach] * 2 * k, [reach] * 2 * k)

    def observe(self, view: AgentView, out: Float32Array) -> None:
        """Every place seen from every agent."""
        fleet, places = view.fleet, view.places
        if not len(places):
            return
        dx = places[None, :, 0] - fleet.x[:, None]
        dy = places[None, :, 1] - fleet.y[:, None]
        ahead, left = to_body(dx, dy, fleet.yaw)
        rows = out.reshape(len(view), len(places), 2)
        rows[..., 0], rows[..., 1] = ahead, left
        np.clip(out, self.low, self.high, out=out)


class Tasks:
    """``tasks``: the open tasks the agent bids for (the bid action), slot by slot.

    For each of the first ``agents.task_slots`` tasks of the latest epoch that reached the
    agent's robot: where its station is (ahead, left; m, body frame), the robot's travel cost
    to it (m, clipped to twice the room's perimeter) and whether it is free for this robot
    (1: nobody else holds or claims it and the robot may serve it). An empty slot reads
    ``0, 0, cost bound, 0``. 4 x ``agents.task_slots`` numbers.
    """

    name: ClassVar[str] = "tasks"

    def __init__(self, view: AgentView) -> None:
        slots, reach = view.settings.task_slots, _diagonal(view)
        self.slots = slots
        self.cost_bound = 4.0 * sum(view.room_m)
        self.low, self.high = _bounds(
            [-reach, -reach, 0.0, 0.0] * slots, [reach, reach, self.cost_bound, 1.0] * slots
        )

    def observe(self, view: AgentView, out: Float32Array) -> None:
        """Every agent's task slots."""
        fleet = view.fleet
        rows = out.reshape(len(view), self.slots, 4)
        rows[:] = 0.0
        rows[..., 2] = self.cost_bound
        for i, epoch in enumerate(view.epochs):
            if epoch is None:
                continue
            tasks = epoch.tasks[: self.slots]
            if not tasks:
                continue
            k = len(tasks)
            dx = np.array([t.x_m for t in tasks]) - fleet.x[i]
            dy = np.array([t.y_m for t in tasks]) - fleet.y[i]
            ahead, left = to_body(dx, dy, np.full(k, fleet.yaw[i]))
            cost = np.asarray(epoch.problem.cost[i, :k], dtype=float)
            free = np.array([j not in epoch.taken for j in range(k)]) & np.isfinite(cost)
            bound = self.cost_bound
            rows[i, :k, 0], rows[i, :k, 1] = ahead, left
            rows[i, :k, 2] = np.minimum(np.nan_to_num(cost, posinf=bound), bound)
            rows[i, :k, 3] = free
        np.clip(out, self.low, self.high, out=out)
