"""The ``[mocap]`` section: a motion-capture pose source for the robots' software.

The paper tracks its Jackal with a Vicon system (Vicon Tracker 3.10) and brings the poses
into ROS 2 with ``ros2-vicon-receiver``. The default noise (1 mm, 2 mrad) is of the order
of what Merriaux et al. measured for a Vicon system ("A Study of Vicon System Positioning
Performance", Sensors 17(7), 2017: millimetre-level errors); the default rate, 100 Hz, is
a common Vicon tracking rate, and the 5 ms latency a chosen value for camera processing
plus the bridge, not a measured one.
"""

from __future__ import annotations

import string
from collections.abc import Iterator
from dataclasses import dataclass
from typing import ClassVar, Literal

from adapters.ros2dds.naming import dds_topic
from cosim.scenario.fields import Problem, param

MocapSource = Literal["none", "simulated", "bag", "motioncapture", "ros2", "unity"]

EXTERNAL_SOURCES = ("bag", "motioncapture", "ros2", "unity")
"""Sources whose poses come from outside the simulation: they move the robots they track."""

LIVE_SOURCES = ("motioncapture", "ros2", "unity")
"""External sources that send poses while the run goes (on the wall clock)."""

SYSTEMS = ("vicon", "optitrack", "qualisys", "vrpn", "mock")
"""Backends the motioncapture 1.1 wheel supports (others: "Unknown motion capture type!")."""

PATTERN_TOKENS = ("robot",)
"""The ``{token}`` names ``topic_pattern`` may hold."""


@dataclass(frozen=True)
class MocapConfig:
    """``[mocap]``: a motion-capture pose source for the robots' software."""

    ORDER: ClassVar[int] = 100
    """Where the section comes in a resolved scenario and in the adapters' order."""

    source: MocapSource = param(
        "none",
        "where the poses come from: none (robots localize by odometry), simulated (from "
        "ground truth with rate, latency, noise, dropouts), bag (a recorded ROS 2 bag or a "
        "CSV replayed), motioncapture (live, through the motioncapture library), ros2 "
        "(live PoseStamped topics over DDS), or unity (live PoseStamped topics a Unity scene "
        "publishes to `cosim run --unity`)",
    )
    robots: tuple[str, ...] = param(
        (), "simulated: the robots tracked (empty: all); other sources: see bodies"
    )
    bodies: tuple[tuple[str, str], ...] = param(
        (),
        "[[robot, body], ...]: what tracks each robot; body is a topic in the bag (bag), a "
        "rigid-body name (motioncapture) or a ROS topic (ros2, unity). Empty: robot_0 with "
        "the bag's only pose topic (bag), each physical robot by its name (motioncapture) "
        "or on topic_pattern (ros2, unity)",
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
        "ros2, unity: the PoseStamped topic of each physical robot, {robot} standing for its "
        "name (the only token; ros2-vicon-receiver publishes /vicon/<subject>/<segment>)",
    )
    connect_timeout_s: float = param(
        10.0,
        "motioncapture, ros2, unity: a live source that has not connected, or has sent no pose of "
        "a tracked robot, this long after the run started ends the run with an error naming "
        "the system, its host and the robot (s)",
        gt=0,
        le=3600,
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
                "no bodies unless source is 'bag', 'motioncapture', 'ros2' or 'unity'",
            )
        tracked = [robot for robot, _ in self.bodies]
        if len(set(tracked)) != len(tracked):
            yield Problem("bodies", [list(b) for b in self.bodies], "each robot tracked once")
        yield from self._pattern_problems()
        by_topic = self.source in ("ros2", "unity")
        if by_topic and "{robot}" not in self.topic_pattern and not self.bodies:
            yield Problem("topic_pattern", self.topic_pattern, "a pattern containing {robot}")
        if by_topic:
            for robot, body in self.bodies:
                reason = _topic_problem(body)
                if reason is not None:
                    yield Problem(
                        "bodies", [robot, body], f"a ROS 2 topic for {self.source} ({reason})"
                    )
        if self.source == "motioncapture":
            if self.system not in SYSTEMS:
                yield Problem("system", self.system, f"one of {', '.join(SYSTEMS)}")
            elif self.system != "mock" and not self.hostname.strip():
                yield Problem("hostname", self.hostname, f"the {self.system} server's address")
            if any(c.isspace() for c in self.hostname):
                yield Problem("hostname", self.hostname, "an address without spaces")

    def _pattern_problems(self) -> Iterator[Problem]:
        """``topic_pattern``: only known tokens, and a valid topic once they are filled in."""
        known = ", ".join("{" + t + "}" for t in PATTERN_TOKENS)
        try:
            fields = list(string.Formatter().parse(self.topic_pattern))
        except ValueError:  # a lone brace
            yield Problem(
                "topic_pattern", self.topic_pattern, f"braces only around a token ({known})"
            )
            return
        for _text, name, spec, conversion in fields:
            if name is None:
                continue
            if name not in PATTERN_TOKENS or spec or conversion:
                token = "{" + name + ("!" + conversion if conversion else "")
                token += (":" + spec if spec else "") + "}"
                yield Problem(
                    "topic_pattern",
                    self.topic_pattern,
                    f"only the tokens {known} (not {token})",
                )
                return
        reason = _topic_problem(self.topic_pattern.replace("{robot}", "robot_1"))
        if reason is not None:
            yield Problem(
                "topic_pattern", self.topic_pattern, f"a ROS 2 topic once filled in ({reason})"
            )

    @property
    def external(self) -> bool:
        """Whether the poses come from outside the simulation (and move their robots)."""
        return self.source in EXTERNAL_SOURCES

    def adapters(self) -> tuple[str, ...]:
        """The adapters these settings ask for: the pose source, unless ``none``."""
        return ("mocap",) if self.source != "none" else ()

    def needs_realtime(self) -> bool:
        """A live system sends poses on the wall clock: the run must keep pace with it."""
        return self.source in LIVE_SOURCES


def _topic_problem(name: str) -> str | None:
    """Why ``name`` is not an absolute ROS 2 topic, or None."""
    try:
        dds_topic(name)
    except ValueError as error:
        return str(error)
    return None
