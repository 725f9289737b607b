"""Shelf layouts of the warehouse: where shelves go, given the hall and its aisles.

Shelves are axis-aligned boxes ``(xmin, ymin, xmax, ymax)`` in ``map`` (m); a shelf turned
by 90 deg swaps its extents. Every layout keeps at least ``aisle_width_m`` between any two
shelves (racks in the rows layouts), between shelves and walls, and between shelves and
extra obstacles, and keeps the dock strip along the south wall free.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from models.arrays import FloatArray
from models.errors import ModelError

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
    obstacles: tuple[tuple[float, float, float, float], ...] = field(default=())


def _shelf_region(spec: WarehouseSpec, dock: float) -> tuple[float, float, float, float]:
    aisle = spec.aisle_width_m
    width, height = spec.size_m
    return (aisle, dock + aisle, width - aisle, height - aisle)


def box_gaps(boxes: FloatArray, box: FloatArray) -> FloatArray:
    """Free gap (m) between one box and each of (n, 4) boxes; negative when they overlap."""
    gap_x = np.maximum(boxes[:, 0] - box[2], box[0] - boxes[:, 2])
    gap_y = np.maximum(boxes[:, 1] - box[3], box[1] - boxes[:, 3])
    # apart along both axes: the corners are closest; along one axis: that axis' gap
    both = (gap_x > 0) & (gap_y > 0)
    gaps: FloatArray = np.where(both, np.hypot(gap_x, gap_y), np.maximum(gap_x, gap_y))
    return gaps


def _keepout(spec: WarehouseSpec) -> tuple[FloatArray, FloatArray]:
    """Boxes shelves keep an aisle from (obstacles), and boxes they must not overlap.

    The latter are the squares around explicit start poses.
    """
    obstacles = np.array(spec.obstacles, dtype=float).reshape(-1, 4)
    starts = np.array(spec.positions, dtype=float).reshape(-1, 3)
    reach = spec.robot_radius_m + START_CLEARANCE_M
    squares = np.stack(
        [starts[:, 0] - reach, starts[:, 1] - reach, starts[:, 0] + reach, starts[:, 1] + reach],
        axis=1,
    )
    return obstacles, squares


def _allowed(box: FloatArray, spec: WarehouseSpec, keepout: tuple[FloatArray, FloatArray]) -> bool:
    obstacles, squares = keepout
    if len(obstacles) and np.any(box_gaps(obstacles, box) < spec.aisle_width_m):
        return False
    return not (len(squares) and np.any(box_gaps(squares, box) < 0))


def _band_slots(
    spec: WarehouseSpec, band: tuple[float, float], ymin: float, ymax: float
) -> list[list[float]]:
    """Shelves in one x band: racks of ``shelves_per_rack`` along x, rows along y.

    A band too narrow for a whole rack gets shorter racks (as many shelves as fit), and one
    too narrow for a single shelf lengthwise gets the shelves turned (one per rack, their
    length along y), as a rack generator sized to the room would.
    """
    length, depth = spec.shelf_size_m
    aisle = spec.aisle_width_m
    bx0, bx1 = band
    per_rack = min(spec.shelves_per_rack, int((bx1 - bx0 + 1e-9) // length))
    sx, sy = length, depth
    if per_rack < 1:  # turned: the shelf's depth along x
        per_rack, sx, sy = 1, depth, length
    rack = per_rack * sx
    rows = int((ymax - ymin + aisle + 1e-9) // (sy + aisle))
    cols = int((bx1 - bx0 + aisle + 1e-9) // (rack + aisle))
    if cols < 1 or rows < 1:
        return []
    used_x = cols * rack + (cols - 1) * aisle
    used_y = rows * sy + (rows - 1) * aisle
    x_start = bx0 + (bx1 - bx0 - used_x) / 2
    y_start = ymin + (ymax - ymin - used_y) / 2
    slots = []
    for row in range(rows):
        y0 = y_start + row * (sy + aisle)
        for col in range(cols):
            for i in range(per_rack):
                x0 = x_start + col * (rack + aisle) + i * sx
                slots.append([x0, y0, x0 + sx, y0 + sy])
    return slots


def _rack_shelves(
    spec: WarehouseSpec, region: tuple[float, float, float, float], bands: list[tuple[float, float]]
) -> FloatArray:
    """Shelves in racks along x, rows of racks along y, per x band (see :func:`_band_slots`)."""
    _, ymin, _, ymax = region
    slots = [slot for band in bands for slot in _band_slots(spec, band, ymin, ymax)]
    boxes = np.array(slots, dtype=float).reshape(-1, 4)
    # fill whole rows from the north (far from the dock) across every band first
    return boxes[np.lexsort((boxes[:, 0], -boxes[:, 1]))]


def _corridor_bands(
    spec: WarehouseSpec, xmin: float, xmax: float
) -> list[list[tuple[float, float]]]:
    """Ways to lay three shelf bands between two north-south main corridors.

    Corridors two aisles wide first, then one aisle wide (room for longer racks); only
    ways whose bands are at least a shelf's depth wide.

    Raises:
        ModelError: on ``world.size_m`` when even one-aisle corridors leave no band a shelf
            fits in, naming the narrowest room that would do.
    """
    aisle = spec.aisle_width_m
    narrow = min(spec.shelf_size_m)
    ways = []
    for corridor in (2 * aisle, aisle):
        third = (xmax - xmin - 2 * corridor) / 3
        if third >= narrow:
            ways.append(
                [
                    (xmin + i * (third + corridor), xmin + i * (third + corridor) + third)
                    for i in range(3)
                ]
            )
    if ways:
        return ways
    least = 3 * narrow + 4 * aisle
    raise ModelError(
        "world.size_m",
        list(spec.size_m),
        f"a room at least {least:.2f} m wide for layout 'two_corridors' (three bands of "
        f"{narrow:g} m shelves, two corridors and the side aisles of {aisle:g} m)",
    )


def _random_shelves(
    spec: WarehouseSpec,
    region: tuple[float, float, float, float],
    rng: np.random.Generator,
    keepout: tuple[FloatArray, FloatArray],
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
        box = np.array([x0, y0, x0 + sx, y0 + sy])
        if placed and np.any(box_gaps(np.array(placed), box) < aisle):
            continue
        if not _allowed(box, spec, keepout):
            continue
        placed.append(list(box))
    if len(placed) < spec.shelf_count:
        raise ModelError(
            "world.shelf_count",
            spec.shelf_count,
            f"at most about {len(placed)} shelves of {list(spec.shelf_size_m)} m with "
            f"{aisle:g} m aisles in a {list(spec.size_m)} m room",
        )
    return np.array(placed, dtype=float).reshape(-1, 4)


def place_shelves(spec: WarehouseSpec, dock: float, rng: np.random.Generator) -> FloatArray:
    """Shelves for the spec's layout, north of a dock strip ``dock`` m deep.

    Args:
        spec: the warehouse parameters.
        dock: depth of the dock strip along the south wall (m).
        rng: random stream of the random layout.

    Raises:
        ModelError: when the requested shelves do not fit.
    """
    region = _shelf_region(spec, dock)
    if spec.shelf_count == 0:
        return np.zeros((0, 4))
    if region[2] <= region[0] or region[3] <= region[1]:
        raise ModelError(
            "world.size_m", list(spec.size_m), "a room large enough for aisles around the dock"
        )
    keepout = _keepout(spec)
    if spec.layout == "random":
        return _random_shelves(spec, region, rng, keepout)
    xmin, _, xmax, _ = region
    # two_corridors: shelf bands between two north-south main corridors
    ways = [[(xmin, xmax)]] if spec.layout == "all_rows" else _corridor_bands(spec, xmin, xmax)
    slots = np.zeros((0, 4))
    for bands in ways:  # the first way with room for every shelf, else the roomiest
        found = _rack_shelves(spec, region, bands)
        found = np.array([s for s in found if _allowed(s, spec, keepout)]).reshape(-1, 4)
        if len(found) > len(slots):
            slots = found
        if len(slots) >= spec.shelf_count:
            break
    if spec.shelf_count > len(slots):
        raise ModelError(
            "world.shelf_count",
            spec.shelf_count,
            f"at most {len(slots)} shelves for layout {spec.layout!r} in a "
            f"{list(spec.size_m)} m room with {spec.aisle_width_m:g} m aisles",
        )
    return slots[: spec.shelf_count]
