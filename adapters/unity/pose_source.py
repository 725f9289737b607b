"""``mocap.source = "unity"``: poses that Unity scenes publish.

A Unity scene attached to ``cosim run --unity`` (its ROS-TCP-Connector) publishes a
``geometry_msgs/PoseStamped`` in ``map`` for each tracked robot, on the robot's body topic
(``mocap.bodies``, or ``mocap.topic_pattern``, ``/{robot}/pose`` by default). The source
does not see the Unity endpoint (:mod:`adapters.unity.server`): the hand-over is the run's
bus. Each body topic is advertised as ``/unity`` + the topic (``/unity/robot_1/pose``,
:class:`~cosim.core.messages.PoseStamped`); the server finds these advertisements, lets
scenes ``__publish`` on the topics behind the prefix, checks every sample (a CDR
PoseStamped, in ``map``, finite) and publishes the newest one of each topic from the
``mocap`` host every 50 ms, stamped with the kernel time it takes it in (Unity's clock is
not the run's). This source keeps them until it is polled, and the pose intake checks
them as any live pose (stale, off the map, a jump). The runner offers the run's endpoint as
a service (:class:`~adapters.unity.server.UnitySink`): a run serving no Unity scene, where
no pose can ever come, ends as it starts, and a silent one names where scenes had to
connect.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any, ClassVar

from adapters.mocap.contract import SourceContext, Tracked
from adapters.mocap.live import LIVE_SUMMARY, LiveSourceError, PolledSource, Sample
from adapters.mocap.ros2 import pattern_tracks, topic_bodies_problems
from adapters.mocap.settings import MocapConfig
from adapters.unity.server import UnitySink
from adapters.unity.topics import pose_bus_topic
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope
from cosim.core.errors import RegistryError
from cosim.core.messages import Message, PoseStamped
from cosim.core.summary import SummaryKey
from cosim.scenario.fields import Problem


class UnityPoseSource(PolledSource):
    """Poses of the tracked robots, published by Unity scenes (see the module docstring)."""

    name: ClassVar[str] = "unity"
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        **LIVE_SUMMARY,
        "mocap_unity_poses": SummaryKey(
            "count", "poses received from Unity scenes (before the intake's checks)"
        ),
        "mocap_unity_not_in_map": SummaryKey(
            "count", "of those, poses refused for a frame other than map"
        ),
    }
    """The summary keys :meth:`summary` writes (documented in the summary reference)."""
    uses_dds: ClassVar[bool] = False
    keys: ClassVar[tuple[str, ...]] = ("bodies",)
    settings_hint: ClassVar[str] = "mocap.bodies or mocap.topic_pattern, and cosim run --unity"

    @classmethod
    def problems(cls, mocap: MocapConfig) -> Iterator[Problem]:
        """Topics, or a pattern that makes one per robot."""
        yield from topic_bodies_problems(mocap)

    @classmethod
    def tracks(cls, mocap: MocapConfig, outside: Mapping[str, str], names: list[str]) -> Tracked:
        """``mocap.bodies``, or each robot posed from outside on ``mocap.topic_pattern``."""
        return pattern_tracks(mocap, outside)

    @classmethod
    def describe(cls, mocap: MocapConfig, body: str) -> str:
        """The topic a scene publishes on."""
        return f"geometry_msgs/PoseStamped on {body} from Unity scenes"

    def __init__(self, context: SourceContext) -> None:
        super().__init__(context)
        self.topic = dict(context.tracked)
        self.pending: list[Sample] = []
        self.received = 0
        self.not_in_map = 0
        for _index, body in context.tracked:  # now, so that the Unity server finds them
            context.run.bus.advertise(pose_bus_topic(body), PoseStamped)

    def connect(self, run: RunContext) -> None:
        """Listen on every body's bus topic on the ``mocap`` host.

        Raises:
            LiveSourceError: the run serves no Unity scene (no ``--unity``): no pose can come.
        """
        if self.endpoint() is None and self.context.tracked:
            index, body = self.context.tracked[0]
            raise LiveSourceError(
                f"mocap.source = 'unity': no pose of {self.names[index]} can come (on {body}): "
                "this run serves no Unity scene; expected cosim run --unity "
                "(from Python: cosim.run(..., unity=UnityOptions()))"
            )
        for index, body in self.context.tracked:
            run.bus.subscribe(pose_bus_topic(body), self.context.host, self._on_pose(index))

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

    def counts(self) -> Mapping[str, Any]:
        """Poses received from Unity (before the intake's checks)."""
        return {"mocap_unity_poses": self.received, "mocap_unity_not_in_map": self.not_in_map}

    def endpoint(self) -> UnitySink | None:
        """The run's Unity endpoint, or None when it serves no Unity scene."""
        try:
            return self.context.run.service(UnitySink)
        except RegistryError:
            return None

    def silence(self, index: int) -> str:
        """The topic listened on, where scenes connect, and how a scene must send it."""
        sink = self.endpoint()
        if sink is None:
            where = "no ROS-TCP-Endpoint (run with --unity)"
        else:
            clients = sink.summary()["unity_clients"]
            where = (
                f"the ROS-TCP-Endpoint at {sink.options.host}:{sink.port} ({clients} "
                "connections; a scene registers the topic with __publish, then publishes)"
            )
        return (
            f"no pose of {self.names[index]} within {self.waited_s:g} s: listened for "
            f"geometry_msgs/PoseStamped in 'map' on {self.topic[index]} from Unity scenes on "
            f"{where}"
        )
