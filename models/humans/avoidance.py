"""People keep clear of robots: a collision-free speed model over SUMO's walking (``map``).

SUMO's striping model gives way only to what is ahead on a person's own lane and stripe,
and not at all on junctions; nothing in it knows the robots' true footprints. Two layers
run on top of it at every coupling step, batched over people and robots:

1. **Speed** (Tordeux, Chraibi & Seyfried 2016, "Collision-free speed model for pedestrian
   dynamics", Traffic and Granular Flow '15, Springer, pp. 225-232): a walker's speed is

       v = min(v0, max(0, (s - l) / T))

   with ``s - l`` the free distance ahead: how far the person can walk along their heading
   before their disc touches a robot's footprint grown by ``margin_m`` (the swept corridor
   of the person's disc, not only the centre line). ``T`` is the model's time gap
   (``TIME_GAP_S``, the paper's 1 s). The direction stays SUMO's: its router and stripes
   choose where to walk, this layer only how fast. A step is also never longer than the
   room to any robot not behind the person (:func:`room`), whatever way SUMO turns it.
2. **Safety projection**: the step SUMO took from the last published position is cut
   where the person's disc would come within ``margin_m`` of a robot's footprint (a
   person already closer may only move away). It catches what the speed law cannot see a
   step ahead: sideways stripe changes, turns on a junction, a person put back on the lane
   when they stop. A person who cannot pass a standing robot thus waits; nobody walks
   into a robot.

Robots that drive into a person are the robots' business (they see people and stop);
this module moves only people.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray

TIME_GAP_S = 1.0
"""The speed model's time gap T (s): Tordeux et al. (2016) fit 1 s to single-file data."""
MARGIN_M = 0.1
"""Gap a walker keeps between their body and a robot's footprint (m)."""


def free_distance(
    xy: FloatArray,
    yaw_rad: FloatArray,
    radius_m: FloatArray,
    robots: FloatArray,
    *,
    margin_m: float = MARGIN_M,
) -> FloatArray:
    """How far each person can walk straight ahead before coming within the margin (m).

    Args:
        xy: (m, 2) people's positions (``map``, m).
        yaw_rad: (m,) their walking directions (rad).
        radius_m: (m,) their radii (m).
        robots: (n, 3) robot footprints ``x_m, y_m, radius_m``.
        margin_m: gap kept to a footprint (m).

    Returns:
        (m,) the distance along the heading to the first point where the person's disc
        meets a robot's disc grown by the person's radius and ``margin_m`` (``inf``
        without any robot in the way; 0 for a robot already that close and ahead).
    """
    m = len(xy)
    if m == 0 or len(robots) == 0:
        return np.full(m, np.inf)
    heading = np.column_stack([np.cos(yaw_rad), np.sin(yaw_rad)])
    rel = robots[None, :, :2] - xy[:, None, :]  # (m, n, 2)
    along = (rel * heading[:, None, :]).sum(axis=2)
    across = rel[..., 1] * heading[:, None, 0] - rel[..., 0] * heading[:, None, 1]
    reach = radius_m[:, None] + robots[None, :, 2] + margin_m
    inside = along**2 + across**2 < reach**2
    crossing = np.abs(across) < reach
    entry = along - np.sqrt(np.maximum(reach**2 - across**2, 0.0))
    gap = np.where(crossing & (along > 0), np.maximum(entry, 0.0), np.inf)
    gap = np.where(inside & (along > 0), 0.0, gap)
    free: FloatArray = gap.min(axis=1)
    return free


def room(
    xy: FloatArray,
    yaw_rad: FloatArray,
    radius_m: FloatArray,
    robots: FloatArray,
    *,
    margin_m: float = MARGIN_M,
) -> FloatArray:
    """How far each person may move in any direction but backwards before the margin (m).

    The free distance ahead assumes a straight walk; SUMO also moves people sideways
    (stripe changes) and along curves on junctions. Bounding a step by the clearance to
    every robot not behind the person (footprint to body, less ``margin_m``) keeps any
    such step clear of them. Robots behind (``along <= 0``) are left out, so a person
    next to a robot may always walk away from it.

    Returns:
        (m,) the room (m; ``inf`` without robots ahead or beside, 0 when closer than the
        margin).
    """
    m = len(xy)
    if m == 0 or len(robots) == 0:
        return np.full(m, np.inf)
    heading = np.column_stack([np.cos(yaw_rad), np.sin(yaw_rad)])
    rel = robots[None, :, :2] - xy[:, None, :]
    along = (rel * heading[:, None, :]).sum(axis=2)
    clear = np.hypot(rel[..., 0], rel[..., 1]) - radius_m[:, None] - robots[None, :, 2]
    slack = np.where(along > 0, np.maximum(clear - margin_m, 0.0), np.inf)
    least: FloatArray = slack.min(axis=1)
    return least


def speed_limit(
    free_m: FloatArray,
    v0_mps: FloatArray,
    *,
    time_gap_s: float = TIME_GAP_S,
    room_m: FloatArray | None = None,
    step_s: float = 0.1,
) -> FloatArray:
    """The collision-free speed ``min(v0, max(0, free / T))``, and at most ``room / step``.

    Args:
        free_m: (m,) free distance ahead, ``s - l`` in the paper (m).
        v0_mps: (m,) desired (free-walking) speeds (m/s).
        time_gap_s: the time gap T (s).
        room_m: (m,) room in any direction but backwards (:func:`room`), or ``None``.
        step_s: the step over which the speed holds (s).
    """
    speed: FloatArray = np.minimum(v0_mps, np.maximum(0.0, free_m / time_gap_s))
    if room_m is not None:
        speed = np.minimum(speed, room_m / step_s)
    return speed


def safe_step(
    start: FloatArray,
    proposed: FloatArray,
    radius_m: FloatArray,
    robots: FloatArray,
    *,
    margin_m: float = MARGIN_M,
) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
    """Cut each person's step where it would bring them within the margin of a robot.

    Every step is the straight segment from ``start`` to ``proposed``; it is kept up to
    the first point where the person's disc comes within ``margin_m`` of a footprint. A
    person already that close to a robot keeps their start when the step brings them
    closer to it, and moves freely when it takes them away.

    Args:
        start: (m, 2) positions before the step (``map``, m).
        proposed: (m, 2) positions SUMO proposes (m).
        radius_m: (m,) the people's radii (m).
        robots: (n, 3) robot footprints ``x_m, y_m, radius_m``.
        margin_m: gap kept to a footprint (m).

    Returns:
        (m, 2) the positions allowed, and (m,) which steps were cut.
    """
    m = len(start)
    if m == 0 or len(robots) == 0:
        return np.array(proposed, dtype=float), np.zeros(m, dtype=bool)
    d = proposed - start  # (m, 2)
    rel = start[:, None, :] - robots[None, :, :2]  # (m, n, 2) from robot to person
    reach = radius_m[:, None] + robots[None, :, 2] + margin_m
    # |rel + t d|^2 = reach^2: a t^2 + 2 b t + c = 0
    a = (d**2).sum(axis=1)[:, None]
    b = (rel * d[:, None, :]).sum(axis=2)
    c = (rel**2).sum(axis=2) - reach**2
    approaching = b < 0
    with np.errstate(divide="ignore", invalid="ignore"):
        first = (-b - np.sqrt(np.maximum(b * b - a * c, 0.0))) / a
    touches = approaching & (b * b - a * c > 0) & (first <= 1.0)
    # already within reach and getting closer: no step at all
    t = np.where(c <= 0, np.where(approaching, 0.0, 1.0), np.where(touches, first, 1.0))
    allowed = np.clip(t.min(axis=1), 0.0, 1.0)
    cut = allowed < 1.0
    return start + allowed[:, None] * d, cut


def step_aside(
    xy: FloatArray, radius_m: FloatArray, robots: FloatArray, *, margin_m: float = MARGIN_M
) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
    """Move people who appear inside a robot's reach straight out of it (m, ``map``).

    For someone SUMO puts into the world where a robot stands (nobody walked there): the
    disc moves away from the nearest such robot's centre until it keeps ``margin_m``.

    Returns:
        (m, 2) the positions, and (m,) which were moved.
    """
    pts = np.array(xy, dtype=float).reshape(-1, 2)
    if len(pts) == 0 or len(robots) == 0:
        return pts, np.zeros(len(pts), dtype=bool)
    rel = pts[:, None, :] - robots[None, :, :2]
    dist = np.hypot(rel[..., 0], rel[..., 1])
    reach = radius_m[:, None] + robots[None, :, 2] + margin_m
    short = reach - dist
    worst = short.argmax(axis=1)
    rows = np.arange(len(pts))
    moved = short[rows, worst] > 0
    for i in np.flatnonzero(moved).tolist():
        j = int(worst[i])
        away = rel[i, j] / dist[i, j] if dist[i, j] > 1e-9 else np.array([0.0, 1.0])
        pts[i] = robots[j, :2] + away * reach[i, j]
    return pts, moved
