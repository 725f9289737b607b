"""The warehouse world: walls, shelves and robot start poses (frame ``map``).

The inner room spans ``[0, size_x] x [0, size_y]`` metres; the walls lie outside it. All
obstacles are axis-aligned boxes ``(xmin, ymin, xmax, ymax)``: shelves turned by 90 deg
simply swap their extents. Every layout keeps a gap of at least ``aisle_width_m``
between any two shelves and between shelves and walls, and keeps a dock strip along the
south wall free. Obstacles that are disjoint convex sets separated by gaps wider than a
robot leave the free space connected, so every free point is reachable from every other.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
import numpy.typing as npt

from models.errors import ModelError

FloatArray = npt.NDArray[np.float64]

DOCK_GAP_M = 0.3
"""Free gap between neighbouring robots in the dock (m)."""
START_CLEARANCE_M = 0.1
"""Clearance kept between a start pose and any obstacle or robot (m)."""


@dataclass(frozen=True)
class WarehouseSpec:
    """Parameters of a warehouse (mirrors the ``world`` and ``robots`` scenario sections)."""

    size_m: tuple[float, float] = (30.0, 30.0)
    layout: Literal["random", "all_rows", "two_corridors"] = "random"
    shelf_size_m: tuple[float, float] = (2.0, 0.8)
    shelf_count: int = 24
    shelves_per_rack: int = 3
    aisle_width_m: float = 1.6
    wall_thickness_m: float = 0.2
    robot_count: int = 4
    robot_radius_m: float = 0.33
    placement: Literal["dock", "random", "explicit"] = "dock"
    positions: tuple[tuple[float, float, float], ...] = field(default=())


@dataclass(frozen=True)
class Warehouse:
    """A generated warehouse.

    Attributes:
        size_m: inner room size (x, y) in m.
        wall_thickness_m: wall thickness in m.
        walls: (4, 4) wall boxes ``xmin, ymin, xmax, ymax`` in ``map`` (m).
        shelves: (n, 4) shelf boxes in ``map`` (m).
        starts: (robots, 3) start poses ``x_m, y_m, yaw_rad`` in ``map``.
        dock_depth_m: depth of the dock strip along the south wall (m).
    """

    size_m: tuple[float, float]
    wall_thickness_m: float
    walls: FloatArray
    shelves: FloatArray
    starts: FloatArray
    dock_depth_m: float

    @property
    def boxes(self) -> FloatArray:
        """All static obstacles (walls, then shelves) as an (n, 4) box array."""
        return np.vstack([self.walls, self.shelves])

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """Outer bounds of the world including walls: xmin, ymin, xmax, ymax (m)."""
        t = self.wall_thickness_m
        return (-t, -t, self.size_m[0] + t, self.size_m[1] + t)

    def segments(self) -> FloatArray:
        """The obstacle outlines as an (4n, 4) array of segments ``x0, y0, x1, y1``."""
        return box_segments(self.boxes)

    def clearance(self, points: FloatArray) -> FloatArray:
        """Distance (m) from each point (k, 2) to the nearest static obstacle (0 inside)."""
        nearest: FloatArray = box_distance(points, self.boxes).min(axis=1)
        return nearest

    def is_free(self, points: FloatArray, radius_m: float) -> npt.NDArray[np.bool_]:
        """Whether a disc of ``radius_m`` at each point (k, 2) is inside the room and clear."""
        pts = np.atleast_2d(points)
        inside = (
            (pts[:, 0] >= radius_m)
            & (pts[:, 1] >= radius_m)
            & (pts[:, 0] <= self.size_m[0] - radius_m)
            & (pts[:, 1] <= self.size_m[1] - radius_m)
        )
        if len(self.shelves) == 0:
            return inside
        clear: npt.NDArray[np.bool_] = box_distance(pts, self.shelves).min(axis=1) >= radius_m
        return inside & clear


def box_segments(boxes: FloatArray) -> FloatArray:
    """Edges of axis-aligned boxes (n, 4) as (4n, 4) segments ``x0, y0, x1, y1``."""
    x0, y0, x1, y1 = boxes.T
    edges = [
        np.stack([x0, y0, x1, y0], axis=1),
        np.stack([x1, y0, x1, y1], axis=1),
        np.stack([x1, y1, x0, y1], axis=1),
        np.stack([x0, y1, x0, y0], axis=1),
    ]
    return np.stack(edges, axis=1).reshape(-1, 4)


def box_distance(points: FloatArray, boxes: FloatArray) -> FloatArray:
    """Euclidean distance (k, n) from points (k, 2) to boxes (n, 4); 0 inside a box."""
    px = points[:, 0:1]
    py = points[:, 1:2]
    dx = np.maximum(np.maximum(boxes[None, :, 0] - px, px - boxes[None, :, 2]), 0.0)
    dy = np.maximum(np.maximum(boxes[None, :, 1] - py, py - boxes[None, :, 3]), 0.0)
    return np.hypot(dx, dy)


def _walls(width: float, height: float, t: float) -> FloatArray:
    return np.array(
        [
            [-t, -t, width + t, 0.0],  # south
            [-t, height, width + t, height + t],  # north
            [-t, 0.0, 0.0, height],  # west
            [width, 0.0, width + t, height],  # east
        ]
    )


def dock_rows(spec: WarehouseSpec) -> tuple[int, int]:
    """Robots per dock row and number of dock rows for a fleet."""
    pitch = 2 * spec.robot_radius_m + DOCK_GAP_M
    per_row = int((spec.size_m[0] - DOCK_GAP_M) // pitch)
    if per_row < 1:
        raise ModelError(
            "world.size_m", list(spec.size_m), f"a room wider than one robot ({pitch:g} m)"
        )
    rows = math.ceil(spec.robot_count / per_row)
    return per_row, rows


def dock_depth(spec: WarehouseSpec) -> float:
    """Depth of the dock strip along the south wall (m); zero unless placement is ``dock``."""
    if spec.placement != "dock":
        return 0.0
    _, rows = dock_rows(spec)
    return rows * (2 * spec.robot_radius_m + DOCK_GAP_M) + DOCK_GAP_M


def _shelf_region(spec: WarehouseSpec, dock: float) -> tuple[float, float, float, float]:
    aisle = spec.aisle_width_m
    width, height = spec.size_m
    return (aisle, dock + aisle, width - aisle, height - aisle)


def _rack_shelves(
    spec: WarehouseSpec, region: tuple[float, float, float, float], bands: list[tuple[float, float]]
) -> FloatArray:
    """Shelves in racks of ``shelves_per_rack`` along x, rows of racks along y, per x band."""
    length, depth = spec.shelf_size_m
    aisle = spec.aisle_width_m
    k = spec.shelves_per_rack
    rack = k * length
    _, ymin, _, ymax = region
    rows = int((ymax - ymin + aisle) // (depth + aisle))
    slots: list[list[float]] = []
    for bx0, bx1 in bands:
        cols = int((bx1 - bx0 + aisle) // (rack + aisle))
        if cols < 1 or rows < 1:
            continue
        used_x = cols * rack + (cols - 1) * aisle
        used_y = rows * depth + (rows - 1) * aisle
        x_start = bx0 + (bx1 - bx0 - used_x) / 2
        y_start = ymin + (ymax - ymin - used_y) / 2
        for row in range(rows - 1, -1, -1):  # fill from the north, far from the dock
            y0 = y_start + row * (depth + aisle)
            for col in range(cols):
                for i in range(k):
                    x0 = x_start + col * (rack + aisle) + i * length
                    slots.append([x0, y0, x0 + length, y0 + depth])
    return np.array(slots, dtype=float).reshape(-1, 4)


def _random_shelves(
    spec: WarehouseSpec, region: tuple[float, float, float, float], rng: np.random.Generator
) -> FloatArray:
    length, depth = spec.shelf_size_m
    xmin, ymin, xmax, ymax = region
    aisle = spec.aisle_width_m
    # each shelf with half an aisle around it claims (L + a) x (D + a) of the region grown
    # by half an aisle on every side: more than fits there is impossible
    capacity = int(
        (xmax - xmin + aisle) * (ymax - ymin + aisle) // ((length + aisle) * (depth + aisle))
    )
    if spec.shelf_count > capacity:
        raise ModelError(
            "world.shelf_count",
            spec.shelf_count,
            f"at most {capacity} shelves of {list(spec.shelf_size_m)} m with {aisle:g} m aisles "
            f"in a {list(spec.size_m)} m room (by area)",
        )
    placed: list[list[float]] = []
    attempts = 0
    limit = 50_000
    while len(placed) < spec.shelf_count and attempts < limit:
        attempts += 1
        sx, sy = (length, depth) if rng.random() < 0.5 else (depth, length)
        if sx > xmax - xmin or sy > ymax - ymin:
            continue
        x0 = rng.uniform(xmin, xmax - sx)
        y0 = rng.uniform(ymin, ymax - sy)
        box = [x0, y0, x0 + sx, y0 + sy]
        if placed:
            others = np.array(placed)
            gap_x = np.maximum(others[:, 0] - box[2], box[0] - others[:, 2])
            gap_y = np.maximum(others[:, 1] - box[3], box[1] - others[:, 3])
            # the gap between two boxes is the larger of the axis gaps when one is
            # negative; both positive means a diagonal gap of hypot(gap_x, gap_y)
            gap = np.where(
                (gap_x > 0) & (gap_y > 0), np.hypot(gap_x, gap_y), np.maximum(gap_x, gap_y)
            )
            if np.any(gap < aisle):
                continue
        placed.append(box)
    if len(placed) < spec.shelf_count:
        raise ModelError(
            "world.shelf_count",
            spec.shelf_count,
            f"at most about {len(placed)} shelves of {list(spec.shelf_size_m)} m with "
            f"{aisle:g} m aisles in a {list(spec.size_m)} m room",
        )
    return np.array(placed, dtype=float).reshape(-1, 4)


def _shelves(spec: WarehouseSpec, dock: float, rng: np.random.Generator) -> FloatArray:
    region = _shelf_region(spec, dock)
    if spec.shelf_count == 0:
        return np.zeros((0, 4))
    if region[2] <= region[0] or region[3] <= region[1]:
        raise ModelError(
            "world.size_m", list(spec.size_m), "a room large enough for aisles around the dock"
        )
    if spec.layout == "random":
        return _random_shelves(spec, region, rng)
    xmin, _, xmax, _ = region
    if spec.layout == "all_rows":
        bands = [(xmin, xmax)]
    else:  # two_corridors: two north-south main corridors, two aisles wide
        corridor = 2 * spec.aisle_width_m
        third = (xmax - xmin - 2 * corridor) / 3
        bands = [
            (xmin + i * (third + corridor), xmin + i * (third + corridor) + third) for i in range(3)
        ]
    slots = _rack_shelves(spec, region, bands)
    if spec.shelf_count > len(slots):
        raise ModelError(
            "world.shelf_count",
            spec.shelf_count,
            f"at most {len(slots)} shelves for layout {spec.layout!r} in a "
            f"{list(spec.size_m)} m room with {spec.aisle_width_m:g} m aisles",
        )
    return slots[: spec.shelf_count]


def _dock_starts(spec: WarehouseSpec) -> FloatArray:
    per_row, _ = dock_rows(spec)
    pitch = 2 * spec.robot_radius_m + DOCK_GAP_M
    starts = np.zeros((spec.robot_count, 3))
    for i in range(spec.robot_count):
        row, col = divmod(i, per_row)
        in_row = min(per_row, spec.robot_count - row * per_row)
        x0 = (spec.size_m[0] - (in_row - 1) * pitch) / 2
        starts[i] = (x0 + col * pitch, DOCK_GAP_M + spec.robot_radius_m + row * pitch, math.pi / 2)
    return starts


def _random_starts(spec: WarehouseSpec, world: Warehouse, rng: np.random.Generator) -> FloatArray:
    radius = spec.robot_radius_m + START_CLEARANCE_M
    starts: list[tuple[float, float, float]] = []
    attempts = 0
    while len(starts) < spec.robot_count and attempts < 5000 * spec.robot_count:
        attempts += 1
        point = rng.uniform((0.0, 0.0), spec.size_m)
        yaw = rng.uniform(-math.pi, math.pi)
        if not world.is_free(point[None, :], radius)[0]:
            continue
        if starts and np.min(np.hypot(*(np.array(starts)[:, :2] - point).T)) < 2 * radius:
            continue
        starts.append((float(point[0]), float(point[1]), float(yaw)))
    if len(starts) < spec.robot_count:
        raise ModelError(
            "robots.count",
            spec.robot_count,
            f"at most about {len(starts)} robots with free start slots",
        )
    return np.array(starts)


def _check_explicit(spec: WarehouseSpec, world: Warehouse) -> FloatArray:
    starts = np.array(spec.positions, dtype=float).reshape(-1, 3)
    free = world.is_free(starts[:, :2], spec.robot_radius_m)
    for bad in np.flatnonzero(~free):
        i = int(bad)
        raise ModelError(
            f"robots.positions[{i}]",
            list(spec.positions[i]),
            f"a pose whose {spec.robot_radius_m:g} m footprint is inside the room "
            "and clear of shelves",
        )
    for i in range(len(starts)):
        gaps = np.hypot(*(starts[i + 1 :, :2] - starts[i, :2]).T)
        for j in np.flatnonzero(gaps < 2 * spec.robot_radius_m):
            raise ModelError(
                f"robots.positions[{i + 1 + j}]",
                list(spec.positions[i + 1 + j]),
                f"a pose at least {2 * spec.robot_radius_m:g} m from robot {i}",
            )
    return starts


def generate_warehouse(spec: WarehouseSpec, rng: np.random.Generator) -> Warehouse:
    """Generate a warehouse from its parameters.

    Args:
        spec: the parameters.
        rng: random stream for the random layout and random start poses.

    Raises:
        ModelError: for impossible requests (shelves that do not fit, more robots than
            free start slots, a start pose inside an obstacle).
    """
    width, height = spec.size_m
    if 2 * spec.robot_radius_m >= spec.aisle_width_m:
        raise ModelError(
            "world.aisle_width_m",
            spec.aisle_width_m,
            f"a width above the robot diameter ({2 * spec.robot_radius_m:g} m)",
        )
    dock = dock_depth(spec)
    if dock > height / 2:
        raise ModelError(
            "robots.count",
            spec.robot_count,
            f"a fleet whose dock fits in half the room ({height / 2:g} m)",
        )
    shelves = _shelves(spec, dock, rng)
    world = Warehouse(
        size_m=(width, height),
        wall_thickness_m=spec.wall_thickness_m,
        walls=_walls(width, height, spec.wall_thickness_m),
        shelves=shelves,
        starts=np.zeros((0, 3)),
        dock_depth_m=dock,
    )
    if spec.placement == "dock":
        starts = _dock_starts(spec)
    elif spec.placement == "random":
        starts = _random_starts(spec, world, rng)
    else:
        starts = _check_explicit(spec, world)
    return Warehouse(
        size_m=world.size_m,
        wall_thickness_m=world.wall_thickness_m,
        walls=world.walls,
        shelves=world.shelves,
        starts=starts,
        dock_depth_m=dock,
    )
