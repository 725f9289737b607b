"""The ``[mapping]`` section: every robot maps as it drives (the slam_toolbox role).

Defaults follow slam_toolbox's (``minimum_travel_distance`` 0.5 m,
``minimum_travel_heading`` 0.5 rad, ``minimum_time_interval`` 0.5 s,
``map_update_interval`` 5 s, 0.05 m resolution) unless said otherwise; the log-odds
update is documented in :mod:`models.mapping.grid`.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import ClassVar, Literal

from cosim.scenario.choices import choice_problems
from cosim.scenario.fields import Problem, param

NO_SHARING = "none"
"""``mapping.share`` of robots that send their neighbours nothing (the default)."""


@dataclass(frozen=True)
class MappingConfig:
    """``[mapping]``: per-robot occupancy mapping, pose correction and map sharing."""

    ORDER: ClassVar[int] = 90
    """Where the section comes in a resolved scenario and in the adapters' order."""

    enabled: bool = param(
        False,
        "robots build their own maps, localize by scan matching and plan on their own map",
    )
    resolution_m: float = param(0.05, "map cell size (m)", gt=0, le=1)
    scan_matching: Literal["correlative", "none"] = param(
        "correlative",
        "correct odometry by correlative scan-to-map matching (Olson 2009), or none "
        "(odometry only, for comparison)",
    )
    share: str = param(
        NO_SHARING,
        "what robots send their neighbours over the network, a registered map sharing mode: "
        "none, scans (their localized scans, as slam_toolbox's multi-robot mode) or maps "
        "(compressed map updates)",
        registry="cosim.map_sharing",
    )
    min_travel_m: float = param(0.5, "distance driven before a scan updates the map (m)", ge=0)
    min_heading_rad: float = param(0.5, "or rotation before a scan updates the map (rad)", ge=0)
    min_interval_s: float = param(0.5, "and time since the last update (s)", ge=0)
    clear_no_return_m: float = param(
        3.0, "a beam without a return clears free space up to this range (m)", ge=0
    )
    search_window_m: float = param(
        0.3, "scan matching: half-width of the translation window (m)", gt=0, le=5
    )
    search_window_rad: float = param(
        0.12, "scan matching: half-width of the rotation window (rad)", gt=0, le=1.6
    )
    match_margin: float = param(
        0.02,
        "scan matching: how much better than the odometry's prediction (score 0..1) a pose "
        "must fit to replace it; on the simulated warehouse 0.02 gave fleet map IoU 0.86-0.95 "
        "over 10 seeds where 0 gave 0.82-0.90 (cosim map uses 0: real odometry is noisier)",
        ge=0,
        le=1,
        unit="score (0..1)",
    )
    refine: Literal["walls", "score"] = param(
        "walls",
        "scan matching: what the last, sub-cell step fits: 'walls', each return onto the wall "
        "it lies near (fitted to where returns fell in their cells), or 'score', the "
        "bilinear match score (cosim map's default on real recordings). On the simulated "
        "warehouse (warehouse-mapping, 10 seeds x 300 s) 'walls' gave fleet map IoU "
        "0.94-1.00 where 'score' gave 0.88-1.00 (see the mapping guide)",
    )
    map_update_interval_s: float = param(
        5.0, "period of each robot's map going to its navigation and the bag (s)", gt=0
    )
    share_period_s: float = param(
        2.0, "share = 'maps': period of map updates to the neighbours (s)", gt=0
    )
    quality_period_s: float = param(5.0, "period of tables/map_quality rows (s)", gt=0)
    loop_closure: bool = param(
        False,
        "each robot closes loops: a pose graph of its map updates, re-solved when a scan "
        "matches a place mapped long before (Karto / slam_toolbox), its map then rebuilt; "
        "off by default: identical racks can alias (see the mapping guide)",
    )
    loop_search_radius_m: float = param(
        4.0, "loop closure: old map updates within this of the estimate are candidates (m)", gt=0
    )
    loop_min_path_m: float = param(
        10.0, "loop closure: ... only if the robot drove at least this since them (m)", gt=0
    )
    loop_min_correction: float = param(
        7.81,
        "loop closure: a closure enters the pose graph only if the estimate disagrees with it "
        "by at least this (squared Mahalanobis distance, its own covariance; 7.81 is the 95 % "
        "point of chi-square with 3 degrees of freedom; 0 adds every verified closure)",
        ge=0,
        unit="χ² (3 dof)",
    )

    def problems(self) -> Iterator[Problem]:
        """Refuse settings that cannot work together.

        A map finer than 1 cm would be very large; robots that do not map share nothing;
        the sharing mode may refuse settings of its own (rebuilt maps cannot be sent as
        updates).
        """
        if self.resolution_m < 0.01:
            yield Problem("resolution_m", self.resolution_m, "a cell size >= 0.01 m")
        if not self.enabled and self.share != NO_SHARING:
            yield Problem(
                "share",
                self.share,
                f"{NO_SHARING!r} with enabled = false (robots that do not map have nothing to "
                "share); or set mapping.enabled = true",
            )
        yield from choice_problems(self, "share")

    def adapters(self) -> tuple[str, ...]:
        """The adapters these settings ask for: the robots' mapping when enabled."""
        return ("mapping",) if self.enabled else ()
