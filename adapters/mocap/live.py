"""Live pose sources: a motion-capture system through ``motioncapture``, or ROS 2 over DDS.

Both are polled from the kernel (no callback runs on another thread's time): each poll
takes what arrived since the last one and maps its wall-clock stamps to kernel time with
the real-time kernel's clock. Nothing received is trusted: samples that are not a pose
are counted and dropped here, the rest go through the pose intake's checks.

Nothing here waits for the system: the mocap adapter asks each poll whether the source
failed (:meth:`LiveSource.failure`) and, once ``mocap.connect_timeout_s`` has passed
without a pose of some tracked robot, ends the run with :class:`LiveSourceError` saying
what the source got that far (:meth:`LiveSource.silence`).
"""

from __future__ import annotations

from typing import Any, Protocol

from adapters.mocap.feed import MotionCaptureFeed, mock_bodies
from adapters.mocap.settings import MocapConfig
from adapters.ros2dds.qos import QosKind
from adapters.ros2dds.session import dds_session
from adapters.ros2dds.types import PoseStamped as DdsPoseStamped
from adapters.ros2dds.types import planar_pose
from cosim.core.adapter import RunContext
from cosim.core.errors import BridgeError
from models.fleet.kinematics import FleetState

Sample = tuple[int, int, float, float, float]
"""(robot index, stamp in kernel ns, x_m, y_m, yaw_rad) in ``map``."""


class LiveSourceError(BridgeError):
    """A live pose source failed, or sent no pose of a tracked robot in time."""


class LiveSource(Protocol):
    """What the mocap adapter polls."""

    def take(self, now_ns: int) -> list[Sample]:
        """The poses that arrived since the last call, oldest first."""
        ...

    def close(self) -> None:
        """Disconnect."""
        ...

    def summary(self) -> dict[str, Any]:
        """Counts for the run's summary."""
        ...

    def failure(self) -> str | None:
        """Why the source delivers nothing more (one line), or None while it may."""
        ...

    def silence(self, index: int) -> str:
        """What was listened to for robot ``index``, and what came (for an error line)."""
        ...


class MotionCaptureSource:
    """Rigid bodies of a live mocap system, one per tracked robot."""

    def __init__(self, run: RunContext, cfg: MocapConfig, bodies: list[tuple[int, str]]) -> None:
        self.kernel = run.kernel
        self.cfg = cfg
        self.body = {index: body for index, body in bodies}
        self.index = {body: index for index, body in bodies}
        fleet = run.service(FleetState)
        self.names = list(fleet.names)
        options = {}
        if cfg.system == "mock":
            # a mock system holds each body where its robot starts (demos and tests)
            options["rigid_bodies"] = mock_bodies(
                {body: (fleet.x[i], fleet.y[i], fleet.yaw[i]) for body, i in self.index.items()}
            )
        self.feed = MotionCaptureFeed(
            cfg.system, hostname=cfg.hostname, bodies=list(self.index), options=options
        )

    def take(self, now_ns: int) -> list[Sample]:
        """Frames since the last poll, stamped on arrival (wall clock)."""
        sim_ns = self.kernel.sim_ns
        return [
            (self.index[body], sim_ns(t_ns), x, y, yaw)
            for t_ns, body, x, y, yaw in self.feed.drain()
            if body in self.index
        ]

    def close(self) -> None:
        """Stop the feed's thread."""
        self.feed.close()

    def summary(self) -> dict[str, Any]:
        """Bodies never seen."""
        return {"mocap_missing_bodies": len(self.feed.missing_bodies())}

    def where(self) -> str:
        """``the vicon motion capture at '10.0.0.5'``."""
        host = f" at {self.cfg.hostname!r}" if self.cfg.hostname else ""
        return f"the {self.cfg.system} motion capture{host}"

    def failure(self) -> str | None:
        """The library's or the worker's last words, naming the system and its host."""
        failure = self.feed.failure()
        if failure is None:
            return None
        return f"{self.where()}: {failure}"

    def silence(self, index: int) -> str:
        """Not connected, connected but no frame, or frames without this robot's body."""
        feed, waited = self.feed, f"{self.cfg.connect_timeout_s:g} s"
        if not feed.connected:
            return f"{self.where()} did not answer within {waited} (no connection)"
        if feed.frames == 0:
            return f"{self.where()} accepted the connection but sent no frame within {waited}"
        occluded = f", {feed.occluded} times occluded" if feed.occluded else ""
        return (
            f"no pose of {self.names[index]} within {waited} from {self.where()}: "
            f"listened for rigid body {self.body[index]!r} ({feed.frames} frames came, none "
            f"with it{occluded})"
        )


class Ros2PoseSource:
    """PoseStamped topics over DDS, one per tracked robot (as ros2-vicon-receiver publishes)."""

    def __init__(self, run: RunContext, cfg: MocapConfig, bodies: list[tuple[int, str]]) -> None:
        self.kernel = run.kernel
        self.cfg = cfg
        self.names = list(run.service(FleetState).names)
        self.topic = dict(bodies)
        self.session = dds_session(run)
        participant = self.session.participant
        self.subscriptions = [
            (index, participant.subscription(topic, DdsPoseStamped, QosKind.SENSOR_DATA))
            for index, topic in bodies
        ]
        self.invalid = 0

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

    def close(self) -> None:
        """Leave the DDS domain (shared with the physical bridge; closed once)."""
        self.session.close()

    def summary(self) -> dict[str, Any]:
        """Samples refused before the intake, and those that failed to deserialize."""
        return {
            "mocap_dds_invalid": self.invalid,
            "mocap_dds_malformed": sum(s.malformed for _, s in self.subscriptions),
        }

    def failure(self) -> str | None:
        """DDS has no connection to lose: never."""
        return None

    def silence(self, index: int) -> str:
        """The topic and the DDS domain listened on."""
        return (
            f"no pose of {self.names[index]} within {self.cfg.connect_timeout_s:g} s: listened "
            f"for geometry_msgs/PoseStamped on {self.topic[index]} on {self.session.where()} "
            "(mocap.source = 'ros2')"
        )


def open_live_source(
    run: RunContext, cfg: MocapConfig, bodies: list[tuple[int, str]]
) -> LiveSource:
    """Connect the live source ``cfg.source`` names."""
    if cfg.source == "motioncapture":
        return MotionCaptureSource(run, cfg, bodies)
    if cfg.source == "unity":
        from adapters.mocap.unity import UnityPoseSource  # it imports this module's Sample

        return UnityPoseSource(run, cfg, bodies)
    return Ros2PoseSource(run, cfg, bodies)
