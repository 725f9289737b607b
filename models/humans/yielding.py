"""People give way to robots: who stops, and for how long (frame ``map``).

SUMO's pedestrians keep to their lanes and give way to a vehicle ahead on the same lane
only; they walk into a robot standing on a junction or beside the lane line. The
co-simulation adds the rule people follow: a walker with a robot in their way (its
footprint within ``LOOKAHEAD_S`` of walking, plus a margin) stops until the way is clear,
as a person waits for a robot to pass. Like SUMO's own jams, the wait has a limit: after
``give_up_s`` the person walks on (and is not stopped again for as long), so a robot that
waits for the person in turn never deadlocks with them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray

LOOKAHEAD_S = 0.6
"""How far ahead a walker looks for robots, in seconds of walking."""
MARGIN_M = 0.15
"""Gap a walker keeps to a robot's footprint (m)."""


def robots_ahead(
    people: FloatArray,
    yaw_rad: FloatArray,
    speed_mps: float,
    robots: FloatArray,
) -> npt.NDArray[np.bool_]:
    """Which people have a robot in their way.

    Args:
        people: (m, 3) discs ``x_m, y_m, radius_m``.
        yaw_rad: (m,) walking directions (rad).
        speed_mps: walking speed (m/s) that sets the look-ahead distance.
        robots: (n, 3) robot discs ``x_m, y_m, radius_m``.

    Returns:
        (m,) True where a robot's footprint, grown by both radii and ``MARGIN_M``, meets
        the segment from the person to the point ``LOOKAHEAD_S`` of walking ahead, and
        the robot is in front of the person (not beside or behind).
    """
    if len(people) == 0 or len(robots) == 0:
        return np.zeros(len(people), dtype=bool)
    reach = LOOKAHEAD_S * speed_mps
    heading = np.column_stack([np.cos(yaw_rad), np.sin(yaw_rad)])
    rel = robots[None, :, :2] - people[:, None, :2]  # (m, n, 2)
    along = (rel * heading[:, None, :]).sum(axis=2)
    nearest = np.clip(along, 0.0, reach)
    foot = people[:, None, :2] + nearest[..., None] * heading[:, None, :]
    gap = np.hypot(*(robots[None, :, :2] - foot).transpose(2, 0, 1))
    touch = gap < people[:, None, 2] + robots[None, :, 2] + MARGIN_M
    blocked: npt.NDArray[np.bool_] = (touch & (along > 0)).any(axis=1)
    return blocked


@dataclass
class Yielding:
    """Who is stopped for a robot, since when, and who gave up waiting.

    Attributes:
        give_up_ns: longest wait (ns); then the person walks on.
    """

    give_up_ns: int
    held: dict[str, int] = field(default_factory=dict)
    gave_up: dict[str, int] = field(default_factory=dict)
    yields: int = 0

    def update(
        self,
        now_ns: int,
        names: list[str],
        blocked: npt.NDArray[np.bool_],
        walking: npt.NDArray[np.bool_],
    ) -> tuple[list[str], list[str]]:
        """Decide who stops now and who walks on.

        Args:
            now_ns: the instant (ns).
            names: the people present.
            blocked: (m,) whether each has a robot in the way.
            walking: (m,) whether each is walking now (not staying at a station).

        Returns:
            The people to stop now, and those to let walk on (clear, or waited too long).
        """
        present = set(names)
        for gone in [n for n in self.held if n not in present]:
            del self.held[gone]
        for done in [n for n, t in self.gave_up.items() if now_ns - t >= self.give_up_ns]:
            del self.gave_up[done]
        stop: list[str] = []
        go: list[str] = []
        for name, is_blocked, is_walking in zip(
            names, blocked.tolist(), walking.tolist(), strict=True
        ):
            since = self.held.get(name)
            if since is not None:
                if not is_blocked or now_ns - since >= self.give_up_ns:
                    del self.held[name]
                    go.append(name)
                    if is_blocked:
                        self.gave_up[name] = now_ns
            elif is_blocked and is_walking and name not in self.gave_up:
                self.held[name] = now_ns
                self.yields += 1
                stop.append(name)
        return stop, go
