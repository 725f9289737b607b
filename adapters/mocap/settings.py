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
from typing import Any, ClassVar

from adapters.ros2dds.naming import dds_topic
from cosim.core.registry import group_named
from cosim.scenario.choices import choice_problems
from cosim.scenario.fields import Problem, param

NO_SOURCE = "none"
"""``mocap.source`` of a run without motion capture (robots localize by odometry)."""

SOURCES = "cosim.mocap_sources"
"""The registry of pose sources (:mod:`adapters.mocap.contract`)."""

PATTERN_TOKENS = ("robot",)
"""The ``{token}`` names ``topic_pattern`` may hold."""


@dataclass(frozen=True)
class MocapConfig:
    """``[mocap]``: a motion-capture pose source for the robots' software."""

    ORDER: ClassVar[int] = 100
    """Where the section comes in a resolved scenario and in the adapters' order."""

    source: str = param(
        NO_SOURCE,
        "where the poses come from: none (robots localize by odometry), or a registered "
        "source: simulated (from ground truth with rate, latency, noise, dropouts), bag (a "
        "recorded ROS 2 bag or a CSV replayed), motioncapture (live, through the "
        "motioncapture library), ros2 (live PoseStamped topics over DDS), unity (live "
        "PoseStamped topics a Unity scene publishes to `cosim run --unity`)",
        registry=SOURCES,
        off=NO_SOURCE,
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
        0.0,
        "simulated: probability that a body is missing from a frame",
        ge=0,
        le=1,
        unit="probability",
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
        """Patterns and bodies; what the chosen source cannot run with; keys it leaves unused."""
        tracked = [robot for robot, _ in self.bodies]
        if len(set(tracked)) != len(tracked):
            yield Problem("bodies", [list(b) for b in self.bodies], "each robot tracked once")
        yield from self._pattern_problems()
        yield from choice_problems(self, "source")

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
        reason = topic_problem(self.topic_pattern.replace("{robot}", "robot_1"))
        if reason is not None:
            yield Problem(
                "topic_pattern", self.topic_pattern, f"a ROS 2 topic once filled in ({reason})"
            )

    def chosen(self) -> Any:
        """The chosen source's class (:class:`~adapters.mocap.contract.PoseSource`), or None.

        Raises:
            RegistryError: for a source that cannot be loaded (a broken plugin).
        """
        if self.source == NO_SOURCE:
            return None
        return group_named(SOURCES).installed().get(self.source)

    @property
    def external(self) -> bool:
        """Whether the poses come from outside the simulation (and move their robots)."""
        source = self.chosen()
        return source is not None and bool(source.external)

    def adapters(self) -> tuple[str, ...]:
        """The adapters these settings ask for: the pose source, unless ``none``."""
        return () if self.source == NO_SOURCE else ("mocap",)

    def needs_realtime(self) -> bool:
        """A live system sends poses on the wall clock: the run must keep pace with it."""
        source = self.chosen()
        return source is not None and bool(source.live)

    def uses_dds(self) -> bool:
        """Whether the source listens on the run's DDS domain."""
        source = self.chosen()
        return source is not None and bool(source.uses_dds)


def topic_problem(name: str) -> str | None:
    """Why ``name`` is not an absolute ROS 2 topic, or None."""
    try:
        dds_topic(name)
    except ValueError as error:
        return str(error)
    return None
