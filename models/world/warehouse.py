"""The warehouse world: walls, shelves and robot start poses (frame ``map``).

``WarehouseSpec`` and the shelf layouts live in :mod:`models.world.layout`.

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

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray
from models.errors import ModelError
from models.geometry.occupancy import OccupancyGrid, rasterize_boxes
from models.world.layout import (
    DOCK_GAP_M,
    START_CLEARANCE_M,
    WarehouseSpec,
    place_shelves,
)


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
        obstacles: (k, 4) extra obstacle boxes given by the user, in ``map`` (m).
    """

    size_m: tuple[float, float]
    wall_thickness_m: float
    walls: FloatArray
    shelves: FloatArray
    starts: FloatArray
    dock_depth_m: float
    obstacles: FloatArray = field(default_factory=lambda: np.zeros((0, 4)))

    @property
    def boxes(self) -> FloatArray:
        """All static obstacles (walls, shelves, then extra obstacles) as an (n, 4) array."""
        return np.vstack([self.walls, self.shelves, self.obstacles])

    @property
    def inner_boxes(self) -> FloatArray:
        """Shelves and extra obstacles (everything inside the room) as an (n, 4) array."""
        return np.vstack([self.shelves, self.obstacles])

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
        inner = self.inner_boxes
        if len(inner) == 0:
            return inside
        clear: npt.NDArray[np.bool_] = box_distance(pts, inner).min(axis=1) >= radius_m
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


def _check_obstacles(spec: WarehouseSpec) -> FloatArray:
    boxes = np.array(spec.obstacles, dtype=float).reshape(-1, 4)
    width, height = spec.size_m
    for i, (xmin, ymin, xmax, ymax) in enumerate(boxes):
        if not (0 <= xmin < xmax <= width and 0 <= ymin < ymax <= height):
            raise ModelError(
                f"world.obstacles[{i}]",
                list(spec.obstacles[i]),
                f"a box [xmin, ymin, xmax, ymax] with xmin < xmax, ymin < ymax inside the "
                f"room [0, 0, {width:g}, {height:g}]",
            )
    return boxes


def _check_fleet(spec: WarehouseSpec) -> None:
    """Refuse a fleet the room cannot hold, naming the most robots it can.

    Docked robots stand in rows along the south wall and may take half the room; randomly
    placed ones need a footprint each (an upper bound: shelves take more room).
    """
    width, height = spec.size_m
    pitch = 2 * spec.robot_radius_m + DOCK_GAP_M
    if spec.placement == "dock":
        per_row = int((width - DOCK_GAP_M) // pitch)
        rows = int((height / 2 - DOCK_GAP_M) // pitch)
        most = max(per_row, 0) * max(rows, 0)
        where = f"docked in rows of {max(per_row, 0)} in the south half of the"
    elif spec.placement == "random":
        most = int(width // pitch) * int(height // pitch)
        where = "with room around each in the"
    else:
        return  # explicit poses are checked one by one
    if spec.robot_count > most:
        raise ModelError(
            "robots.count",
            spec.robot_count,
            f"at most {most} robots of {2 * spec.robot_radius_m:g} m {where} "
            f"{width:g} m x {height:g} m room",
        )


def _check_shelf_size(spec: WarehouseSpec, dock: float) -> None:
    """Refuse shelves longer or deeper than the room leaves room for, naming the limit."""
    aisle = spec.aisle_width_m
    width, height = spec.size_m
    free_x = width - 2 * aisle
    free_y = height - dock - 2 * aisle
    length, depth = spec.shelf_size_m
    room = f"with {aisle:g} m aisles around them in the {width:g} m x {height:g} m room"
    if min(length, depth) > max(free_x, free_y) or min(free_x, free_y) <= 0:
        raise ModelError(
            "world.shelf_size_m",
            list(spec.shelf_size_m),
            f"shelves at most {max(min(free_x, free_y), 0):.2f} m deep {room}",
        )
    short, long_ = sorted((length, depth))
    longest = max(free_x if short <= free_y else 0.0, free_y if short <= free_x else 0.0)
    if long_ > longest:
        raise ModelError(
            "world.shelf_size_m",
            list(spec.shelf_size_m),
            f"shelves at most {longest:.2f} m long ({short:g} m deep) {room}",
        )


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
    # the binding problem first: a fleet that cannot fit makes every other answer moot
    _check_fleet(spec)
    if 2 * spec.robot_radius_m >= spec.aisle_width_m:
        raise ModelError(
            "world.aisle_width_m",
            spec.aisle_width_m,
            f"a width above the robot diameter ({2 * spec.robot_radius_m:g} m)",
        )
    dock = dock_depth(spec)
    obstacles = _check_obstacles(spec)
    if spec.shelf_count > 0:
        _check_shelf_size(spec, dock)
    shelves = place_shelves(spec, dock, rng)
    world = Warehouse(
        size_m=(width, height),
        wall_thickness_m=spec.wall_thickness_m,
        walls=_walls(width, height, spec.wall_thickness_m),
        shelves=shelves,
        starts=np.zeros((0, 3)),
        dock_depth_m=dock,
        obstacles=obstacles,
    )
    if spec.placement == "dock":
        starts = _dock_starts(spec)
        blocked = ~world.is_free(starts[:, :2], spec.robot_radius_m)
        if blocked.any():
            raise ModelError(
                "world.obstacles",
                [list(o) for o in spec.obstacles],
                f"boxes clear of the dock strip (y < {dock:g} m), where robot "
                f"{int(np.flatnonzero(blocked)[0])} starts",
            )
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
        obstacles=obstacles,
    )


__all__ = [
    "Warehouse",
    "WarehouseSpec",
    "box_distance",
    "box_segments",
    "dock_depth",
    "dock_rows",
    "generate_warehouse",
]


def ground_truth_grid(warehouse: Warehouse, resolution_m: float) -> OccupancyGrid:
    """The ground-truth occupancy of a warehouse's walls and shelves.

    Args:
        warehouse: the generated world.
        resolution_m: cell edge length (m/cell).

    Returns:
        A grid covering :attr:`models.world.warehouse.Warehouse.bounds` (walls included) with every
        cell free or occupied; robots are not obstacles.
    """
    return rasterize_boxes(warehouse.boxes, warehouse.bounds, resolution_m)
