"""The ``[humans]`` section: workers and forklifts in the aisles, moved by SUMO.

The defaults come from SUMO's own pedestrian defaults where SUMO has one (a person is
0.48 m wide and walks at up to 1.39 m/s: SUMO's ``DEFAULT_PEDTYPE``); a worker's disc
radius of 0.25 m covers that width. Picking times are a chosen range, not a measured one.
Forklift dimensions are those of a common 1.5 t counterbalance truck (about 2.3 m x 1.1 m,
e.g. Linde E15 data sheet); 2.2 m/s (8 km/h) is a usual indoor speed limit for them.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import ClassVar

from cosim.scenario.fields import Problem, param


@dataclass(frozen=True)
class HumansConfig:
    """``[humans]``: people and forklifts sharing the aisles with the robots (SUMO)."""

    ORDER: ClassVar[int] = 120
    """Where the section comes in a resolved scenario and in the adapters' order."""

    workers: int = param(
        0, "workers walking between pick stations and the dock", ge=0, le=2000, unit="count"
    )
    forklifts: int = param(
        0, "forklifts driving between pick stations and the dock", ge=0, le=200, unit="count"
    )
    standing: tuple[tuple[float, float], ...] = param(
        (),
        "[[x_m, y_m], ...]: extra workers who stand at these points (snapped to the nearest "
        "aisle) for the whole run",
        unit="m",
    )
    near_miss_m: float = param(
        0.5,
        "a robot and a person closer than this (footprint to footprint) is a near miss (m)",
        gt=0,
    )
    step_length_s: float = param(
        0.1, "SUMO's step; people move in steps of this length (s)", ge=0.01, le=1.0
    )
    worker_radius_m: float = param(0.25, "a worker's footprint as a disc (m)", gt=0, le=1.0)
    worker_speed_mps: float = param(1.2, "a worker's walking speed (m/s)", gt=0, le=3.0)
    pick_s: tuple[float, float] = param(
        (10.0, 40.0), "[min, max]: how long a worker stays at a pick station (s)", ge=0
    )
    stations: int = param(
        12,
        "pick stations (aisle spots next to shelves) workers walk to",
        ge=1,
        le=1000,
        unit="count",
    )
    forklift_size_m: tuple[float, float] = param(
        (2.3, 1.1), "[length, width] of a forklift (m)", gt=0, le=10.0
    )
    forklift_speed_mps: float = param(2.2, "a forklift's top speed (m/s)", gt=0, le=10.0)
    aisle_spacing_m: float = param(
        1.5,
        "the walking network's lines run along aisle centres at least this far apart (m)",
        ge=0.5,
        le=20.0,
    )
    stop_radius_m: float = param(
        1.5,
        "a robot that halts with a person this close to its footprint counts as stopped by "
        "people (m)",
        gt=0,
    )
    jam_time_s: float = param(
        30.0,
        "a worker blocked this long squeezes past whoever blocks them (SUMO's "
        "pedestrian.striping.jamtime; SUMO's default, 300 s, is for streets) (s)",
        gt=0,
    )
    avoid_robots: bool = param(
        True,
        "people keep clear of robots, moving or standing (a collision-free speed model over "
        "SUMO's walking: a walker slows and waits rather than walk into a robot); false: only "
        "SUMO's own pedestrians' giving way to a robot's mirror ahead on their lane",
    )
    record_hz: float = param(
        10.0, "rows per second and person in tables/humans (capped by the SUMO step)", gt=0
    )

    def problems(self) -> Iterator[Problem]:
        """Ranges given as [min, max] must be ordered."""
        if self.pick_s[0] > self.pick_s[1]:
            yield Problem("pick_s", list(self.pick_s), "[min, max] with min <= max")

    @property
    def enabled(self) -> bool:
        """Whether the run has anyone moved by SUMO."""
        return self.workers > 0 or self.forklifts > 0 or bool(self.standing)

    @property
    def people(self) -> int:
        """Workers, standing ones included."""
        return self.workers + len(self.standing)

    def adapters(self) -> tuple[str, ...]:
        """The adapters these settings ask for: SUMO's people, with workers or forklifts."""
        return ("humans",) if self.enabled else ()
