"""The robots layer: every robot's pose and footprint broadcast over the network.

With ``navigation.robots_layer`` each robot publishes a :class:`~cosim.core.messages.RobotState`
on ``/fleet/robot_states`` at ``robots_layer_hz`` (latency and loss apply), and each keeps
what it last heard from the others; a robot not heard from for ``robots_layer_timeout_s``
is forgotten. The navigation builds it and offers it as a service of the run: the global
planner and the local controller avoid the discs it knows, and the robots' mapping leaves
returns off them out of their maps.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from adapters.fleet.topics import ROBOT_STATES
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.messages import Message, RobotState
from cosim.core.timebase import period_ns, s_to_ns
from models.arrays import FloatArray, IntArray


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
        self.others: list[dict[int, tuple[float, float, float, int]]] = [{} for _ in names]
        """Per robot: robot index -> (x_m, y_m, radius_m, t_recv_ns) last heard."""

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
                self.others[i][k] = (message.x_m, message.y_m, message.radius_m, envelope.t_recv_ns)

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
        known = [
            (x, y, r) for x, y, r, t in self.others[i].values() if now_ns - t <= self.timeout_ns
        ]
        return np.array(known, dtype=float).reshape(-1, 3)

    def all_discs(self, now_ns: int) -> tuple[FloatArray, IntArray]:
        """Every robot's :meth:`discs`, CSR-packed.

        Returns:
            ``(discs, start)``: robot ``i`` owns ``discs[start[i]:start[i + 1]]``.
        """
        start = np.zeros(len(self.names) + 1, dtype=np.int64)
        parts = [self.discs(i, now_ns) for i in range(len(self.names))]
        np.cumsum([len(p) for p in parts], out=start[1:])
        return (np.vstack(parts) if parts else np.zeros((0, 3))), start
