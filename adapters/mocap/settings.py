"""The ``[mocap]`` section: a motion-capture pose source for the robots' software.

The paper tracks its Jackal with a Vicon system (Vicon Tracker 3.10) and brings the poses
into ROS 2 with ``ros2-vicon-receiver``. The default noise (1 mm, 2 mrad) is of the order
of what Merriaux et al. measured for a Vicon system ("A Study of Vicon System Positioning
Performance", Sensors 17(7), 2017: millimetre-level errors); the default rate, 100 Hz, is
a common Vicon tracking rate, and the 5 ms latency a chosen value for camera processing
plus the bridge, not a measured one.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import ClassVar, Literal

from cosim.scenario.fields import Problem, param

MocapSource = Literal["none", "simulated", "bag", "motioncapture", "ros2"]

EXTERNAL_SOURCES = ("bag", "motioncapture", "ros2")
"""Sources whose poses come from outside the simulation: they move the robots they track."""


@dataclass(frozen=True)
class MocapConfig:
    """``[mocap]``: a motion-capture pose source for the robots' software."""

    ORDER: ClassVar[int] = 100
    """Where the section comes in a resolved scenario and in the adapters' order."""

    source: MocapSource = param(
        "none",
        "where the poses come from: none (robots localize by odometry), simulated (from "
        "ground truth with rate, latency, noise, dropouts), bag (a recorded ROS 2 bag or a "
        "CSV replayed), motioncapture (live, through the motioncapture library), or ros2 "
        "(live PoseStamped topics over DDS)",
    )
    robots: tuple[str, ...] = param(
        (), "simulated: the robots tracked (empty: all); other sources: see bodies"
    )
    bodies: tuple[tuple[str, str], ...] = param(
        (),
        "[[robot, body], ...]: what tracks each robot; body is a topic in the bag (bag), a "
        "rigid-body name (motioncapture) or a ROS topic (ros2). Empty: robot_0 with the "
        "bag's only pose topic (bag), each physical robot by its name (motioncapture) or "
        "on topic_pattern (ros2)",
    )
    rate_hz: float = param(100.0, "simulated: frames per second (Hz)", gt=0, le=2000)
    latency_ms: float = param(
        5.0, "simulated: time from the instant a frame shows to its pose being sent (ms)", ge=0
    )
    noise_std_m: float = param(0.001, "simulated: Gaussian position noise per axis (m)", ge=0)
    noise_std_rad: float = param(0.002, "simulated: Gaussian yaw noise (rad)", ge=0)
    dropout: float = param(
        0.0, "simulated: probability that a body is missing from a frame", ge=0, le=1
    )
    max_age_ms: float = param(
        200.0, "a robot whose newest pose is older than this stops (zero velocity) (ms)", gt=0
    )
    jump_tolerance_m: float = param(
        0.05,
        "a pose further from the last one than the robot can drive in between, by more "
        "than this, is rejected as a jump (m)",
        ge=0,
    )
    file: str = param("", "bag: the ROS 2 bag (folder, .mcap, .db3) or CSV to replay", path=True)
    system: str = param(
        "vicon",
        "motioncapture: the backend (vicon, optitrack, qualisys, vrpn, mock, ... as the "
        "motioncapture library names them)",
    )
    hostname: str = param("", "motioncapture: the mocap server's address")
    topic_pattern: str = param(
        "/{robot}/pose",
        "ros2: the PoseStamped topic of each physical robot, {robot} standing for its name "
        "(ros2-vicon-receiver publishes /vicon/<subject>/<segment>)",
    )

    def problems(self) -> Iterator[Problem]:
        """Files, bodies and patterns that a source needs."""
        if self.source == "bag" and not self.file:
            yield Problem("file", self.file, "a bag or CSV file for source = 'bag'")
        if self.source != "bag" and self.file:
            yield Problem("file", self.file, "no file unless source = 'bag'")
        if self.source == "bag" and len(self.bodies) > 1 and self.file.endswith(".csv"):
            yield Problem("bodies", [list(b) for b in self.bodies], "one body for a CSV file")
        if self.robots and self.source != "simulated":
            yield Problem("robots", list(self.robots), "no robots unless source = 'simulated'")
        if self.bodies and self.source not in EXTERNAL_SOURCES:
            yield Problem(
                "bodies",
                [list(b) for b in self.bodies],
                "no bodies unless source is 'bag', 'motioncapture' or 'ros2'",
            )
        tracked = [robot for robot, _ in self.bodies]
        if len(set(tracked)) != len(tracked):
            yield Problem("bodies", [list(b) for b in self.bodies], "each robot tracked once")
        if self.source == "ros2" and "{robot}" not in self.topic_pattern and not self.bodies:
            yield Problem("topic_pattern", self.topic_pattern, "a pattern containing {robot}")

    @property
    def external(self) -> bool:
        """Whether the poses come from outside the simulation (and move their robots)."""
        return self.source in EXTERNAL_SOURCES

    def adapters(self) -> tuple[str, ...]:
        """The adapters these settings ask for: the pose source, unless ``none``."""
        return ("mocap",) if self.source != "none" else ()

    def needs_realtime(self) -> bool:
        """A live system sends poses on the wall clock: the run must keep pace with it."""
        return self.source in ("motioncapture", "ros2")
