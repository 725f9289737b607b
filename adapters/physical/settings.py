"""The ``[physical]`` section: real robots joining a run over ROS 2's wire protocol (DDS)."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import ClassVar, Literal

from cosim.scenario.fields import Problem, param


@dataclass(frozen=True)
class PhysicalConfig:
    """``[physical]``: real robots joining the run over ROS 2's wire protocol (DDS).

    A physical robot's twin is a full fleet member (sensed by the others' lidars, checked
    for collisions, given tasks); its pose comes from outside, its virtual lidar scan and
    (with ``drive = "cosim"``) its velocity commands go out over DDS. Runs with a physical
    robot run in real time.
    """

    ORDER: ClassVar[int] = 110
    """Where the section comes in a resolved scenario and in the adapters' order."""

    robots: tuple[str, ...] = param((), "names of the robots that are physical (robot_i)")
    dds_domain: int = param(0, "DDS domain (ROS_DOMAIN_ID)", ge=0, le=232)
    interface: str = param(
        "", "network interface or address for DDS; empty keeps DDS on loopback (127.0.0.1)"
    )
    drive: Literal["cosim", "own"] = param(
        "cosim",
        "who drives a physical robot: cosim's navigation (Twist on /<robot>/cmd_vel), or "
        "its own stack (cosim sends goals on /<robot>/goal_pose and mirrors the robot)",
    )
    pose: Literal["mocap", "odom"] = param(
        "mocap",
        "where a physical robot's pose comes from: the mocap source, or the robot's own "
        "nav_msgs/Odometry on /<robot>/odom (its odometry frame taken as map)",
    )
    poll_hz: float = param(
        200.0, "rate at which DDS samples are taken into the simulation (Hz)", gt=0, le=2000
    )

    def problems(self) -> Iterator[Problem]:
        """Robot names must be unique."""
        if len(set(self.robots)) != len(self.robots):
            yield Problem("robots", list(self.robots), "each robot named once")

    def adapters(self) -> tuple[str, ...]:
        """The adapters these settings ask for: the bridge, with physical robots."""
        return ("physical",) if self.robots else ()

    def needs_realtime(self) -> bool:
        """A physical robot lives on the wall clock: the run must keep pace with it."""
        return bool(self.robots)
