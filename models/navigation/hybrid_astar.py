"""Hybrid-A*: kinematically feasible paths of a robot with a minimum turning radius.

Dolgov, Thrun, Montemerlo and Diebel, "Path Planning for Autonomous Vehicles in Unknown
Semi-structured Environments", IJRR 29(5), 2010; the layout follows Nav2's Smac Hybrid-A*.
States ``(x, y, heading)`` have continuous positions and are closed by bins: squares of
``cell_m`` times ``heading_bins`` headings. A state expands by motion primitives: a
straight ``sqrt(2) * cell_m`` long (it always leaves its bin), arcs of the minimum turning
radius left and right turning by the least whole number of heading bins that makes them
as long, and for a differential drive turns on the spot by that angle at a cost of their
own; headings stay on the bins' centres. A primitive is swept every half cell: the
robot's disc is clear where the cell under its centre costs less than 253 (the costmap is
inflated by the footprint), and a step costs its length times ``1 + w * c / 252`` of the
cell it ends in, times ``arc_penalty`` on arcs (Nav2's non-straight penalty) and
``against`` against a one-way lane.

The heuristic is the larger of the Euclidean distance (the non-holonomic distance without
obstacles is at least that) and a 2-D Dijkstra cost-to-go from the goal with obstacles,
computed once per plan on blocks of the bins' size each as cheap as its cheapest cell
(Nav2 downsamples its obstacle heuristic likewise;
:func:`models.navigation.landmarks._dijkstra_py`). On the 8-connected grid it may exceed
the Euclidean cost-to-go by 8 %: the search is slightly greedy, as Nav2's. Shots at the
goal (the goal's heading is free) are tried every few expansions, more often nearer the
goal (analytic expansion): an arc of the minimum radius until facing the goal, then
straight, or a turn on the spot, then straight. A free shot ends the search once it
costs at most ``_SHOT_SLACK`` times the least ``f`` still open.

The request gives no start heading: the search leaves the start at every heading (a
differential-drive robot turns towards its path first) and first tries the straight to the
goal. The start may lie in blocked cells: the escape rule of
:mod:`models.navigation.planner` applies.
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass
from typing import Any, NamedTuple

import numba
import numpy as np

from models.arrays import FloatArray, IntArray, UInt8Array
from models.errors import ModelError
from models.navigation.costmap import INSCRIBED, MAX_NON_OBSTACLE
from models.navigation.gridsearch import DX, DY, SQRT2, escape_r2, readonly
from models.navigation.landmarks import _dijkstra
from models.navigation.thetastar import Terrain, _factor, heap_pop, heap_push, lane_array

_SAMPLE_CELLS = 0.5
"""Primitives and analytic expansions are swept at most this far apart (cells)."""
_SHOT_SLACK = 1.25
"""A shot at the goal ends the search when its path costs at most this many times the
least ``f`` left (a shot against a lane or along walls waits for better ways)."""


@dataclass(frozen=True)
class HybridParams:
    """The search's lattice and costs.

    Attributes:
        turning_radius_m: radius of the arcs (m), > 0.
        cell_m: edge of the states' position bins (m), > 0.
        heading_bins: number of heading bins, 4 .. 720.
        turn_in_place: whether turning on the spot is a primitive.
        rotate_cost_m: cost of one turn on the spot by an arc's angle, as a distance (m).
        arc_penalty: an arc costs this many times its length, >= 1.
        cost_weight: weight of the cell costs, >= 0.
        max_expansions: states expanded at most before giving up, > 0.
        analytic_expansion: whether to try shots at the goal.
    """

    turning_radius_m: float = 0.4
    cell_m: float = 0.2
    heading_bins: int = 72
    turn_in_place: bool = True
    rotate_cost_m: float = 0.3
    arc_penalty: float = 1.2
    cost_weight: float = 1.0
    max_expansions: int = 100_000
    analytic_expansion: bool = True

    def __post_init__(self) -> None:
        for name, least, strict in [
            ("turning_radius_m", 0, True), ("cell_m", 0, True), ("rotate_cost_m", 0, False),
            ("arc_penalty", 1, False), ("cost_weight", 0, False), ("max_expansions", 0, True),
        ]:  # fmt: skip
            value = getattr(self, name)
            if not (math.isfinite(value) and (value > least if strict else value >= least)):
                raise ModelError(name, value, f"a finite number {'>' if strict else '>='} {least}")
        if not 4 <= self.heading_bins <= 720:
            raise ModelError("heading_bins", self.heading_bins, "a count from 4 to 720")


class Primitives(NamedTuple):
    """The motion primitives from each heading bin, in cells.

    Attributes:
        dx: (B, P, S) x offsets of each primitive's samples from its start; the last
            sample of primitive ``m`` (index ``samples[m] - 1``) is where it ends.
        dy: (B, P, S) y offsets.
        samples: (P,) samples per primitive (0 for a turn on the spot).
        turn: (P,) heading bins each primitive turns by (+ left).
        factor: (P,) cost factor of each primitive (``arc_penalty`` for arcs, else 1).
        rotate: cost of a turn on the spot (cells).
        step: length of the straight primitive (cells).
        arc_bins: heading bins an arc turns by.
        radius: the arcs' radius (cells).
    """

    dx: FloatArray
    dy: FloatArray
    samples: IntArray
    turn: IntArray
    factor: FloatArray
    rotate: float
    step: float
    arc_bins: int
    radius: float


@functools.lru_cache(maxsize=16)
def primitives(params: HybridParams, resolution_m: float) -> Primitives:
    """The primitives of ``params`` on a grid of cells ``resolution_m`` wide (read-only)."""
    bins = params.heading_bins
    delta = 2.0 * math.pi / bins
    radius = params.turning_radius_m / resolution_m
    step = SQRT2 * params.cell_m / resolution_m
    arc_bins = max(1, math.ceil(step / (radius * delta) - 1e-9))
    arc = radius * arc_bins * delta
    turns = [0, arc_bins, -arc_bins] + ([arc_bins, -arc_bins] if params.turn_in_place else [])
    lengths = [step, arc, arc] + ([0.0, 0.0] if params.turn_in_place else [])
    count = np.array([math.ceil(ln / _SAMPLE_CELLS) for ln in lengths], dtype=np.int64)
    dx = np.zeros((bins, len(turns), max(1, int(count.max()))))
    dy = np.zeros_like(dx)
    for h, m in itertools.product(range(bins), range(3)):
        theta = h * delta
        for j in range(count[m]):
            f = (j + 1) / count[m]
            if m == 0:
                dx[h, m, j], dy[h, m, j] = f * step * math.cos(theta), f * step * math.sin(theta)
            else:
                dx[h, m, j], dy[h, m, j] = _on_arc_py(0.0, 0.0, theta, f * turns[m] * delta, radius)
    factor = np.array([1.0] + [params.arc_penalty] * 2 + [1.0] * (len(turns) - 3))
    turn = np.array(turns, dtype=np.int64)
    made = Primitives(
        readonly(dx), readonly(dy), readonly(count), readonly(turn), readonly(factor),
        params.rotate_cost_m / resolution_m, step, arc_bins, radius,
    )  # fmt: skip
    return made


@dataclass(frozen=True, eq=False)
class HybridResult:
    """The outcome of one Hybrid-A* search.

    Attributes:
        found: whether a path was found within the expansions allowed.
        waypoints: (k, 2) the path in ``map`` (m) from the start to the goal itself, its
            arcs as their primitives' end points, straight runs merged; (0, 2) if not found.
        length_m: its length (m); ``inf`` if not found.
        cost_m: the search's objective (m); ``inf`` if not found.
        expansions: number of states expanded.
    """

    found: bool
    waypoints: FloatArray
    length_m: float
    cost_m: float
    expansions: int


# -- kernels --------------------------------------------------------------------------------
def _sweep_py(t: Terrain, x0: float, y0: float, dx: FloatArray, dy: FloatArray, n: int) -> float:
    """Cost (cells) of driving from ``(x0, y0)`` through ``(x0 + dx[j], y0 + dy[j])``, j < n.

    -1 when a sample lies off the grid or on a blocked cell. Each step costs its length
    times the factor of the cell it ends in (:class:`~.thetastar.Terrain`).
    """
    height, width = t.cost.shape
    total = 0.0
    px, py = x0, y0
    for j in range(n):
        x, y = x0 + dx[j], y0 + dy[j]
        ix, iy = math.floor(x), math.floor(y)
        if ix < 0 or iy < 0 or ix >= width or iy >= height:
            return -1.0
        sx, sy = x - px, y - py
        factor = _factor(t, ix, iy, (sx > 1e-9) - (sx < -1e-9), (sy > 1e-9) - (sy < -1e-9))
        if factor < 0.0:
            return -1.0
        total += math.sqrt(sx * sx + sy * sy) * factor
        px, py = x, y
    return total


def _straight_py(t: Terrain, x: float, y: float, gx: float, gy: float) -> float:
    """:func:`_sweep_py` along the straight from ``(x, y)`` to ``(gx, gy)``."""
    n = max(1, math.ceil(math.hypot(gx - x, gy - y) / _SAMPLE_CELLS))
    f = np.arange(1, n + 1) / n
    cost: float = _sweep(t, x, y, f * (gx - x), f * (gy - y), n)
    return cost


def _lower_py(h2d: FloatArray, k: int, x: float, y: float, gx: float, gy: float) -> float:
    """The heuristic at ``(x, y)``: the larger of the distance to ``(gx, gy)`` and ``h2d``'s.

    ``h2d``: the 2-D cost-to-go of blocks of ``k`` x ``k`` cells (cells).
    """
    cost_to_go: float = k * h2d[math.floor(y) // k, math.floor(x) // k]
    return max(cost_to_go, math.hypot(gx - x, gy - y))


def _shot_py(
    t: Terrain, x: float, y: float, theta: float, goal: FloatArray, p: Primitives
) -> tuple[float, float]:
    """The cheapest free shot at the goal from a state: its cost (cells; -1: none) and turn.

    The turn is the arc's signed angle (rad, + left) of an arc-then-straight shot, NaN for
    a turn on the spot (if allowed) then straight.
    """
    gx, gy, radius = goal[0], goal[1], p.radius
    c, s = math.cos(theta), math.sin(theta)
    lx, ly = c * (gx - x) + s * (gy - y), -s * (gx - x) + c * (gy - y)
    best, turn = -1.0, 0.0
    side = 1.0 if ly >= 0 else -1.0
    ux, uy = lx, side * ly - radius  # the goal from the turning circle's centre
    dc = math.hypot(ux, uy)
    if dc > radius:
        alpha = (math.atan2(uy, ux) + math.asin(radius / dc)) % (2.0 * math.pi)
        na = math.ceil(radius * alpha / _SAMPLE_CELLS)
        phi = alpha * np.arange(1, na + 1) / na
        ax, ay = radius * np.sin(phi), side * radius * (1.0 - np.cos(phi))
        dx, dy = c * ax - s * ay, s * ax + c * ay
        arc = _sweep(t, x, y, dx, dy, na)
        if arc >= 0.0:
            line = _straight(t, x + dx[na - 1], y + dy[na - 1], gx, gy)
            if line >= 0.0:
                best, turn = arc * p.factor[1] + line, side * alpha
    if p.samples.shape[0] > 3:
        rotate = abs(math.atan2(ly, lx)) * p.rotate / (p.arc_bins * 2.0 * math.pi / p.dx.shape[0])
        if best < 0.0 or rotate + math.hypot(lx, ly) < best:
            line = _straight(t, x, y, gx, gy)
            if line >= 0.0 and (best < 0.0 or rotate + line < best):
                best, turn = rotate + line, np.nan
    return best, turn


def _hybrid_py(
    t: Terrain,
    start: FloatArray,
    goal: FloatArray,
    h2d: FloatArray,
    k: int,
    p: Primitives,
    bin_cells: float,
    max_expansions: int,
    analytic: bool,
) -> tuple[bool, FloatArray, float, int]:
    """Hybrid-A* in cells: found, the path's points (m, 2) in cells, its cost, expansions.

    States are flat indices ``(bin_y * bins_x + bin_x) * B + heading``; per state
    ``state`` (0 new, 1 open, 2 closed), ``g``, the continuous position ``px, py`` and
    ``parent`` (-1 at the start) are valid where open or closed. ``h2d``: the 2-D
    cost-to-go (cells / ``k``) of blocks of ``k`` x ``k`` cells.
    """
    height, width = t.cost.shape
    bins = p.dx.shape[0]
    delta = 2.0 * math.pi / bins
    bins_x = math.ceil(width / bin_cells)
    total = bins_x * math.ceil(height / bin_cells) * bins
    state = np.zeros(total, dtype=np.uint8)
    g, px, py = np.empty(total), np.empty(total), np.empty(total)
    parent = np.empty(total, dtype=np.int64)
    keys, items, size = np.empty(2048), np.empty(1024, dtype=np.int64), 0
    x, y, gx, gy = start[0], start[1], goal[0], goal[1]
    h0 = _lower(h2d, k, x, y, gx, gy)
    first = (math.floor(y / bin_cells) * bins_x + math.floor(x / bin_cells)) * bins
    for h in range(bins if h0 < np.inf else 0):  # no start heading: turn on the spot first
        g[first + h], px[first + h], py[first + h] = 0.0, x, y
        parent[first + h], state[first + h] = -1, 1
        keys, items, size = heap_push(keys, items, size, h0, 0.0, first + h)
    expansions, next_shot = 0, 0
    end, shot_cost, shot_turn, best = -1, 0.0, np.nan, np.inf  # the cheapest shot so far
    line = _straight(t, x, y, gx, gy) if h0 < np.inf else -1.0
    if line >= 0.0:  # the heading at the start is free: straight there, if clear
        end, shot_cost, best = first, line, line
    while size > 0:
        f, gs, s, size = heap_pop(keys, items, size)
        if state[s] == 2 or gs > g[s]:
            continue
        if best <= _SHOT_SLACK * f:
            break  # nothing left promises much better than the shot in hand
        state[s] = 2
        expansions += 1
        x, y, h = px[s], py[s], s % bins
        d = math.hypot(gx - x, gy - y)
        if d <= bin_cells or (analytic and expansions >= next_shot):
            cost, turn = _shot(t, x, y, h * delta, goal, p)
            if cost < 0.0 and d <= bin_cells:  # a last step under a bin: any heading
                cost, turn = _straight(t, x, y, gx, gy), np.nan
            if cost >= 0.0 and g[s] + cost < best:
                end, shot_cost, shot_turn, best = s, cost, turn, g[s] + cost
                if best <= _SHOT_SLACK * f:
                    break
            next_shot = expansions + max(1, int(d / p.step))  # more often nearer the goal
        if expansions >= max_expansions:
            break
        for m in range(p.samples.shape[0]):
            n = p.samples[m]
            nx, ny, c = x, y, p.rotate
            if n > 0:
                c = _sweep(t, x, y, p.dx[h, m], p.dy[h, m], n) * p.factor[m]
                if c < 0.0:
                    continue
                nx, ny = x + p.dx[h, m, n - 1], y + p.dy[h, m, n - 1]
            nh = (h + p.turn[m]) % bins
            ns = (math.floor(ny / bin_cells) * bins_x + math.floor(nx / bin_cells)) * bins + nh
            ng = g[s] + c
            if state[ns] == 2 or (state[ns] == 1 and ng >= g[ns]):
                continue
            hh = _lower(h2d, k, nx, ny, gx, gy)
            if hh == np.inf:
                continue
            g[ns], px[ns], py[ns], parent[ns], state[ns] = ng, nx, ny, s, 1
            keys, items, size = heap_push(keys, items, size, ng + hh, ng, ns)
    if end < 0:
        return False, np.zeros((0, 2)), np.inf, expansions
    chain = [end]
    while parent[chain[-1]] >= 0:
        chain.append(parent[chain[-1]])
    arcs = 0 if math.isnan(shot_turn) else math.ceil(2 * abs(shot_turn) / (p.arc_bins * delta))
    path = np.empty((2 * len(chain) + arcs, 2))
    path[0] = start
    k = 1
    for i in range(len(chain) - 2, -1, -1):
        a, b = chain[i + 1], chain[i]
        theta = (a % bins) * delta
        side = math.cos(theta) * (py[b] - py[a]) - math.sin(theta) * (px[b] - px[a])
        if abs(side) > 1e-9:  # an arc: its middle too, so its chords stay within a cm
            turn = 0.5 * p.arc_bins * delta
            path[k] = _on_arc(px[a], py[a], theta, turn if side > 0 else -turn, p.radius)
            k += 1
        path[k, 0], path[k, 1] = px[b], py[b]
        k += 1
    for j in range(arcs):  # the shot's arc, in equal turns of at most half an arc's
        turn = shot_turn * (j + 1) / arcs
        path[k] = _on_arc(px[end], py[end], (end % bins) * delta, turn, p.radius)
        k += 1
    path[k, 0], path[k, 1] = gx, gy
    return True, path[: k + 1], g[end] + shot_cost, expansions


def _on_arc_py(x: float, y: float, theta: float, turn: float, radius: float) -> FloatArray:
    """Where an arc of ``radius`` from ``(x, y)`` heading ``theta`` ends after ``turn`` (+ left)."""
    side = 1.0 if turn > 0 else -1.0
    ax, ay = radius * math.sin(abs(turn)), side * radius * (1.0 - math.cos(turn))
    c, s = math.cos(theta), math.sin(theta)
    return np.array([x + c * ax - s * ay, y + s * ax + c * ay])


def _blocks_py(cost: UInt8Array, k: int) -> UInt8Array:
    """The least cost of every ``k`` x ``k`` block of cells (blocks past the edge: their part)."""
    height, width = cost.shape
    least = np.full((-(-height // k), -(-width // k)), 255, dtype=np.uint8)
    for y in range(height):
        row = least[y // k]
        for x in range(width):
            row[x // k] = min(row[x // k], cost[y, x])
    return least


# numba resolves the helpers when a kernel is first compiled, so their order is free
_blocks: Any = numba.njit(cache=True, nogil=True)(_blocks_py)
_sweep: Any = numba.njit(cache=True, nogil=True)(_sweep_py)
_straight: Any = numba.njit(cache=True, nogil=True)(_straight_py)
_lower: Any = numba.njit(cache=True, nogil=True)(_lower_py)
_on_arc: Any = numba.njit(cache=True, nogil=True)(_on_arc_py)
_shot: Any = numba.njit(cache=True, nogil=True)(_shot_py)
_hybrid: Any = numba.njit(cache=True, nogil=True)(_hybrid_py)


def hybrid_astar(
    cost: UInt8Array,
    start_xy: FloatArray,
    goal_xy: FloatArray,
    *,
    origin_xy_m: tuple[float, float],
    resolution_m: float,
    params: HybridParams,
    lethal: int = INSCRIBED,
    lanes: UInt8Array | None = None,
    against: float = 1.0,
) -> HybridResult:
    """A path of arcs and straights from a start to a goal on a cost grid (Hybrid-A*).

    Args:
        cost: (rows, cols) uint8 Nav2 costs, ``[iy, ix]``, row 0 at the lowest y.
        start_xy: the robot's position in ``map`` (m); its heading is free.
        goal_xy: the goal in ``map`` (m); the heading there is free.
        origin_xy_m: ``map`` position of the grid's lower-left corner (m).
        resolution_m: cell edge length (m).
        params: the lattice, the costs and the expansions allowed.
        lethal: cells at or above this cost are never touched by the robot's centre.
        lanes: optional (rows, cols) one-way directions, same shape as ``cost``.
        against: a step against a lane costs this many times more (>= 1).

    Returns:
        The path; not found when the start or goal lies off the grid, the goal is blocked,
        the 2-D search shows the goal out of reach, or ``max_expansions`` run out.

    Raises:
        ModelError: for lanes of another shape or ``against`` below 1.
    """
    if not (math.isfinite(against) and against >= 1):
        raise ModelError("against", against, "a finite factor >= 1")
    grid = readonly(np.ascontiguousarray(cost, dtype=np.uint8))
    lane_grid = lane_array(lanes, grid)
    origin = np.asarray(origin_xy_m, dtype=np.float64)
    start = (np.asarray(start_xy, dtype=np.float64)[:2] - origin) / resolution_m
    goal = (np.asarray(goal_xy, dtype=np.float64)[:2] - origin) / resolution_m
    height, width = grid.shape
    nothing = HybridResult(False, np.zeros((0, 2)), math.inf, math.inf, 0)
    if not all(0 <= p[0] < width and 0 <= p[1] < height for p in (start, goal)):
        return nothing
    sx, sy = math.floor(start[0]), math.floor(start[1])
    gx, gy = math.floor(goal[0]), math.floor(goal[1])
    r2 = int(escape_r2(grid, sx, sy, int(lethal)))
    if r2 < 0 or (grid[gy, gx] >= lethal and (gx - sx) ** 2 + (gy - sy) ** 2 > r2):
        return nothing
    prims = primitives(params, float(resolution_m))
    scale = params.cost_weight / MAX_NON_OBSTACLE
    # the 2-D cost-to-go on blocks of the bins' size, from the goal's block; the escape
    # disc of the start's block opened as the planner's escape rule opens the start's
    k = max(1, round(params.cell_m / resolution_m))
    blocks = _blocks(grid, k)
    bx, by = sx // k, sy // k
    escape = int(escape_r2(blocks, bx, by, int(lethal)))
    ys, xs = np.ogrid[: blocks.shape[0], : blocks.shape[1]]
    disc = ((xs - bx) ** 2 + (ys - by) ** 2 <= escape) & (blocks >= lethal)
    blocks[disc] = MAX_NON_OBSTACLE
    field = _dijkstra(
        readonly(blocks), (gy // k) * blocks.shape[1] + gx // k, params.cost_weight,
        int(lethal), DX, DY,
    )  # fmt: skip
    if escape < 0 or field[by * blocks.shape[1] + bx] == math.inf:
        return nothing  # the goal is out of reach
    terrain = Terrain(grid, lane_grid, scale, int(lethal), r2, sx, sy, float(against))
    found, cells, cost_cells, expansions = _hybrid(
        terrain,
        readonly(start),
        readonly(goal),
        readonly(field.reshape(blocks.shape)),
        k,
        prims,
        params.cell_m / resolution_m,
        int(params.max_expansions),
        bool(params.analytic_expansion),
    )
    if not found:
        return HybridResult(False, np.zeros((0, 2)), math.inf, math.inf, int(expansions))
    points = _merged(origin + cells * resolution_m)
    length = float(np.hypot(*np.diff(points, axis=0).T).sum())
    return HybridResult(True, points, length, float(cost_cells) * resolution_m, int(expansions))


def _merged(points: FloatArray) -> FloatArray:
    """The points without repeats (turns on the spot) and without inner points of straights."""
    points = points[np.r_[True, (np.abs(np.diff(points, axis=0)) > 1e-12).any(axis=1)]]
    if len(points) < 3:
        return points
    a, b = points[1:-1] - points[:-2], points[2:] - points[1:-1]
    cross = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    dot = (a * b).sum(axis=1)
    straight = (np.abs(cross) <= 1e-9 * np.hypot(*a.T) * np.hypot(*b.T)) & (dot > 0)
    merged: FloatArray = points[np.r_[True, ~straight, True]]
    return merged


__all__ = ["HybridParams", "HybridResult", "Primitives", "hybrid_astar", "primitives"]
