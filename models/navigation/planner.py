"""Global planning on a costmap: A* on the 8-connected grid, path pruning, goal checks.

Cost model: a step from a cell to a neighbour costs ``step * (1 + cost_weight * c / 252)``
(m), where ``step`` is the resolution (straight) or ``sqrt(2)`` times it (diagonal) and
``c`` the Nav2 cost of the cell entered; cells with ``c >= lethal`` are never entered. The
octile distance is then an admissible and consistent heuristic, so A* returns a path of
least cost. A diagonal step is allowed only when both cells it passes between are
enterable (no corner cutting past an obstacle).

Escape rule: a robot that touches something (its start cell blocked, e.g. inscribed,
or holding a lidar point) must still be able to leave. When the start cell is blocked,
blocked cells whose centre lies within ``D`` of the start cell's centre are enterable as
if their cost were 252, where ``D`` is the distance to the nearest enterable cell; the
enterable cells of that disc all lie on its rim. Every monotone staircase from the start
to such a cell stays in the disc, so the shortest way out is always found. The disc does
not reach across an obstacle as long as free space on the robot's side is nearer than
beyond it, which holds for a robot centred outside the obstacle with room on its side
(the blocked band around an obstacle is equally wide on both sides). ``D`` is not
capped, and unknown cells count as blocked.

Cells are ``(ix, iy)`` pairs (column, row); cost grids are indexed ``[iy, ix]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import StrEnum

import numpy as np

from models.arrays import FloatArray, IntArray, UInt8Array
from models.errors import ModelError
from models.navigation.costmap import INSCRIBED, NO_INFORMATION, StaticCostmap
from models.navigation.gridsearch import DX, DY, SQRT2, astar, escape_r2, prune, readonly
from models.navigation.landmarks import Landmarks

_NO_LANES = readonly(np.zeros((0, 0), dtype=np.uint8))
_NO_FIELDS = readonly(np.zeros((0, 0), dtype=np.int32))
_NO_FLOOR = readonly(np.zeros((0, 0), dtype=np.uint8))


@dataclass(frozen=True, eq=False)
class PlanResult:
    """The outcome of one global plan.

    Attributes:
        found: whether a path exists.
        cells: (n, 2) int64 cells ``(ix, iy)`` from start to goal; (0, 2) if not found.
        length_m: geometric length of the cell-centre path (m); ``inf`` if not found.
        cost_m: the A* objective of the path, length weighted by cell costs (m).
        expansions: number of cells A* expanded (closed).
    """

    found: bool
    cells: IntArray
    length_m: float
    cost_m: float
    expansions: int


def _check_cell(name: str, cell: tuple[int, int], cost: UInt8Array) -> tuple[int, int]:
    ix, iy = int(cell[0]), int(cell[1])
    if not (0 <= ix < cost.shape[1] and 0 <= iy < cost.shape[0]):
        raise ModelError(
            name, (ix, iy), f"a cell (ix, iy) of the {cost.shape[1]}x{cost.shape[0]} grid"
        )
    return ix, iy


def _check_landmarks(landmarks: Landmarks, grid: UInt8Array, weight: float, lethal: int) -> None:
    if landmarks.cost.shape != grid.shape:
        raise ModelError(
            "landmarks", landmarks.cost.shape, f"fields of the cost grid's shape {grid.shape}"
        )
    if lethal != landmarks.lethal:
        raise ModelError("lethal", lethal, f"the landmarks' threshold {landmarks.lethal}")
    if weight < landmarks.cost_weight:
        raise ModelError(
            "cost_weight", weight, f"at least the landmarks' weight {landmarks.cost_weight:g}"
        )


def _escape_is_free(landmarks: Landmarks, sx: int, sy: int, escape: int) -> bool:
    """Whether the start's escape disc holds only cells enterable on the static layer."""
    if escape <= 0:
        return escape == 0
    r = math.isqrt(escape)
    static = landmarks.cost
    x0, x1 = max(sx - r, 0), min(sx + r + 1, static.shape[1])
    y0, y1 = max(sy - r, 0), min(sy + r + 1, static.shape[0])
    dx = np.arange(x0, x1) - sx
    dy = np.arange(y0, y1) - sy
    disc = dx[None, :] ** 2 + dy[:, None] ** 2 <= escape
    return not bool((static[y0:y1, x0:x1][disc] >= landmarks.lethal).any())


def plan(
    cost: UInt8Array,
    start_cell: tuple[int, int],
    goal_cell: tuple[int, int],
    *,
    cost_weight: float = 1.0,
    lethal: int = INSCRIBED,
    resolution_m: float = 1.0,
    lanes: UInt8Array | None = None,
    against: float = 1.0,
    landmarks: Landmarks | None = None,
) -> PlanResult:
    """A least-cost path between two cells of a cost grid (A*, 8-connected).

    Args:
        cost: (rows, cols) uint8 Nav2 costs, ``[iy, ix]``, e.g. from
            :func:`models.navigation.costmap.with_obstacles`. Unknown cells (255) are
            blocked with the default ``lethal``; a caller that wants to plan through
            unknown space lowers them first.
        start_cell: ``(ix, iy)`` start; may be blocked (see the module's escape rule).
        goal_cell: ``(ix, iy)`` goal; a blocked goal outside the escape disc is not found.
        cost_weight: weight of the cell costs: a step costs
            ``step * (1 + cost_weight * c / 252)``; 0 gives the geometric shortest path.
        lethal: cells with a cost at or above this are never entered (253: the robot
            centre may not touch anything; 254: it may, as long as it is not in an
            obstacle cell).
        resolution_m: cell edge length (m) for ``length_m`` and ``cost_m``.
        lanes: optional (rows, cols) one-way directions of the cells
            (:func:`models.navigation.lanes.aisle_lanes`), same shape as ``cost``.
        against: a step against the lane of the cell it enters costs this many times
            more (>= 1; steps only get dearer, so the heuristic stays admissible).
        landmarks: optional landmark fields of the static layer ``cost`` was made from
            (:mod:`models.navigation.landmarks`), for a larger heuristic: a path of the
            same cost (among equal-cost paths possibly another one) after about half
            the expansions on a large floor. ``cost`` must not be below the layer's
            costs where it is enterable (stamped obstacles only raise costs), with the
            same ``lethal`` and a ``cost_weight`` at least the fields'. A start whose
            escape disc reaches cells blocked on the static layer plans without them.

    Raises:
        ModelError: for a start or goal outside the grid, a negative weight, lanes of
            another shape or ``against`` below 1; for landmarks of another grid shape,
            another ``lethal`` or a larger cost weight, and for a cell of ``cost`` the
            search reads that is enterable and below the landmarks' layer.
    """
    if not (math.isfinite(cost_weight) and cost_weight >= 0):
        raise ModelError("cost_weight", cost_weight, "a finite weight >= 0")
    if not (math.isfinite(against) and against >= 1):
        raise ModelError("against", against, "a finite factor >= 1")
    if lanes is None:
        lane_grid = _NO_LANES
    else:
        lane_grid = readonly(np.ascontiguousarray(lanes, dtype=np.uint8))
        if lane_grid.shape != np.shape(cost):
            raise ModelError("lanes", lane_grid.shape, f"the cost grid's shape {np.shape(cost)}")
    grid = readonly(np.ascontiguousarray(cost, dtype=np.uint8))
    sx, sy = _check_cell("start_cell", start_cell, grid)
    gx, gy = _check_cell("goal_cell", goal_cell, grid)
    fields, scale, floor = _NO_FIELDS, 0.0, _NO_FLOOR
    if landmarks is not None:
        _check_landmarks(landmarks, grid, float(cost_weight), int(lethal))
    escape = int(escape_r2(grid, sx, sy, int(lethal)))
    if landmarks is not None and _escape_is_free(landmarks, sx, sy, escape):
        fields, scale, floor = landmarks.fields, landmarks.scale, landmarks.cost
    goal_blocked = grid[gy, gx] >= lethal and (gx - sx) ** 2 + (gy - sy) ** 2 > escape
    if escape < 0 or goal_blocked:
        # no way out, or a goal no path may enter: known without searching (a search
        # would close every reachable cell first: 10^6 on a 100 m x 100 m floor)
        return PlanResult(False, np.zeros((0, 2), dtype=np.int64), math.inf, math.inf, 0)
    found, cells, straight, diagonal, cost_cells, expansions, below = astar(
        grid,
        sx,
        sy,
        gx,
        gy,
        float(cost_weight),
        int(lethal),
        escape,
        DX,
        DY,
        lane_grid,
        float(against),
        fields,
        scale,
        floor,
    )
    if below >= 0:
        iy, ix = divmod(int(below), grid.shape[1])
        raise ModelError(
            "cost",
            f"{int(grid[iy, ix])} at cell {(ix, iy)}",
            f"at least the landmarks' static cost {int(floor[iy, ix])} there",
        )
    if not found:
        return PlanResult(False, cells, math.inf, math.inf, int(expansions))
    length = (int(straight) + int(diagonal) * SQRT2) * resolution_m
    return PlanResult(True, cells, length, float(cost_cells) * resolution_m, int(expansions))


def prune_path(
    cost: UInt8Array, cells: IntArray, *, lethal: int = INSCRIBED, keep_clearance: bool = True
) -> IntArray:
    """Reduce a grid path to its waypoints by line-of-sight shortcuts.

    From each waypoint the path is followed as far as the straight segment to the next
    cell stays clear; then waypoints in line with their neighbours are dropped. With
    ``keep_clearance`` a shortcut may touch no cell costlier than the costliest cell of
    the path section it replaces, so the pruned path keeps the planned distance from
    obstacles; without it, any cell below ``lethal`` will do. No shortcut crosses the
    escape section of a path that starts in blocked cells.

    Args:
        cost: the cost grid the path was planned on, ``[iy, ix]``.
        cells: (n, 2) path cells ``(ix, iy)``, consecutive cells 8-adjacent.
        lethal: blocking threshold the path was planned with.
        keep_clearance: whether shortcuts must keep the path's cost level.

    Returns:
        (k, 2) int64 waypoints, a subsequence of ``cells`` with the same first and last.
    """
    path = readonly(np.ascontiguousarray(cells, dtype=np.int64).reshape(-1, 2))
    if len(path) <= 2:
        return path.copy()
    grid = readonly(np.ascontiguousarray(cost, dtype=np.uint8))
    pruned: IntArray = prune(grid, path, int(lethal), bool(keep_clearance))
    return pruned


def path_to_world(static: StaticCostmap, cells: IntArray) -> FloatArray:
    """Cell centres of a path (n, 2) ``(ix, iy)`` as (n, 2) ``map`` points (m)."""
    c = np.asarray(cells, dtype=np.float64).reshape(-1, 2)
    origin = np.asarray(static.origin_xy_m, dtype=np.float64)
    points: FloatArray = origin + (c + 0.5) * static.resolution_m
    return points


class GoalStatus(StrEnum):
    """Where a goal lies on the static map; equal to the plain strings."""

    OK = "ok"
    OUTSIDE = "outside"
    IN_OBSTACLE = "in_obstacle"
    UNKNOWN = "unknown"


def goal_status(static: StaticCostmap, goal_xy: tuple[float, float] | FloatArray) -> GoalStatus:
    """Whether a goal can be planned to on the static map, before planning.

    Returns:
        ``outside`` off the grid; ``in_obstacle`` where the static cost is 253 or 254
        (a robot centred there touches a wall or shelf); ``unknown`` on an unknown cell
        (only on maps with unknown space); otherwise ``ok``. An ``ok`` goal can still be
        enclosed: :func:`reachable` or ``plan(...).found`` tells.
    """
    cell = static.world_to_cell(goal_xy)
    if not static.in_bounds(cell):
        return GoalStatus.OUTSIDE
    c = int(static.cost[cell[1], cell[0]])
    if c == NO_INFORMATION:
        return GoalStatus.UNKNOWN
    if c >= INSCRIBED:
        return GoalStatus.IN_OBSTACLE
    return GoalStatus.OK


def reachable(
    static: StaticCostmap,
    start_xy: tuple[float, float] | FloatArray,
    goal_xy: tuple[float, float] | FloatArray,
) -> bool:
    """Whether the static map has a path from a start to a goal (``map``, m).

    False for a goal that is not :attr:`GoalStatus.OK` or a start off the grid.
    """
    start = static.world_to_cell(start_xy)
    if goal_status(static, goal_xy) != GoalStatus.OK or not static.in_bounds(start):
        return False
    return plan(static.cost, start, static.world_to_cell(goal_xy), cost_weight=0.0).found


def shortest_path_length_m(
    static: StaticCostmap,
    start_xy: tuple[float, float] | FloatArray,
    goal_xy: tuple[float, float] | FloatArray,
    *,
    landmarks: Landmarks | None = None,
) -> float:
    """Length (m) of a shortest collision-free path for the robot centre on the static map.

    A* with ``cost_weight=0`` on the static costs (inscribed cells blocked), pruned by
    line of sight without the clearance rule, measured from ``start_xy`` through the
    inner waypoints (cell centres) to ``goal_xy``. Pruning removes most of the up to
    8 % excess of 8-connected grid paths over straight lines, so a robot that drives
    the shortest route gets a path-length ratio close to 1. ``inf`` when no path exists
    or either point is off the grid. ``landmarks`` of ``static.cost`` built for cost
    weight 0 shorten the search (:func:`plan`).
    """
    start = static.world_to_cell(start_xy)
    goal = static.world_to_cell(goal_xy)
    if not (static.in_bounds(start) and static.in_bounds(goal)):
        return math.inf
    result = plan(static.cost, start, goal, cost_weight=0.0, landmarks=landmarks)
    if not result.found:
        return math.inf
    inner = path_to_world(static, prune_path(static.cost, result.cells, keep_clearance=False))
    points = np.vstack(
        [np.asarray(start_xy, dtype=float)[:2], inner[1:-1], np.asarray(goal_xy, dtype=float)[:2]]
    )
    return float(np.hypot(*np.diff(points, axis=0).T).sum())


__all__ = [
    "GoalStatus",
    "PlanResult",
    "goal_status",
    "path_to_world",
    "plan",
    "prune_path",
    "reachable",
    "shortest_path_length_m",
]
