"""``mocap.source = "ros2"``: live ``geometry_msgs/PoseStamped`` topics over DDS.

As ros2-vicon-receiver publishes a Vicon system's subjects (``/vicon/<subject>/<segment>``),
one topic per tracked robot, taken from the run's DDS domain
(:mod:`adapters.ros2dds.session`); stamps are the senders' (ROS time, wall clock). By
default each robot posed from outside (a physical robot) is tracked on
``mocap.topic_pattern`` with its name filled in.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any, ClassVar

from adapters.mocap.contract import SourceContext, Tracked, bodies_or
from adapters.mocap.live import LIVE_SUMMARY, PolledSource, Sample
from adapters.mocap.settings import MocapConfig, topic_problem
from adapters.ros2dds.qos import QosKind
from adapters.ros2dds.session import DdsSession, dds_session
from adapters.ros2dds.types import PoseStamped as DdsPoseStamped
from adapters.ros2dds.types import planar_pose
from cosim.core.adapter import RunContext
from cosim.core.summary import SummaryKey
from cosim.scenario.fields import Problem


def topic_bodies_problems(mocap: MocapConfig) -> Iterator[Problem]:
    """Every body must be a ROS 2 topic, and without bodies the pattern must name the robot."""
    if "{robot}" not in mocap.topic_pattern and not mocap.bodies:
        yield Problem("topic_pattern", mocap.topic_pattern, "a pattern containing {robot}")
    for robot, body in mocap.bodies:
        reason = topic_problem(body)
        if reason is not None:
            yield Problem("bodies", [robot, body], f"a ROS 2 topic for {mocap.source} ({reason})")


def pattern_tracks(mocap: MocapConfig, outside: Mapping[str, str]) -> Tracked:
    """``mocap.bodies``, or each robot posed from outside on ``mocap.topic_pattern``."""
    return bodies_or(mocap, outside, lambda robot: mocap.topic_pattern.replace("{robot}", robot))


class Ros2PoseSource(PolledSource):
    """PoseStamped topics over DDS, one per tracked robot (see the module)."""

    name: ClassVar[str] = "ros2"
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        **LIVE_SUMMARY,
        "mocap_dds_invalid": SummaryKey(
            "count", "PoseStamped samples that hold no planar pose (refused before the intake)"
        ),
        "mocap_dds_malformed": SummaryKey("count", "DDS samples that failed to deserialize"),
    }
    """The summary keys :meth:`summary` writes (documented in the summary reference)."""
    uses_dds: ClassVar[bool] = True
    keys: ClassVar[tuple[str, ...]] = ("bodies",)
    settings_hint: ClassVar[str] = "mocap.bodies or mocap.topic_pattern, and physical.dds_domain"

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
        """The topic and its type (the bridge adds the DDS domain)."""
        return f"geometry_msgs/PoseStamped on {body}"

    def __init__(self, context: SourceContext) -> None:
        super().__init__(context)
        self.topic = dict(context.tracked)
        self.invalid = 0

    def connect(self, run: RunContext) -> None:
        """Join the run's DDS domain and subscribe to every body's topic."""
        self.kernel = run.kernel
        self.session: DdsSession = dds_session(run)
        participant = self.session.participant
        self.subscriptions = [
            (index, participant.subscription(topic, DdsPoseStamped, QosKind.SENSOR_DATA))
            for index, topic in self.context.tracked
        ]

    def take(self, now_ns: int) -> list[Sample]:
        """Samples since the last poll; stamps are the senders' (ROS time, wall clock)."""
        sim_ns = self.kernel.sim_ns
        out: list[Sample] = []
        for index, subscription in self.subscriptions:
            for sample in subscription.take():
                pose = planar_pose(sample.header, sample.pose)
                if pose is None:
                    self.invalid += 1
                    continue
                out.append((index, sim_ns(pose[0]), pose[1], pose[2], pose[3]))
        return out

    def disconnect(self) -> None:
        """Leave the DDS domain (shared with the physical bridge; closed once)."""
        self.session.close()

    def counts(self) -> Mapping[str, Any]:
        """Samples refused before the intake, and those that failed to deserialize."""
        return {
            "mocap_dds_invalid": self.invalid,
            "mocap_dds_malformed": sum(s.malformed for _, s in self.subscriptions),
        }

    def silence(self, index: int) -> str:
        """The topic and the DDS domain listened on."""
        return (
            f"no pose of {self.names[index]} within {self.waited_s:g} s: listened "
            f"for geometry_msgs/PoseStamped on {self.topic[index]} on {self.session.where()} "
            "(mocap.source = 'ros2')"
        )
