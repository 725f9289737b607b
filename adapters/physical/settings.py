"""The ``[physical]`` section: real robots joining a run over ROS 2's wire protocol (DDS)."""

from __future__ import annotations

from collections.abc import Iterator, Mapping
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
    dds_domain: int | Literal["auto"] = param(
        "auto",
        "DDS domain (ROS_DOMAIN_ID) 0-232, or auto: on loopback, a domain 1-101 that no other "
        "run or DDS participant of this machine uses, chosen per run (so that runs side by "
        "side never hear each other's robots; the run says which)",
        ge=0,
        le=232,
        unit="id",
    )
    interface: str = param(
        "", "network interface or address for DDS; empty keeps DDS on loopback (127.0.0.1)"
    )
    pose_timeout_s: float = param(
        10.0,
        "a physical robot whose pose has not come for this long (from the start, or since "
        "its last one) ends the run with an error naming it and where it was listened for (s)",
        gt=0,
        le=3600,
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
        if self.dds_domain == "auto" and self.interface:
            yield Problem(
                "dds_domain",
                self.dds_domain,
                f"the robots' ROS_DOMAIN_ID (0-232) with interface = {self.interface!r}: a "
                "robot on a network keeps its own domain",
            )

    def adapters(self) -> tuple[str, ...]:
        """The adapters these settings ask for: the bridge, with physical robots."""
        return ("physical",) if self.robots else ()

    def needs_realtime(self) -> bool:
        """A physical robot lives on the wall clock: the run must keep pace with it."""
        return bool(self.robots)

    def uses_dds(self) -> bool:
        """Physical robots talk to the run over DDS."""
        return bool(self.robots)

    def external_poses(self) -> Mapping[str, str]:
        """Every physical robot is posed from outside: by the mocap source, or its odometry.

        (See :class:`adapters.mocap.contract.ExternalPoses`.)
        """
        return {robot: self.pose for robot in self.robots}
