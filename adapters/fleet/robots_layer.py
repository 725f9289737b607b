"""The robots layer: every robot's pose and footprint broadcast over the network.

With ``navigation.robots_layer`` each robot publishes a :class:`~cosim.core.messages.RobotState`
on ``/fleet/robot_states`` at ``robots_layer_hz`` (latency and loss apply), and each keeps
what it last heard from the others; a robot not heard from for ``robots_layer_timeout_s``
is forgotten. The navigation builds it and offers it as a service of the run: the global
planner and the local controller avoid the discs it knows, and the robots' mapping leaves
returns off them out of their maps.

Besides the discs, each robot knows how the others were moving and how old that news is
(:meth:`RobotsLayer.neighbours`): the velocity in ``map`` from the heard heading and speed,
and the age since the state's stamp (the time it was sent), so that network latency shows
up as age. A local controller may extrapolate the others' positions by their age.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from adapters.fleet.topics import ROBOT_STATES
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import Message, RobotState
from cosim.core.timebase import NS_PER_S, period_ns, s_to_ns
from models.arrays import FloatArray, IntArray


class Heard(NamedTuple):
    """What a robot last heard from another one.

    Attributes:
        x_m, y_m: its position in ``map`` (m).
        radius_m: its footprint radius (m).
        yaw_rad: its heading in ``map`` (rad).
        v_mps: its forward speed (m/s).
        stamp_ns: the state's stamp: when it was sent (ns).
        t_recv_ns: when it arrived (ns).
    """

    x_m: float
    y_m: float
    radius_m: float
    yaw_rad: float
    v_mps: float
    stamp_ns: int
    t_recv_ns: int


class RobotsLayer:
    """What each robot heard of the others' poses and footprints.

    Args:
        names: robot names, in fleet order.
        hosts: each robot's host.
        radius_m: footprint radius every robot broadcasts (m).
        timeout_s: forget a robot not heard from for this long (s).
    """

    def __init__(
        self, names: list[str], hosts: list[HostId], radius_m: float, timeout_s: float
    ) -> None:
        self.names = names
        self.hosts = hosts
        self.radius_m = radius_m
        self.timeout_ns = s_to_ns(timeout_s)
        self.others: list[dict[int, Heard]] = [{} for _ in names]
        """Per robot: robot index -> what it last heard from that robot."""

    def advertise(self, run: RunContext) -> None:
        """Declare the broadcast topic."""
        run.bus.advertise(ROBOT_STATES, RobotState)

    def start(self, run: RunContext, rate_hz: float, poses: FloatArray, speeds: FloatArray) -> None:
        """Listen on every host and broadcast ``poses`` (n, 3) and ``speeds`` (n,) at ``rate_hz``.

        The arrays are read at each broadcast (the caller updates them in place).
        """
        for i, host in enumerate(self.hosts):
            run.bus.subscribe(ROBOT_STATES, host, self._on_state(i))
        run.kernel.every(
            period_ns(rate_hz),
            lambda now: self._broadcast(run, now, poses, speeds),
            stage=Stage.CONTROL,
        )

    def _on_state(self, i: int) -> Callable[[Message, Envelope], None]:
        me = self.names[i]
        index = {name: k for k, name in enumerate(self.names)}

        def on_state(message: Message, envelope: Envelope) -> None:
            assert isinstance(message, RobotState)
            if message.robot != me:
                k = index[message.robot]
                self.others[i][k] = Heard(
                    message.x_m,
                    message.y_m,
                    message.radius_m,
                    message.yaw_rad,
                    message.v_mps,
                    message.stamp_ns,
                    envelope.t_recv_ns,
                )

        return on_state

    def _broadcast(
        self, run: RunContext, now_ns: int, poses: FloatArray, speeds: FloatArray
    ) -> None:
        for i, host in enumerate(self.hosts):
            x, y, yaw = poses[i]
            state = RobotState(
                now_ns,
                self.names[i],
                float(x),
                float(y),
                float(yaw),
                float(speeds[i]),
                self.radius_m,
            )
            run.bus.publish(ROBOT_STATES, state, host)

    def discs(self, i: int, now_ns: int) -> FloatArray:
        """(k, 3) discs ``x, y, r`` (m, ``map``) of the robots ``i`` heard from recently."""
        return self._known(i, now_ns)[0]

    def neighbours(self, i: int, now_ns: int) -> FloatArray:
        """(k, 5) ``x, y, vx, vy, age_s`` of the robots ``i`` heard from recently.

        Row for row with :meth:`discs`: positions (m) and velocities (m/s) in ``map`` as
        heard (the velocity is the heard speed along the heard heading), and the age (s)
        of that news at ``now_ns``: ``now_ns`` minus the state's stamp, the time it was
        sent, so the network's latency is part of it.
        """
        return self._known(i, now_ns)[1]

    def _known(self, i: int, now_ns: int) -> tuple[FloatArray, FloatArray]:
        """Robot ``i``'s :meth:`discs` and :meth:`neighbours`, in the order first heard."""
        recent = [h for h in self.others[i].values() if now_ns - h.t_recv_ns <= self.timeout_ns]
        discs = np.array([(h.x_m, h.y_m, h.radius_m) for h in recent], dtype=float)
        neighbours = np.array(
            [
                (
                    h.x_m,
                    h.y_m,
                    h.v_mps * math.cos(h.yaw_rad),
                    h.v_mps * math.sin(h.yaw_rad),
                    max(now_ns - h.stamp_ns, 0) / NS_PER_S,
                )
                for h in recent
            ],
            dtype=float,
        )
        return discs.reshape(-1, 3), neighbours.reshape(-1, 5)

    def all_discs(self, now_ns: int) -> tuple[FloatArray, IntArray]:
        """Every robot's :meth:`discs`, CSR-packed.

        Returns:
            ``(discs, start)``: robot ``i`` owns ``discs[start[i]:start[i + 1]]``.
        """
        discs, _, start = self.all_neighbours(now_ns)
        return discs, start

    def all_neighbours(self, now_ns: int) -> tuple[FloatArray, FloatArray, IntArray]:
        """Every robot's :meth:`discs` and :meth:`neighbours`, CSR-packed, row for row.

        Returns:
            ``(discs, neighbours, start)``: robot ``i`` owns rows ``start[i]:start[i + 1]``
            of ``discs`` (k, 3) and of ``neighbours`` (k, 5).
        """
        start = np.zeros(len(self.names) + 1, dtype=np.int64)
        known = [self._known(i, now_ns) for i in range(len(self.names))]
        np.cumsum([len(discs) for discs, _ in known], out=start[1:])
        if not known:
            return np.zeros((0, 3)), np.zeros((0, 5)), start
        return np.vstack([d for d, _ in known]), np.vstack([m for _, m in known]), start
