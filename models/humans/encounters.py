"""Robots among people: clearances, near misses and stops that people cause.

Clearance is footprint to footprint: centre distance minus the robot's and the person's
radii (m; negative when they overlap). A near miss is one *episode* of a robot-person pair
closer than ``near_miss_m``: it is counted when the pair comes closer and ends once they
are further apart than that again, so a robot waiting beside a picker is one near miss,
not one per step. A stop caused by people is a robot that was moving (faster than
``MOVING_MPS``) and comes to a halt (slower than ``HALT_MPS``) with a person within
``stop_radius_m`` of its footprint.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray

MOVING_MPS = 0.05
"""A robot faster than this is moving (m/s)..."""
HALT_MPS = 0.02
"""...and one slower than this has halted (m/s)."""


@dataclass(frozen=True)
class Encounter:
    """A robot and a person close to each other.

    Attributes:
        robot: robot index.
        person: the person's name.
        clearance_m: footprint-to-footprint distance at that moment (m).
    """

    robot: int
    person: str
    clearance_m: float


@dataclass
class Encounters:
    """Keeps the run's robot-person closeness.

    Attributes:
        near_miss_m: near-miss threshold (m).
        stop_radius_m: a halt with a person this close counts as caused by people (m).
        min_clearance_m: smallest clearance seen so far (m; inf before any person).
    """

    near_miss_m: float
    stop_radius_m: float
    min_clearance_m: float = np.inf
    _near: set[tuple[int, str]] = field(default_factory=set)
    _moving: npt.NDArray[np.bool_] | None = None

    def update(
        self,
        robots: FloatArray,
        speed_mps: FloatArray,
        people: FloatArray,
        names: list[str],
    ) -> tuple[list[Encounter], list[Encounter]]:
        """Take one instant into account.

        Args:
            robots: (n, 3) robot discs ``x_m, y_m, radius_m``.
            speed_mps: (n,) robot speeds (m/s).
            people: (m, 3) people discs ``x_m, y_m, radius_m``.
            names: the people's names, in the order of ``people``.

        Returns:
            The near misses that began now, and the stops that people caused now (each
            with the nearest person).
        """
        speed = np.abs(np.asarray(speed_mps, dtype=float))
        moving_before = self._moving if self._moving is not None else speed > MOVING_MPS
        self._moving = np.where(
            speed > MOVING_MPS, True, np.where(speed < HALT_MPS, False, moving_before)
        )
        if len(people) == 0 or len(robots) == 0:
            self._near = set()
            return [], []
        gap = np.hypot(
            robots[:, None, 0] - people[None, :, 0], robots[:, None, 1] - people[None, :, 1]
        )
        clearance = gap - robots[:, None, 2] - people[None, :, 2]
        self.min_clearance_m = min(self.min_clearance_m, float(clearance.min()))
        close = np.argwhere(clearance < self.near_miss_m)
        near = {(int(i), names[j]) for i, j in close.tolist()}
        began = [
            Encounter(int(i), names[j], float(clearance[i, j]))
            for i, j in close.tolist()
            if (int(i), names[j]) not in self._near
        ]
        self._near = near
        nearest = clearance.argmin(axis=1)
        least = clearance[np.arange(len(robots)), nearest]
        halted = moving_before & (speed < HALT_MPS) & (least < self.stop_radius_m)
        stops = [
            Encounter(int(i), names[int(nearest[i])], float(least[i]))
            for i in np.flatnonzero(halted).tolist()
        ]
        return began, stops
