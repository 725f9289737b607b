"""Landmark lower bounds for A* on a static layer (ALT: A*, landmarks, triangle inequality).

Goldberg & Harrelson, "Computing the shortest path: A* search meets graph theory" (SODA
2005): with the least cost ``d(L, n)`` between a landmark ``L`` and every cell, the
triangle inequality gives ``d(n, g) >= |d(L, g) - d(L, n)|`` on a graph whose steps
cost the same both ways; the largest such bound over a few landmarks, or the octile
distance if larger, is a consistent heuristic, exact for cells on a least-cost path
from a landmark to the goal. On the 100 m x 100 m hall (1004 x 1004 cells, 8 landmarks,
200 fleet-like searches, ``bench/landmarks_bench.py``) it cuts A*'s mean expansions 2.3x
at cost weight 1 and 2.1x at 0, and its mean time 1.6x and 1.5x; what is left lies
mostly in the vast sets of equal-cost paths of the 8-connected grid, where no bound
short of the exact cost-to-go helps (12 or 16 landmarks expand 8 and 12 % fewer cells
but cost more per cell, and are no faster).

Cost model: that of :mod:`models.navigation.planner`, made symmetric by charging a step
for the cheaper of its two cells: ``step * (1 + cost_weight * min(c_from, c_to) / 252)``.
A planner step costs at least that (it pays for the cell it enters), so the bound holds
for the planner's directed costs; with ``cost_weight = 0`` the two agree. (Exact fields
from and to each landmark bound no better per byte: 6 landmarks with both expanded as
many cells as 12 symmetric ones.)

Why the bound holds on the costs a robot actually plans on: stamping obstacles
(:func:`models.navigation.costmap.with_obstacles`) only raises costs and blocks cells,
one-way lanes only make steps dearer, and a larger cost weight raises every step, so
every such search costs at least the static layer's (the planner refuses costs below
the layer's in any cell it reads). A robot that maps as it goes plans on a layer of its
own, on which these fields say nothing: it keeps the plain heuristic. So does a search
whose start's escape disc reaches cells blocked on the static layer (the planner's escape
rule lets it enter cells the static layer never enters).

Two cells are connected on the static layer exactly when they lie in the same
4-connected region of enterable cells (a diagonal step needs both cells beside it), for
any cost weight; every landmark lies in the largest region, so a cell reached from the
landmarks and one not reached cannot be joined: such cells are never opened, and a goal
walled off from the start is known at once.

Distances are stored as int32 fixed point, ``floor(d * 2**s)`` (cells), one row of ``K``
values per cell so that a heuristic evaluation reads one cache line. Rounding down makes
a difference of two stored values exceed ``2**s`` times the true difference by less
than one unit; dividing by ``2**s + 2`` instead of ``2**s`` takes that back for steps
costing at least one cell, so the heuristic stays admissible and consistent exactly.

Landmarks are chosen by farthest-point selection on the largest free region: from a seed
(the region's cell nearest the grid's centre) the farthest cell, then each next one
farthest from the seed and all chosen so far; on a hall that gives its four corners,
then the middles of its walls.
"""

from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass, field

import numba
import numpy as np
import numpy.typing as npt
from scipy import ndimage

from models.arrays import IntArray, UInt8Array
from models.errors import ModelError
from models.navigation.costmap import INSCRIBED, MAX_NON_OBSTACLE, StaticCostmap
from models.navigation.gridsearch import DX, DY, SQRT2, UNREACHED, readonly

Int32Array = npt.NDArray[np.int32]

DEFAULT_COUNT = 8
"""Landmarks per layer (measured on the 100 m x 100 m hall: 8 plans as fast as 12 or 16)."""
MAX_COUNT = 16
ALT_MIN_CELLS = 500_000
"""Smallest static layer (cells) on which a fleet's planning pays for the landmark fields.

``bench/landmarks_bench.py`` on the fleet50 hall grown with the fleet (the scale study's
halls, 0.1 m cells, 200 fleet-like searches each): per new goal the fields save the full
plan and the path-length yardstick together 0.6 ms on 304 x 304 cells (50 robots),
1.1 ms on 424 x 424 (100), 2.1 ms on 604 x 604 (200), 2.2 ms on 754 x 754 (500) and
2.9 ms on 1004 x 1004 (1,000); building both weights' fields takes 0.12, 0.2, 0.45, 0.76
and 1.5 s, so they pay after 195, 174, 213, 344 and 509 goals. In the scale study's runs
themselves (fields on against off, seed 1, two runs each) the 200-robot hall's 20 s
took 0.5 s longer with them (8.1 vs 7.6 s), the 500-robot hall's 10 s about as long
(12.4-12.8 vs 12.8-12.9 s) and the 1,000-robot hall's 10 s 2 s less (29.2-29.4 vs
31.1-31.6 s). fleet50's 60 s (about 100 goals) would not pay either.
"""


def _dijkstra_py(
    cost: UInt8Array, start: int, weight: float, lethal: int, dxs: IntArray, dys: IntArray
) -> npt.NDArray[np.float64]:
    """Least symmetric cost (cells) from ``start`` to every cell, ``inf`` where unreached.

    Steps as in the planner (8-connected, no corner cutting, cells at or above ``lethal``
    never entered), each charged ``step * (1 + weight * min(c_u, c_v) / 252)``.

    Dial's bucket queue instead of a heap: every step costs at least 1, so the cells
    whose cost lies in ``[b, b + 1)`` cannot improve one another and are settled in any
    order once the buckets below are done (a fifth faster than the heap on 10^6 cells,
    and exactly the same distances: each is the least of the same sums). Steps cost at
    most ``sqrt(2) * (1 + weight)``, so a ring of that many buckets plus two suffices.
    """
    height, width = cost.shape
    n = width * height
    grid = cost.ravel()
    offsets = dys * width + dxs
    dist = np.full(n, np.inf)
    done = np.zeros(n, dtype=np.bool_)
    scale = weight / MAX_NON_OBSTACLE
    ring = math.ceil(SQRT2 * (1.0 + weight)) + 2
    cap = 1024
    buckets = np.empty((ring, cap), dtype=np.int64)
    counts = np.zeros(ring, dtype=np.int64)
    dist[start] = 0.0
    buckets[0, 0] = start
    counts[0] = 1
    pending = 1
    current = 0
    while pending > 0:
        b = current % ring
        while counts[b] > 0:
            counts[b] -= 1
            pending -= 1
            node = buckets[b, counts[b]]
            if done[node]:
                continue  # settled from a lower bucket after an improvement
            done[node] = True
            node_d = dist[node]
            y = node // width
            x = node - y * width
            c_node = grid[node]
            border = x == 0 or y == 0 or x == width - 1 or y == height - 1
            for k in range(8):
                nx = x + dxs[k]
                ny = y + dys[k]
                if border and (nx < 0 or ny < 0 or nx >= width or ny >= height):
                    continue
                nb = node + offsets[k]
                if done[nb]:
                    continue
                c_nb = grid[nb]
                if c_nb >= lethal:
                    continue
                step = 1.0
                if k >= 4:
                    if grid[node + dxs[k]] >= lethal or grid[node + dys[k] * width] >= lethal:
                        continue
                    step = SQRT2
                nd = node_d + step * (1.0 + scale * min(c_node, c_nb))
                if nd >= dist[nb]:
                    continue
                dist[nb] = nd
                t = math.floor(nd) % ring
                if counts[t] == cap:
                    cap *= 2
                    grown = np.empty((ring, cap), dtype=np.int64)
                    grown[:, : cap // 2] = buckets
                    buckets = grown
                buckets[t, counts[t]] = nb
                counts[t] += 1
                pending += 1
        current += 1
    return dist


_dijkstra = numba.njit(cache=True, nogil=True)(_dijkstra_py)


@dataclass(frozen=True, eq=False)
class Landmarks:
    """Cost fields from a few landmark cells of a static layer, for A*'s heuristic.

    Build with :func:`build_landmarks`. Arrays are read-only.

    Attributes:
        cost: (rows, cols) uint8 static costs the fields were computed on, ``[iy, ix]``.
        cells: (K, 2) int64 landmark cells ``(ix, iy)``.
        fields: (rows * cols, K) int32 ``D_k = floor(d_k * 2**shift)``, ``d_k`` the
            least symmetric cost (cells) between landmark ``k`` and each cell (flat
            index ``iy * cols + ix``); :data:`UNREACHED` where no path joins them.
        shift: fixed-point exponent of the fields.
        scale: ``1 / (2**shift + 2)``: ``|D_k[g] - D_k[n]| * scale`` bounds the cost from
            ``n`` to ``g`` (cells).
        cost_weight: cost weight of the fields; they bound searches at this weight or more.
        lethal: blocking threshold of the fields; they bound searches with this one only.
        build_s: wall time the fields took (s); not part of any result.
    """

    cost: UInt8Array
    cells: IntArray
    fields: Int32Array
    shift: int
    scale: float
    cost_weight: float
    lethal: int
    build_s: float = field(default=0.0, compare=False)

    @property
    def nbytes(self) -> int:
        """Memory held by the fields (bytes)."""
        return int(self.fields.nbytes)

    def lower_bound(self, cell: tuple[int, int], goal: tuple[int, int]) -> float:
        """The landmark bound (cells) on the cost from ``cell`` to ``goal``.

        ``inf`` when the two lie in different connected regions of the layer; 0 when
        neither is reached from any landmark. The planner's heuristic is the larger of
        this and the octile distance.
        """
        width = self.cost.shape[1]
        a = self.fields[int(goal[1]) * width + int(goal[0])].astype(np.int64)
        b = self.fields[int(cell[1]) * width + int(cell[0])].astype(np.int64)
        if ((a == UNREACHED) != (b == UNREACHED)).any():
            return math.inf
        both = (a != UNREACHED) & (b != UNREACHED)
        return float(np.abs(a - b)[both].max(initial=0) * self.scale)


def _to_fixed(dist: npt.NDArray[np.float64], shift: int) -> Int32Array:
    fixed = np.full(dist.shape, UNREACHED, dtype=np.int32)
    finite = np.isfinite(dist)
    fixed[finite] = np.floor(np.ldexp(dist[finite], shift)).astype(np.int32)
    return fixed


def build_landmarks(
    cost: UInt8Array,
    *,
    count: int = DEFAULT_COUNT,
    cost_weight: float = 1.0,
    lethal: int = INSCRIBED,
) -> Landmarks:
    """Choose landmarks on a static layer and compute their cost fields.

    Args:
        cost: (rows, cols) uint8 static Nav2 costs, ``[iy, ix]`` (a
            :class:`~models.navigation.costmap.StaticCostmap`'s ``cost``).
        count: number of landmarks ``K``, 1 to 16 (fewer if the free region has fewer
            cells). Memory: ``4 * K`` bytes per cell.
        cost_weight: the planner's cost weight the fields are for (>= 0); they bound
            searches with this weight or a larger one.
        lethal: cells at or above this cost are never entered (as for the planner).

    Returns:
        The landmarks; without any enterable cell, none (``K = 0``).

    Raises:
        ModelError: for a count outside 1..16, a negative or non-finite weight, a
            lethal threshold outside 1..255 or a cost grid that is not 2-D and
            non-empty.
    """
    if not 1 <= count <= MAX_COUNT:
        raise ModelError("count", count, f"a number of landmarks from 1 to {MAX_COUNT}")
    if not (math.isfinite(cost_weight) and cost_weight >= 0):
        raise ModelError("cost_weight", cost_weight, "a finite weight >= 0")
    if not 1 <= lethal <= 255:
        raise ModelError("lethal", lethal, "a cost threshold from 1 to 255")
    if np.ndim(cost) != 2 or min(np.shape(cost)) == 0:
        raise ModelError("cost", np.shape(cost), "a non-empty (rows, cols) cost grid")
    start = time.perf_counter()
    grid = readonly(np.ascontiguousarray(cost, dtype=np.uint8))
    height, width = grid.shape
    weight, block = float(cost_weight), int(lethal)
    cells: list[int] = []
    table = np.zeros((height * width, 0), dtype=np.int32)
    shift = 0
    labels, regions = ndimage.label(grid < block)  # 4-connected: the move graph's regions
    if regions:
        sizes = np.bincount(labels.ravel())
        sizes[0] = 0
        region = np.flatnonzero(labels.ravel() == int(np.argmax(sizes)))
        # seed: the region's cell nearest the grid's centre; its farthest cell is landmark 1
        ys, xs = np.divmod(region, width)
        seed = int(region[np.argmin((xs - width / 2) ** 2 + (ys - height / 2) ** 2)])
        nearest = _dijkstra(grid, seed, weight, block, DX, DY)
        # no two cells of the region are farther apart than twice the seed's farthest:
        # the largest power of two keeping every stored distance below UNREACHED
        top = 2.0 * float(nearest[region].max())
        shift = max(0, math.floor(math.log2((UNREACHED - 1) / max(top, 1.0))))
        nearest[~np.isfinite(nearest)] = -1.0  # cells off the region are never chosen
        table = np.empty((height * width, min(count, len(region))), dtype=np.int32)
        for k in range(table.shape[1]):
            far = int(np.argmax(nearest))
            dist = _dijkstra(grid, far, weight, block, DX, DY)
            np.minimum(nearest, dist, out=nearest)
            cells.append(far)
            table[:, k] = _to_fixed(dist, shift)
    flat = np.array(cells, dtype=np.int64)
    return Landmarks(
        cost=readonly(grid),
        cells=readonly(np.stack([flat % width, flat // width], axis=1).reshape(-1, 2)),
        fields=readonly(table),
        shift=shift,
        scale=1.0 / (2.0**shift + 2.0),
        cost_weight=weight,
        lethal=block,
        build_s=time.perf_counter() - start,
    )


class LandmarkCache:
    """The landmark fields of one static costmap, built on first use per cost weight.

    One cache serves every robot planning on the same layer, also from several threads
    at once (a field set is built once, under a lock).

    Args:
        static: the static layer.
        count: landmarks per field set (see :func:`build_landmarks`).
    """

    def __init__(self, static: StaticCostmap, *, count: int = DEFAULT_COUNT) -> None:
        self.static = static
        self.count = count
        self._built: dict[float, Landmarks] = {}
        self._lock = threading.Lock()

    def get(self, cost_weight: float) -> Landmarks:
        """The fields for planning at ``cost_weight`` with the default lethal threshold."""
        key = float(cost_weight)
        built = self._built.get(key)
        if built is None:
            with self._lock:
                built = self._built.get(key)
                if built is None:
                    built = build_landmarks(self.static.cost, count=self.count, cost_weight=key)
                    self._built[key] = built
        return built


__all__ = [
    "ALT_MIN_CELLS",
    "DEFAULT_COUNT",
    "UNREACHED",
    "LandmarkCache",
    "Landmarks",
    "build_landmarks",
]
