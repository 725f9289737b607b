"""The stand-in robot's options and command line, without the robot (no DDS, no physics).

``cosim standin`` and ``python -m adapters.physical.standin`` parse them here, so that
building the command line (``cosim --help``) imports no DDS library.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass, fields

from adapters.ros2dds.naming import dds_topic
from cosim.core.errors import ConfigError

MAX_RATE_HZ = 1000.0
"""Highest control and pose rate (Hz) a wall-clock Python loop can hold."""


@dataclass(frozen=True)
class StandinOptions:
    """How the stand-in robot behaves (drive limits default to a Jackal's).

    Attributes:
        name: robot name, the namespace of its topics (``robot_0``).
        domain: DDS domain id (``ROS_DOMAIN_ID``).
        interface: None for loopback only, else a network interface name or address.
        x_m, y_m, yaw_rad: start pose in ``map`` (m, m, rad).
        rate_hz: control and pose rate (Hz).
        latency_ms: each pose is published this long after the instant it describes
            (and is stamped with that instant), as motion capture would be.
        noise_std_m, noise_std_rad: standard deviation of the pose's position and yaw noise.
        seed: seed of the pose noise.
        cmd_timeout_s: with no ``cmd_vel`` for this long the robot is commanded to stop.
        duration_s: run this long (s), or until stopped if None.
    """

    name: str
    domain: int = 0
    interface: str | None = None
    x_m: float = 0.0
    y_m: float = 0.0
    yaw_rad: float = 0.0
    rate_hz: float = 100.0
    latency_ms: float = 0.0
    noise_std_m: float = 0.0
    noise_std_rad: float = 0.0
    seed: int = 1
    max_speed_mps: float = 1.0
    max_reverse_mps: float = 0.3
    max_yaw_rate_radps: float = 2.0
    max_accel_mps2: float = 2.0
    max_yaw_accel_radps2: float = 3.0
    cmd_timeout_s: float = 0.5
    duration_s: float | None = None

    def __post_init__(self) -> None:
        try:
            dds_topic(f"/{self.name}")
        except ValueError:
            raise ConfigError(
                f"name {self.name!r}: expected a relative ROS name such as 'robot_0'"
            ) from None
        for field in fields(self):
            value = getattr(self, field.name)
            if isinstance(value, float) and not math.isfinite(value):
                raise ConfigError(f"{field.name} = {value!r}: expected a finite number")
        positive = ("max_speed_mps", "max_yaw_rate_radps", "max_accel_mps2")
        for key in (*positive, "max_yaw_accel_radps2", "cmd_timeout_s"):
            if not getattr(self, key) > 0:
                raise ConfigError(f"{key} = {getattr(self, key)!r}: expected a value > 0")
        for key in ("latency_ms", "noise_std_m", "noise_std_rad", "max_reverse_mps"):
            if not getattr(self, key) >= 0:
                raise ConfigError(f"{key} = {getattr(self, key)!r}: expected a value >= 0")
        if not 0 < self.rate_hz <= MAX_RATE_HZ:
            raise ConfigError(f"rate_hz = {self.rate_hz!r}: expected a rate in (0, {MAX_RATE_HZ}]")
        if self.duration_s is not None and not self.duration_s > 0:
            raise ConfigError(f"duration_s = {self.duration_s!r}: expected a value > 0")


FLOAT_OPTIONS = {
    "x_m": "start x in map (m)",
    "y_m": "start y in map (m)",
    "yaw_rad": "start heading in map (rad)",
    "rate_hz": "control and pose rate (Hz)",
    "latency_ms": "each pose is published this long after the instant it shows (ms)",
    "noise_std_m": "Gaussian pose noise per axis (m)",
    "noise_std_rad": "Gaussian yaw noise (rad)",
    "max_speed_mps": "forward speed limit (m/s)",
    "max_yaw_rate_radps": "yaw-rate limit (rad/s)",
    "cmd_timeout_s": "stop when no cmd_vel came for this long (s)",
}
"""The numeric options of the command line, with their help."""


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the stand-in's options to ``parser`` (``cosim standin`` and ``python -m``)."""
    parser.add_argument("--name", required=True, help="robot name, its topics' namespace")
    parser.add_argument("--domain", type=int, default=0, help="DDS domain id (ROS_DOMAIN_ID)")
    parser.add_argument(
        "--interface", default=None, help="network interface or address (default: loopback)"
    )
    for key, text in FLOAT_OPTIONS.items():
        default = getattr(StandinOptions, key)
        parser.add_argument(
            f"--{key.replace('_', '-')}",
            type=float,
            default=default,
            help=f"{text} (default {default:g})",
        )
    parser.add_argument("--seed", type=int, default=1, help="seed of the pose noise")
    parser.add_argument(
        "--duration-s", type=float, default=None, help="stop after this long (default: Ctrl-C)"
    )


def options_from(args: argparse.Namespace) -> StandinOptions:
    """The options parsed by :func:`add_arguments`.

    Raises:
        ConfigError: naming the value that is out of range.
    """
    keys = {"name", "domain", "interface", "seed", "duration_s", *FLOAT_OPTIONS}
    return StandinOptions(**{key: getattr(args, key) for key in keys})
