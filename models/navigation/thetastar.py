"""Theta*: any-angle paths on a cost grid, and the binary heap the grid searches share.

Nash, Daniel, Koenig and Felner, "Theta*: Any-Angle Path Planning on Grids", AAAI 2007;
here in its lazy form, Nash, Koenig and Tovey, "Lazy Theta*: Any-Angle Path Planning and
Path Length Analysis in 3D", AAAI 2010. Theta* is A* on the 8-connected grid whose cells
may take their parent's parent when it sees them (the segment between the cell centres
crosses no blocked cell), so paths bend only round obstacles and need no pruning. Lazy
Theta* assumes the sight when it reaches a cell and walks the segment once, when it
expands the cell; without it, the cell takes its best expanded neighbour as its parent
(and, dearer than assumed, waits in line again). As in Nav2's Theta* planner the line
of sight is cost-aware: it refuses cells at or above ``lethal`` (253: inscribed, lethal
and, with the default threshold, unknown cells) and charges the cells it crosses.

Cost model (A*'s of :mod:`models.navigation.planner` along segments): a segment costs the
integral along it of ``1 + w * c / 252`` over the cells it passes (``c`` their Nav2
costs), ``against`` times more in a cell whose one-way lane (:mod:`models.navigation.lanes`)
it runs against, in cells; a straight way costs the same cut in pieces or not. With cell
costs the triangle inequality fails, so a cell takes the cheaper of the step from the
expanded cell and the segment from its parent (Basic Theta* takes any visible segment).
The heuristic is the Euclidean distance, which no cost factor undercuts. Theta* is not
optimal: its paths may be a few percent longer than the shortest any-angle path (Nash et
al.), while shorter than 8-connected grid paths.

The start may lie in blocked cells: the escape rule of :mod:`models.navigation.planner`
applies (blocked cells within the escape disc count as cost 252, on steps and segments).
Cells are ``(ix, iy)``, grids ``[iy, ix]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numba
import numpy as np

from models.arrays import FloatArray, IntArray, UInt8Array
from models.errors import ModelError
from models.navigation.costmap import INSCRIBED, MAX_NON_OBSTACLE, StaticCostmap
from models.navigation.gridsearch import _F_STEPS, DX, DY, SQRT2, _escapes, escape_r2, readonly
from models.navigation.planner import _check_cell
from models.navigation.repair import Repair, RepairParams, repair_path

NO_LANES = readonly(np.zeros((0, 0), dtype=np.uint8))
"""An empty lane grid: no one-way lanes."""
_TIE = 1.0 + 1e-12
"""Costs within this factor count as equal."""


class Terrain(NamedTuple):
    """How a search counts the cells of a cost grid (the kernels' argument).

    Attributes:
        cost: (rows, cols) uint8 Nav2 costs, ``[iy, ix]``.
        lanes: (rows, cols) one-way directions, or :data:`NO_LANES`.
        scale: cost weight over 252: a cell of cost ``c`` costs ``1 + scale * c`` per cell.
        lethal: cells at or above this cost are blocked ...
        r2: ... unless within this squared distance (cells^2) of the start cell
            ``(ex, ey)`` (the escape disc, -1: none); there they cost 252.
        ex: the start cell's x.
        ey: the start cell's y.
        against: a move against a cell's lane costs this many times more there.
    """

    cost: UInt8Array
    lanes: UInt8Array
    scale: float
    lethal: int
    r2: int
    ex: int
    ey: int
    against: float


@dataclass(frozen=True, eq=False)
class ThetaResult:
    """The outcome of one Theta* search.

    Attributes:
        found: whether a path exists.
        cells: (k, 2) int64 corner cells ``(ix, iy)`` from start to goal; (0, 2) if not found.
        length_m: length of the polyline through the cell centres (m); ``inf`` if not found.
        cost_m: the search's objective, length weighted by cell costs (m).
        expansions: number of cells expanded (closed).
    """

    found: bool
    cells: IntArray
    length_m: float
    cost_m: float
    expansions: int


# -- the binary heap ------------------------------------------------------------------------
def _heap_push_py(
    keys: FloatArray, items: IntArray, size: int, f: float, g: float, item: int
) -> tuple[FloatArray, IntArray, int]:
    """Push ``item`` with key ``f`` (ties: larger ``g`` first); the arrays double when full.

    Entry ``i`` is ``keys[2i] = f``, ``keys[2i + 1] = g``, ``items[i]``. Returns the arrays
    (new ones after growing) and the new size.
    """
    if size == items.shape[0]:
        grown_k = np.empty(4 * size)
        grown_k[: 2 * size] = keys[: 2 * size]
        grown_i = np.empty(2 * size, dtype=np.int64)
        grown_i[:size] = items[:size]
        keys, items = grown_k, grown_i
    i = size
    while i > 0:
        p = (i - 1) // 2
        if f < keys[2 * p] or (f == keys[2 * p] and g > keys[2 * p + 1]):
            keys[2 * i] = keys[2 * p]
            keys[2 * i + 1] = keys[2 * p + 1]
            items[i] = items[p]
            i = p
        else:
            break
    keys[2 * i] = f
    keys[2 * i + 1] = g
    items[i] = item
    return keys, items, size + 1


def _heap_pop_py(keys: FloatArray, items: IntArray, size: int) -> tuple[float, float, int, int]:
    """Remove the least entry of a non-empty heap: its ``f``, ``g``, item and the new size."""
    f, g, item = keys[0], keys[1], items[0]
    size -= 1
    if size > 0:
        lf, lg, li = keys[2 * size], keys[2 * size + 1], items[size]
        i = 0
        while True:
            c = 2 * i + 1
            if c >= size:
                break
            if c + 1 < size:
                f1, f2 = keys[2 * c], keys[2 * c + 2]
                if f2 < f1 or (f2 == f1 and keys[2 * c + 3] > keys[2 * c + 1]):
                    c += 1
            fc = keys[2 * c]
            if fc < lf or (fc == lf and keys[2 * c + 1] > lg):
                keys[2 * i] = fc
                keys[2 * i + 1] = keys[2 * c + 1]
                items[i] = items[c]
                i = c
            else:
                break
        keys[2 * i] = lf
        keys[2 * i + 1] = lg
        items[i] = li
    return f, g, item, size


# -- line of sight and the search -----------------------------------------------------------
def _against_py(lane: int, sx: int, sy: int) -> bool:
    """Whether a move with signs ``(sx, sy)`` runs against a cell's lane direction."""
    return (
        (lane == 1 and sx < 0)
        or (lane == 2 and sx > 0)
        or (lane == 3 and sy < 0)
        or (lane == 4 and sy > 0)
    )


def _factor_py(t: Terrain, x: int, y: int, mx: int, my: int) -> float:
    """Cost per cell of length in cell ``(x, y)`` moving by signs ``(mx, my)``; -1 if blocked."""
    c = int(t.cost[y, x])
    if c >= t.lethal:
        if not _escapes(x, y, t.ex, t.ey, t.r2):
            return -1.0
        c = MAX_NON_OBSTACLE
    factor = 1.0 + t.scale * c
    if t.lanes.shape[0] > 0 and _against(int(t.lanes[y, x]), mx, my):
        factor *= t.against
    return factor


def _step_py(t: Terrain, x: int, y: int, mx: int, my: int) -> float:
    """:func:`_segment_py` of the step from cell ``(x, y)`` by ``(mx, my)`` (on the grid)."""
    here: float = _factor(t, x, y, mx, my)
    there: float = _factor(t, x + mx, y + my, mx, my)
    if here < 0.0 or there < 0.0:
        return -1.0
    if mx == 0 or my == 0:
        return 0.5 * (here + there)
    if _factor(t, x + mx, y, mx, my) < 0.0 or _factor(t, x, y + my, mx, my) < 0.0:
        return -1.0  # no corner cutting
    return SQRT2 * 0.5 * (here + there)


def _segment_py(t: Terrain, ax: int, ay: int, bx: int, by: int, budget: float) -> float:
    """Cost (cells) of the segment between two cell centres; -1 if blocked or over ``budget``.

    The walk is exact in integers: the segment crosses an x boundary after
    ``(0.5 + i) / |dx|`` of its length and a y boundary after ``(0.5 + j) / |dy|``; through
    a corner exactly, both cells beside it must be enterable too (as A*'s diagonal steps).
    Factors are at least 1, so the walk stops once what it summed plus the length left
    passes the budget.
    """
    ddx, ddy = abs(bx - ax), abs(by - ay)
    stx, sty = (1 if bx > ax else -1), (1 if by > ay else -1)
    mx, my = (0 if ddx == 0 else stx), (0 if ddy == 0 else sty)
    half_x, half_y = (0.5 / ddx if ddx > 0 else 0.0), (0.5 / ddy if ddy > 0 else 0.0)
    length = math.sqrt(float(ddx * ddx + ddy * ddy))
    rest = budget / length if length > 0.0 else np.inf  # in lengths of the segment
    x, y, i, j = ax, ay, 0, 0
    factor: float = _factor(t, x, y, mx, my)
    total = before = 0.0
    while (i < ddx or j < ddy) and factor >= 0.0:
        tx, ty = (1 + 2 * i) * ddy, (1 + 2 * j) * ddx
        at = (1 + 2 * i) * half_x if tx <= ty else (1 + 2 * j) * half_y
        if tx == ty and (
            _factor(t, x + stx, y, mx, my) < 0.0 or _factor(t, x, y + sty, mx, my) < 0.0
        ):
            return -1.0
        if tx <= ty:
            x, i = x + stx, i + 1
        if ty <= tx:
            y, j = y + sty, j + 1
        total += factor * (at - before)
        before = at
        if total + 1.0 - before > rest:
            return -1.0
        factor = _factor(t, x, y, mx, my)
    if factor < 0.0:
        return -1.0
    total += factor * (1.0 - before)
    return -1.0 if total > rest else length * total


def _rounded_py(f: float) -> float:
    """``f`` (cells) rounded to a multiple of 2^-28 as in A* (:mod:`~.gridsearch`)."""
    return math.floor(f * _F_STEPS + 0.5) / _F_STEPS


def _theta_py(t: Terrain, gx: int, gy: int) -> tuple[bool, IntArray, float, int]:
    """Lazy Theta* from the start ``(t.ex, t.ey)`` to ``(gx, gy)``, heap ordered by ``(f, -g)``.

    Per cell: ``state`` 0 new, 1 open, 2 closed; ``g``, ``parent`` (flat index), ``lazy``
    (the segment from the parent not walked yet) and ``back`` (the cheapest step in from an
    expanded cell, ``back_by``) valid where open or closed. A cell whose ``g`` changes is
    pushed again; the entry it leaves behind is skipped when popped. ``f`` is rounded as in
    A* (:mod:`models.navigation.gridsearch`), so equal sums in another order tie and the
    ``-g`` rule orders them.

    Returns found, the corner cells (k, 2), the path's cost (cells) and the expansions.
    """
    height, width = t.cost.shape
    n = width * height
    state = np.zeros(n, dtype=np.uint8)
    g, parent, lazy = np.empty(n), np.empty(n, dtype=np.int64), np.empty(n, dtype=np.bool_)
    back, back_by = np.empty(n), np.empty(n, dtype=np.int64)  # the best step in, and whence
    keys, items = np.empty(2048), np.empty(1024, dtype=np.int64)
    start, goal = t.ey * width + t.ex, gy * width + gx
    g[start], parent[start], lazy[start], state[start] = 0.0, start, False, 1
    keys, items, size = heap_push(keys, items, 0, math.hypot(gx - t.ex, gy - t.ey), 0.0, start)
    expansions = 0
    while size > 0:
        _, node_g, node, size = heap_pop(keys, items, size)
        if state[node] == 2 or node_g > g[node]:
            continue  # left behind by a later push
        y, x = divmod(node, width)
        if lazy[node]:  # walk the segment from the parent now; else the best closed step
            alt, via = back[node], back_by[node]
            p = parent[node]
            py, px = divmod(p, width)
            seen = _segment(t, px, py, x, y, alt * _TIE - g[p])
            lazy[node] = False
            if seen < 0.0:
                parent[node] = via
            g[node] = g[p] + seen if seen >= 0.0 else alt
            if g[node] > node_g * _TIE:  # dearer than assumed: back in line at its cost
                f = _rounded(g[node] + math.hypot(x - gx, y - gy))
                keys, items, size = heap_push(keys, items, size, f, g[node], node)
                continue
        state[node] = 2
        expansions += 1
        if node == goal:
            break
        p = parent[node]
        py, px = divmod(p, width)
        fp = _factor(t, px, py, 0, 0)
        for k in range(8):
            nx, ny = x + DX[k], y + DY[k]
            nb = ny * width + nx
            if nx < 0 or ny < 0 or nx >= width or ny >= height or state[nb] == 2:
                continue
            step = _step(t, x, y, DX[k], DY[k])
            if step < 0.0:
                continue  # blocked, or a diagonal cutting a blocked corner
            best, via, walk = g[node] + step, node, False
            if state[nb] == 0 or best < back[nb]:
                back[nb], back_by[nb] = best, node
            ax, ay = x - px, y - py
            if p != node and ax * DY[k] == ay * DX[k] and ax * DX[k] + ay * DY[k] > 0:
                via = p  # straight on from the parent through this cell: seen, as dear
            elif p != node:
                # the segment from the parent, its cost guessed from its ends' (exact on
                # uniform costs), walked when the cell is expanded
                reach = math.hypot(nx - px, ny - py) * 0.5 * (fp + _factor(t, nx, ny, 0, 0))
                if g[p] + reach <= best * _TIE:
                    best, via, walk = min(best, g[p] + reach), p, True
            if state[nb] == 1 and best >= g[nb]:
                continue
            g[nb], parent[nb], lazy[nb], state[nb] = best, via, walk, 1
            f = _rounded(best + math.hypot(nx - gx, ny - gy))
            keys, items, size = heap_push(keys, items, size, f, best, nb)
    if state[goal] != 2:
        return False, np.zeros((0, 2), dtype=np.int64), np.inf, expansions
    chain = [goal]
    while chain[-1] != start:
        chain.append(parent[chain[-1]])
    path = np.empty((len(chain), 2), dtype=np.int64)
    for i, cell in enumerate(chain[::-1]):
        path[i, 1], path[i, 0] = divmod(cell, width)
    return True, path, g[goal], expansions


# numba resolves the helpers when a kernel is first compiled, so their order is free
_against: Any = numba.njit(cache=True, nogil=True, inline="always")(_against_py)
_factor: Any = numba.njit(cache=True, nogil=True, inline="always")(_factor_py)
_rounded: Any = numba.njit(cache=True, nogil=True, inline="always")(_rounded_py)
_step: Any = numba.njit(cache=True, nogil=True, inline="always")(_step_py)
_segment: Any = numba.njit(cache=True, nogil=True)(_segment_py)
_theta: Any = numba.njit(cache=True, nogil=True)(_theta_py)
heap_push: Any = numba.njit(cache=True, nogil=True)(_heap_push_py)
"""Compiled :func:`_heap_push_py`: a binary heap of ``(f, g, item)`` for grid searches."""
heap_pop: Any = numba.njit(cache=True, nogil=True)(_heap_pop_py)
"""Compiled :func:`_heap_pop_py`."""


def theta_star(
    cost: UInt8Array,
    start_cell: tuple[int, int],
    goal_cell: tuple[int, int],
    *,
    cost_weight: float = 1.0,
    lethal: int = INSCRIBED,
    resolution_m: float = 1.0,
    lanes: UInt8Array | None = None,
    against: float = 1.0,
) -> ThetaResult:
    """An any-angle path between two cells of a cost grid (Theta*).

    Args:
        cost: (rows, cols) uint8 Nav2 costs, ``[iy, ix]``; unknown cells (255) are
            blocked with the default ``lethal``.
        start_cell: ``(ix, iy)`` start; may be blocked (the planner's escape rule).
        goal_cell: ``(ix, iy)`` goal; a blocked goal outside the escape disc is not found.
        cost_weight: a segment costs the integral along it of ``1 + cost_weight * c / 252``
            (cells); 0 gives the geometric any-angle path.
        lethal: cells with a cost at or above this are never entered nor seen through.
        resolution_m: cell edge length (m) for ``length_m`` and ``cost_m``.
        lanes: optional (rows, cols) one-way directions, same shape as ``cost``.
        against: a cell passed against its lane costs this many times more (>= 1).

    Raises:
        ModelError: for a start or goal outside the grid, a negative or non-finite weight,
            lanes of another shape, or ``against`` below 1.
    """
    if not (math.isfinite(cost_weight) and cost_weight >= 0):
        raise ModelError("cost_weight", cost_weight, "a finite weight >= 0")
    if not (math.isfinite(against) and against >= 1):
        raise ModelError("against", against, "a finite factor >= 1")
    grid = readonly(np.ascontiguousarray(cost, dtype=np.uint8))
    lane_grid = lane_array(lanes, grid)
    sx, sy = _check_cell("start_cell", start_cell, grid)
    gx, gy = _check_cell("goal_cell", goal_cell, grid)
    r2 = int(escape_r2(grid, sx, sy, int(lethal)))
    if r2 < 0 or (grid[gy, gx] >= lethal and (gx - sx) ** 2 + (gy - sy) ** 2 > r2):
        # no way out, or a goal nothing may enter: known without searching
        return ThetaResult(False, np.zeros((0, 2), dtype=np.int64), math.inf, math.inf, 0)
    scale = cost_weight / MAX_NON_OBSTACLE
    terrain = Terrain(grid, lane_grid, scale, int(lethal), r2, sx, sy, float(against))
    found, cells, cost_cells, expansions = _theta(terrain, gx, gy)
    if not found:
        return ThetaResult(False, cells, math.inf, math.inf, int(expansions))
    steps = np.diff(cells, axis=0).astype(np.float64)
    length = float(np.hypot(steps[:, 0], steps[:, 1]).sum()) * resolution_m
    return ThetaResult(True, cells, length, float(cost_cells) * resolution_m, int(expansions))


def lane_array(lanes: UInt8Array | None, grid: UInt8Array) -> UInt8Array:
    """Lanes as the kernels read them: read-only uint8, or :data:`NO_LANES` for None.

    Raises:
        ModelError: for lanes of another shape than ``grid``.
    """
    if lanes is None:
        return NO_LANES
    lane_grid = readonly(np.ascontiguousarray(lanes, dtype=np.uint8))
    if lane_grid.shape != grid.shape:
        raise ModelError("lanes", lane_grid.shape, f"the cost grid's shape {grid.shape}")
    return lane_grid


def repair_theta(
    static: StaticCostmap,
    points_xy: FloatArray,
    discs: FloatArray | None,
    waypoints: FloatArray,
    segment: int,
    start_xy: FloatArray,
    params: RepairParams,
    *,
    cost_weight: float = 1.0,
    lanes: UInt8Array | None = None,
    against: float = 1.0,
) -> Repair | None:
    """The stretch of a path ahead of the robot planned again by Theta*, in a window.

    A*'s repair (:func:`models.navigation.repair.repair_path`, same arguments: the stretch,
    the window round it and the splice with the rest of the path) with :func:`theta_star`
    as the search in the window. None when no path inside the window reaches the cut point
    (the caller then plans in full).
    """

    def search(
        cost: UInt8Array,
        start: tuple[int, int],
        goal: tuple[int, int],
        resolution_m: float,
        window_lanes: UInt8Array | None,
        against_: float,
    ) -> IntArray | None:
        result = theta_star(
            cost,
            start,
            goal,
            cost_weight=cost_weight,
            resolution_m=resolution_m,
            lanes=window_lanes,
            against=against_,
        )
        return result.cells if result.found else None

    return repair_path(
        static,
        points_xy,
        discs,
        waypoints,
        segment,
        start_xy,
        params,
        lanes=lanes,
        against=against,
        search=search,
    )


__all__ = [
    "NO_LANES",
    "Terrain",
    "ThetaResult",
    "heap_pop",
    "heap_push",
    "lane_array",
    "repair_theta",
    "theta_star",
]
