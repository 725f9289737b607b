"""The sections of a scenario file and their keys (the contract in DESIGN.md).

Each section is a frozen dataclass; every field has a default, a one-line doc, and its
unit in its name. Cross-field rules live in each section's ``problems()``.

Robot defaults are those of a Clearpath Jackal: 508 mm x 430 mm footprint (circumscribed
radius 0.33 m) and 2.0 m/s top speed from Clearpath's Jackal datasheet; acceleration
(2.0 m/s^2, 3.0 rad/s^2) and yaw-rate (2.0 rad/s) limits from the planner parameters in
Clearpath's ``jackal_navigation`` package. The default cruise speed is 1.0 m/s, a
typical indoor setting, below the hardware's 2.0 m/s.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import ClassVar, Literal

from cosim.scenario.fields import Problem, param
from cosim.scenario.names import NAME_RULE, name_problem

Layout = Literal["random", "all_rows", "two_corridors"]
Placement = Literal["dock", "random", "explicit"]


@dataclass(frozen=True)
class ScenarioSection:
    """``[scenario]``: identity, length and seed of a run."""

    ORDER: ClassVar[int] = 0
    """Where the section comes in a resolved scenario and in the adapters' order."""

    name: str = param(
        "unnamed",
        "name shown in summaries and folder names: letters and digits of any script, spaces "
        "between words, '_', '-', '.', '+'",
    )
    duration_s: float = param(60.0, "simulated time to run (s)", gt=0, le=1e7)
    seed: int = param(1, "scenario seed; every random stream derives from it", ge=0, unit="id")
    adapters: tuple[str, ...] = param(
        (),
        "extra adapters to start, by registered name (`cosim plugins`)",
        registry="cosim.adapters",
    )
    hang_timeout_s: float = param(
        60.0,
        "wall-clock time one step of the run (an event, an adapter's start or finish) may "
        "take before the code running is stopped as hung, named, and the results so far "
        "kept (s; 0: never)",
        ge=0,
        le=86400,
    )

    def problems(self) -> Iterator[Problem]:
        """The name is one folder name: runs are written to ``runs/NAME-seedN``.

        Any script's letters and digits (:mod:`cosim.scenario.names`).
        """
        problem = name_problem(self.name)
        if problem is not None:
            yield Problem("name", self.name, f"{NAME_RULE}; {problem}")


@dataclass(frozen=True)
class WorldConfig:
    """``[world]``: the warehouse hall (frame ``map``, origin at the south-west inner corner)."""

    ORDER: ClassVar[int] = 10
    """Where the section comes in a resolved scenario and in the adapters' order."""

    size_m: tuple[float, float] = param((30.0, 30.0), "inner room size [x, y] (m)", gt=0, le=500.0)
    layout: Layout = param("random", "shelf layout")
    shelf_size_m: tuple[float, float] = param(
        (2.0, 0.8), "shelf footprint [length, depth] (m)", gt=0
    )
    shelf_count: int = param(
        24, "number of shelves (rows layouts: at most what fits)", ge=0, le=100_000, unit="count"
    )
    shelves_per_rack: int = param(
        3, "rows layouts: shelves end to end in one rack", ge=1, unit="count"
    )
    aisle_width_m: float = param(1.6, "minimum free gap between shelves and walls (m)", gt=0)
    wall_thickness_m: float = param(0.2, "thickness of the outer walls (m)", gt=0, le=5.0)
    obstacles: tuple[tuple[float, float, float, float], ...] = param(
        (), "extra obstacle boxes [[xmin_m, ymin_m, xmax_m, ymax_m], ...] in map", unit="m"
    )


@dataclass(frozen=True)
class RobotsConfig:
    """``[robots]``: the fleet (differential drive, Jackal defaults)."""

    ORDER: ClassVar[int] = 20
    """Where the section comes in a resolved scenario and in the adapters' order."""

    count: int = param(4, "number of robots", gt=0, le=100_000, unit="count")
    model: Literal["jackal"] = param("jackal", "robot model")
    placement: Placement = param("dock", "start placement")
    positions: tuple[tuple[float, float, float], ...] = param(
        (), "explicit placement: [[x_m, y_m, yaw_rad], ...] in map", unit="m, m, rad"
    )
    max_speed_mps: float = param(1.0, "forward speed limit (m/s)", gt=0, le=2.0)
    max_reverse_mps: float = param(0.3, "backward speed limit (m/s)", ge=0)
    max_yaw_rate_radps: float = param(2.0, "yaw-rate limit (rad/s)", gt=0)
    max_accel_mps2: float = param(2.0, "linear acceleration limit (m/s^2)", gt=0)
    max_yaw_accel_radps2: float = param(3.0, "yaw acceleration limit (rad/s^2)", gt=0)
    radius_m: float = param(0.33, "footprint radius (m)", gt=0, le=5.0)
    control_hz: float = param(20.0, "kinematics and odometry rate (Hz)", gt=0, le=1000)
    driver: str = param(
        "navigation",
        "robot software, a registered driver (`cosim plugins`): 'tasks' (dynamic task "
        "assignment over the network driving through navigation), 'navigation' (to random "
        "reachable goals, the Nav2 role), 'waypoints' (straight lines, no avoidance) or "
        "'wander' (reactive lidar wandering)",
        registry="cosim.drivers",
    )

    def problems(self) -> Iterator[Problem]:
        """Explicit placement needs one pose per robot."""
        if self.placement == "explicit" and len(self.positions) != self.count:
            yield Problem(
                "positions",
                [list(p) for p in self.positions],
                f"{self.count} poses [x_m, y_m, yaw_rad] (one per robot) for placement 'explicit'",
            )
        if self.placement != "explicit" and self.positions:
            yield Problem(
                "positions",
                [list(p) for p in self.positions],
                "no positions unless placement = 'explicit'",
            )


@dataclass(frozen=True)
class LidarConfig:
    """``[lidar]``: a planar lidar on every robot (REP 117 ranges)."""

    ORDER: ClassVar[int] = 30
    """Where the section comes in a resolved scenario and in the adapters' order."""

    beams: int = param(360, "beams per scan (0 disables the lidar)", ge=0, le=100_000, unit="count")
    fov_deg: float = param(
        360.0, "field of view (deg), centred on the robot's heading", gt=0, le=360
    )
    range_min_m: float = param(0.1, "minimum valid range (m)", ge=0)
    range_max_m: float = param(10.0, "maximum range (m)", gt=0)
    rate_hz: float = param(10.0, "scan rate (Hz)", gt=0, le=1000)
    noise_std_m: float = param(0.01, "Gaussian range noise (m)", ge=0)
    dropout_prob: float = param(0.0, "probability that a beam returns nothing (nan)", ge=0, le=1)

    def problems(self) -> Iterator[Problem]:
        """The valid range interval must not be empty."""
        if self.range_min_m >= self.range_max_m:
            yield Problem(
                "range_min_m", self.range_min_m, f"a value < range_max_m ({self.range_max_m:g})"
            )


@dataclass(frozen=True)
class OdometryConfig:
    """``[odometry]``: wheel odometry of every robot."""

    ORDER: ClassVar[int] = 40
    """Where the section comes in a resolved scenario and in the adapters' order."""

    drift: float = param(
        0.0,
        "noise scale: 1 m driven straight gives `drift` m distance and `drift` rad heading "
        "error (1 sigma); 0 = perfect",
        ge=0,
        le=1,
        unit="m/m, rad/m",
    )


DEFAULT_TOPICS = ("*", "!/fleet/dta/*", "!/fleet/robot_states", "!/robot_*/cmd_vel")
"""Bag topics by default: everything but protocol rounds, robots-layer and velocity chatter."""


@dataclass(frozen=True)
class RecordConfig:
    """``[record]``: what the run keeps."""

    ORDER: ClassVar[int] = 900
    """Where the section comes in a resolved scenario and in the adapters' order."""

    pose_rate_hz: float = param(
        10.0,
        "ground-truth sampling rate for tables/poses and the bag's /tf, /clock and "
        "/robot_i/ground_truth (Hz)",
        gt=0,
        le=1000,
    )
    messages: bool = param(True, "keep one row per message in tables/messages")
    tables: bool = param(True, "write tables/*.parquet")
    bag: Literal["mcap", "sqlite3", "none"] = param(
        "mcap", "ROS 2 bag in bag/: MCAP (Foxglove, ros2 bag), sqlite3 (.db3), or none"
    )
    topics: tuple[str, ...] = param(
        DEFAULT_TOPICS,
        "topics in the bag and the live view: glob patterns ('*' any text), in order; one "
        "starting with '!' removes what it matches",
    )
    compression: Literal["zstd", "none"] = param(
        "zstd", "bag compression: zstd chunks (MCAP) or zstd messages (sqlite3), or none"
    )

    def problems(self) -> Iterator[Problem]:
        """Topic patterns must not be empty."""
        for pattern in self.topics:
            if not pattern.lstrip("!"):
                yield Problem("topics", list(self.topics), "non-empty glob patterns")
