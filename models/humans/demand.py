"""Demand: what each worker and forklift does during a run (seeded, no SUMO needed).

A worker starts at a pick station and walks to pick stations drawn at random, staying at
each for a time drawn from ``pick_s``; after each pick it returns to the dock with
probability ``DOCK_RETURN`` (dropping off for ``DOCK_STAY_S``). A forklift does the same
with its own stays. Plans run past the simulation's end; SUMO simply stops there.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from models.arrays import FloatArray
from models.errors import ModelError
from models.humans.aisles import AisleGraph, IntArray

DOCK_RETURN = 0.3
"""Probability that a worker returns to the dock after a pick."""
DOCK_STAY_S = (5.0, 15.0)
"""How long a worker or forklift stays at the dock (s)."""
DEPART_SPREAD_S = 1.0
"""Departures are spread evenly over this interval from the start (s)."""
DETOUR = 1.5
"""Walking distance over straight-line distance assumed when estimating a plan's time."""


@dataclass(frozen=True)
class Spot:
    """A place on the aisle graph.

    Attributes:
        edge: edge index in the :class:`AisleGraph`.
        offset_m: distance from the edge's first node (m).
    """

    edge: int
    offset_m: float


@dataclass(frozen=True)
class Stage:
    """One step of a plan: go to ``spot``, then stay ``stay_s`` seconds (0: walk on)."""

    spot: Spot
    stay_s: float


@dataclass(frozen=True)
class Plan:
    """What one person or forklift does.

    Attributes:
        name: its id (``worker_3``, ``forklift_0``, ``standing_1``).
        kind: ``worker`` or ``forklift``.
        depart_s: when it appears (s).
        start: where it appears.
        stages: where it goes next, in order.
    """

    name: str
    kind: Literal["worker", "forklift"]
    depart_s: float
    start: Spot
    stages: tuple[Stage, ...]


def _spots(edges: IntArray, offsets: FloatArray) -> list[Spot]:
    return [Spot(int(e), float(o)) for e, o in zip(edges, offsets, strict=True)]


def plans(
    graph: AisleGraph,
    stations: tuple[IntArray, FloatArray],
    docks: tuple[IntArray, FloatArray],
    *,
    kind: Literal["worker", "forklift"],
    count: int,
    duration_s: float,
    speed_mps: float,
    stay_s: tuple[float, float],
    rng: np.random.Generator,
) -> list[Plan]:
    """Plans for ``count`` workers or forklifts covering ``duration_s``.

    Args:
        graph: the aisle graph.
        stations: pick stations (edge indices, offsets m).
        docks: dock spots (edge indices, offsets m).
        kind: ``worker`` or ``forklift``.
        count: how many.
        duration_s: the run's length (s); plans are made to last longer.
        speed_mps: travel speed for the time estimate (m/s).
        stay_s: [min, max] stay at a pick station (s).
        rng: the demand's random stream.
    """
    station_spots = _spots(*stations)
    dock_spots = _spots(*docks)
    result = []
    for k in range(count):
        # in the aisles already when the run starts (not at the dock where robots wait)
        start = station_spots[int(rng.integers(len(station_spots)))]
        stages = _stages(
            graph, start, station_spots, dock_spots, duration_s, speed_mps, stay_s, rng
        )
        depart = round(DEPART_SPREAD_S * k / max(count, 1), 1)
        result.append(Plan(f"{kind}_{k}", kind, depart, start, stages))
    return result


def _stages(
    graph: AisleGraph,
    start: Spot,
    stations: list[Spot],
    docks: list[Spot],
    duration_s: float,
    speed_mps: float,
    stay_s: tuple[float, float],
    rng: np.random.Generator,
) -> tuple[Stage, ...]:
    here = graph.point(start.edge, start.offset_m)
    elapsed = 0.0
    stages: list[Stage] = []
    while elapsed < duration_s + 60.0:
        visits = [(stations[int(rng.integers(len(stations)))], float(rng.uniform(*stay_s)))]
        if rng.random() < DOCK_RETURN:
            visits.append((docks[int(rng.integers(len(docks)))], float(rng.uniform(*DOCK_STAY_S))))
        for spot, stay in visits:
            there = graph.point(spot.edge, spot.offset_m)
            distance = float(np.hypot(there[0] - here[0], there[1] - here[1]))
            elapsed += DETOUR * distance / speed_mps + stay
            stages.append(Stage(spot, round(stay, 1)))
            here = there
    return tuple(stages)


STANDING_REACH_M = 2.0
"""A standing worker's point may lie at most this far from an aisle line (m)."""


def standing_plans(graph: AisleGraph, points: FloatArray, duration_s: float) -> list[Plan]:
    """Workers who stand, from the start, at the aisle spots nearest ``points`` (n, 2).

    Raises:
        ModelError: on ``humans.standing[i]`` for a point further than ``STANDING_REACH_M``
            from every aisle (outside the room, inside a shelf block): it would silently
            become a spot elsewhere.
    """
    if len(points) == 0:
        return []
    edges, offsets, gaps = graph.nearest(points)
    for i in np.flatnonzero(gaps > STANDING_REACH_M).tolist():
        raise ModelError(
            f"humans.standing[{i}]",
            [float(v) for v in points[i]],
            f"a point within {STANDING_REACH_M:g} m of an aisle where people walk (the "
            f"nearest is {gaps[i]:.1f} m away)",
        )
    return [
        Plan(f"standing_{k}", "worker", 0.0, spot, (Stage(spot, duration_s + 60.0),))
        for k, spot in enumerate(_spots(edges, offsets))
    ]
