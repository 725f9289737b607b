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
from typing import Literal

from cosim.scenario.fields import Problem, param

Layout = Literal["random", "all_rows", "two_corridors"]
Placement = Literal["dock", "random", "explicit"]


@dataclass(frozen=True)
class ScenarioSection:
    """``[scenario]``: identity, length and seed of a run."""

    name: str = param("unnamed", "name shown in summaries and folder names")
    duration_s: float = param(60.0, "simulated time to run (s)", gt=0, le=1e7)
    seed: int = param(1, "scenario seed; every random stream derives from it", ge=0)
    adapters: tuple[str, ...] = param((), "extra adapters to start, by registered name")


@dataclass(frozen=True)
class WorldConfig:
    """``[world]``: the warehouse hall (frame ``map``, origin at the south-west inner corner)."""

    size_m: tuple[float, float] = param((30.0, 30.0), "inner room size [x, y] (m)", gt=0, le=500.0)
    layout: Layout = param("random", "shelf layout")
    shelf_size_m: tuple[float, float] = param(
        (2.0, 0.8), "shelf footprint [length, depth] (m)", gt=0
    )
    shelf_count: int = param(
        24, "number of shelves (rows layouts: at most what fits)", ge=0, le=100_000
    )
    shelves_per_rack: int = param(3, "rows layouts: shelves end to end in one rack", ge=1)
    aisle_width_m: float = param(1.6, "minimum free gap between shelves and walls (m)", gt=0)
    wall_thickness_m: float = param(0.2, "thickness of the outer walls (m)", gt=0, le=5.0)
    obstacles: tuple[tuple[float, float, float, float], ...] = param(
        (), "extra obstacle boxes [[xmin_m, ymin_m, xmax_m, ymax_m], ...] in map"
    )


@dataclass(frozen=True)
class RobotsConfig:
    """``[robots]``: the fleet (differential drive, Jackal defaults)."""

    count: int = param(4, "number of robots", gt=0, le=100_000)
    model: Literal["jackal"] = param("jackal", "robot model")
    placement: Placement = param("dock", "start placement")
    positions: tuple[tuple[float, float, float], ...] = param(
        (), "explicit placement: [[x_m, y_m, yaw_rad], ...] in map"
    )
    max_speed_mps: float = param(1.0, "forward speed limit (m/s)", gt=0, le=2.0)
    max_reverse_mps: float = param(0.3, "backward speed limit (m/s)", ge=0)
    max_yaw_rate_radps: float = param(2.0, "yaw-rate limit (rad/s)", gt=0)
    max_accel_mps2: float = param(2.0, "linear acceleration limit (m/s^2)", gt=0)
    max_yaw_accel_radps2: float = param(3.0, "yaw acceleration limit (rad/s^2)", gt=0)
    radius_m: float = param(0.33, "footprint radius (m)", gt=0, le=5.0)
    control_hz: float = param(20.0, "kinematics and odometry rate (Hz)", gt=0, le=1000)
    driver: Literal["tasks", "navigation", "waypoints", "wander"] = param(
        "navigation",
        "robot software: dynamic task assignment over the network driving through navigation, "
        "navigation to random reachable goals (the Nav2 role), straight-line waypoints "
        "without avoidance, or reactive lidar wandering",
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

    beams: int = param(360, "beams per scan (0 disables the lidar)", ge=0, le=100_000)
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

    drift: float = param(
        0.0,
        "noise scale: 1 m driven straight gives `drift` m distance and `drift` rad heading "
        "error (1 sigma); 0 = perfect",
        ge=0,
        le=1,
    )


DEFAULT_TOPICS = ("*", "!/fleet/dta/*", "!/fleet/robot_states", "!/robot_*/cmd_vel")
"""Bag topics by default: everything but protocol rounds, robots-layer and velocity chatter."""


@dataclass(frozen=True)
class RecordConfig:
    """``[record]``: what the run keeps."""

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


@dataclass(frozen=True)
class NavigationConfig:
    """``[navigation]``: the Nav2 role, global planning and local control on every robot.

    Defaults follow Nav2's where it has one: a 1 Hz replanning cadence as in its
    ``navigate_to_pose`` behaviour tree (``RateController hz=1.0``), a 10 Hz local
    controller, a 0.25 m goal tolerance (``xy_goal_tolerance``). Inflation uses a 1 m radius
    with scaling 3 (Nav2's code defaults are 0.55 m and 10; the gentler slope keeps robots
    in the middle of 1.6 m aisles). ``stuck`` comes after 30 s without progress: with 50
    robots in one hall, 10 s (Nav2's progress checker) mostly flags robots that are merely
    slowed by traffic and would arrive.
    """

    planner: Literal["astar"] = param("astar", "global planner on the costmap")
    controller: Literal["dwa"] = param("dwa", "local controller")
    replan_hz: float = param(1.0, "periodic global replanning rate (Hz)", gt=0, le=50)
    control_hz: float = param(10.0, "local controller rate (Hz)", gt=0, le=100)
    robots_layer: bool = param(
        False, "robots broadcast pose and footprint over the network; others avoid them"
    )
    robots_layer_hz: float = param(5.0, "robots layer broadcast rate (Hz)", gt=0, le=1000)
    robots_layer_timeout_s: float = param(1.0, "forget a robot not heard from for (s)", gt=0)
    resolution_m: float = param(0.1, "costmap cell size (m)", gt=0, le=1)
    inflation_radius_m: float = param(1.0, "inflation radius (m)", gt=0, le=10.0)
    cost_scaling: float = param(3.0, "inflation cost scaling factor (1/m)", gt=0)
    lookahead_m: float = param(1.0, "carrot distance ahead on the path (m)", gt=0)
    goal_tolerance_m: float = param(0.25, "distance at which a goal is reached (m)", gt=0)
    obstacle_memory_s: float = param(3.0, "how long lidar obstacles stay in the costmap (s)", ge=0)
    stuck_timeout_s: float = param(
        30.0,
        "no progress for this long reports `stuck` (s); the paper's robots stall 20-30 s "
        "before the fleet layer re-targets them",
        gt=0,
    )
    progress_hz: float = param(1.0, "rate of `progress` status reports (Hz)", gt=0, le=1000)
    traffic: Literal["none", "lanes", "pibt"] = param(
        "none",
        "fleet traffic policy: 'none': every robot plans for itself (A* + DWA); 'lanes': "
        "the same with aisles up to 2.5 m wide one-way, neighbours in opposite directions "
        "(the planner charges 5x for a step against one); 'pibt': the fleet manager moves "
        "every robot over a 2r + 0.14 m grid of places with those one-way aisles, one PIBT "
        "step at a time (Okumura et al. 2022), robots stalled 10 s first, then the oldest goal",
    )
    goals: tuple[tuple[float, float], ...] = param(
        (),
        "driver 'navigation': a series of goals [[x_m, y_m], ...] in map, visited in order "
        "and round again (robot i starts at goal i); empty: random reachable goals",
    )


@dataclass(frozen=True)
class TasksConfig:
    """``[tasks]``: pick tasks at the shelves, created over time by the task source.

    As in the paper, a new task appears whenever one is completed.
    """

    initial: int = param(4, "tasks open at the start", ge=1, le=100_000)
    max_total: int = param(0, "tasks created over the run, 0 = unlimited", ge=0, le=10_000_000)
    eligibility_prob: float = param(
        1.0,
        "probability that a robot may serve a task (ChoiRbot's example uses a subset)",
        gt=0,
        le=1,
    )
    dwell_s: float = param(2.0, "time a robot spends at a task to serve it (s)", ge=0)
    station_offset_m: float = param(
        0.25, "pick stations: free space between the footprint and the shelf face (m)", gt=0
    )

    def problems(self) -> Iterator[Problem]:
        """A cap below the initial tasks would never be reached."""
        if 0 < self.max_total < self.initial:
            yield Problem("max_total", self.max_total, f"0 or at least initial ({self.initial})")


@dataclass(frozen=True)
class AssignmentConfig:
    """``[assignment]``: how robots decide who serves which task."""

    protocol: Literal["distributed_simplex", "hungarian", "greedy", "cbba"] = param(
        "distributed_simplex",
        "distributed simplex (Buerger et al. 2012, as in ChoiRbot), centralized Hungarian on "
        "the base station, nearest free task, or consensus-based auction (Choi et al. 2009)",
    )
    period_ms: float = param(100.0, "protocol round period (ms)", gt=0)
    round_phase: Literal["independent", "aligned"] = param(
        "independent",
        "robots' round timers: each started at its own random phase within the period, as "
        "timers on separate machines are, or all firing at the same instants",
    )
    preemption: bool = param(
        False, "a robot heading to its task may be re-assigned by a later epoch"
    )
    diameter_bound: int = param(
        0, "bound on the robot graph's diameter for halting; 0 = from the topology", ge=0
    )
    cost: Literal["euclidean", "path"] = param(
        "euclidean", "task cost: straight-line distance, or shortest path on the static map"
    )
    claim_timeout_s: float = param(
        5.0, "a claim not repeated for this long is released by the task source (s)", gt=0
    )
    rebroadcast_s: float = param(
        1.0, "period of re-sending task sets, claims and unchanged protocol state (s)", gt=0
    )
