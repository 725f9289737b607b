"""Poses from Unity scenes: ``mocap.source = "unity"``.

A Unity scene attached to ``cosim run --unity`` (its ROS-TCP-Connector) publishes a
``geometry_msgs/PoseStamped`` in ``map`` for each tracked robot, on the robot's body topic
(``mocap.bodies``, or ``mocap.topic_pattern``, ``/{robot}/pose`` by default). Adapters do
not see the Unity server (it lives in ``cosim.recording``): the hand-over is the run's bus.
Here each body topic is advertised as ``/unity`` + the topic (``/unity/robot_1/pose``,
:class:`~cosim.core.messages.PoseStamped`); the server finds these advertisements, lets
scenes ``__publish`` on the topics behind the prefix, checks every sample (a CDR
PoseStamped, in ``map``, finite) and publishes the newest one of each topic from the
``mocap`` host every 50 ms, stamped with the kernel time it takes it in (Unity's clock is
not the run's). This source keeps them until the mocap adapter polls, and the pose intake
checks them as any live pose (stale, off the map, a jump).
"""

from __future__ import annotations

from typing import Any

from adapters.mocap.live import Sample
from adapters.mocap.settings import MocapConfig
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.hosts import HostId
from cosim.core.messages import Message, PoseStamped
from models.fleet.kinematics import FleetState

UNITY_PREFIX = "/unity"
"""Bus topics carrying Unity's poses: this prefix and the Unity-side topic (the Unity server
in ``cosim.recording.unity.inbound`` spells it the same)."""


def unity_bus_topic(body: str) -> str:
    """The bus topic of the poses a scene publishes on ``body`` (``/unity/robot_1/pose``)."""
    return UNITY_PREFIX + body


def advertise_unity_poses(run: RunContext, bodies: list[tuple[int, str]]) -> None:
    """Advertise each tracked robot's body topic, so that the Unity server takes it."""
    for _index, body in bodies:
        run.bus.advertise(unity_bus_topic(body), PoseStamped)


class UnityPoseSource:
    """Poses of the tracked robots, published by Unity scenes (see the module docstring)."""

    def __init__(self, run: RunContext, cfg: MocapConfig, bodies: list[tuple[int, str]]) -> None:
        self.cfg = cfg
        self.names = list(run.service(FleetState).names)
        self.topic = dict(bodies)
        self.pending: list[Sample] = []
        self.received = 0
        self.not_in_map = 0
        host = HostId("mocap")
        for index, body in bodies:
            run.bus.subscribe(unity_bus_topic(body), host, self._on_pose(index))

    def _on_pose(self, index: int) -> Any:
        def on_pose(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, PoseStamped)
            self.received += 1
            if message.frame_id != "map":  # the server checks it; a plugin might not
                self.not_in_map += 1
                return
            self.pending.append(
                (index, message.stamp_ns, message.x_m, message.y_m, message.yaw_rad)
            )

        return on_pose

    def take(self, now_ns: int) -> list[Sample]:
        """The poses published since the last poll, oldest first."""
        taken, self.pending = self.pending, []
        return taken

    def close(self) -> None:
        """Nothing to disconnect: the Unity server belongs to the run."""

    def summary(self) -> dict[str, Any]:
        """Poses received from Unity (before the intake's checks)."""
        return {"mocap_unity_poses": self.received, "mocap_unity_not_in_map": self.not_in_map}

    def failure(self) -> str | None:
        """Scenes come and go (the Connector reconnects): never a failure, only silence."""
        return None

    def silence(self, index: int) -> str:
        """The topic listened on, and how a scene must send it."""
        return (
            f"no pose of {self.names[index]} within {self.cfg.connect_timeout_s:g} s: listened "
            f"for geometry_msgs/PoseStamped in 'map' on {self.topic[index]} from Unity scenes "
            "(mocap.source = 'unity': run with --unity and have the scene publish it)"
        )
