"""A traffic roadmap of the hall: a square grid of places, each big enough for one robot.

A fleet manager that coordinates robots by reserving space needs a discrete map of that
space. Here it is a square grid laid over the static map: a node is a place where a robot
fits with margin (its centre at least ``clearance_m`` from every static obstacle), and two
4-neighbouring nodes are joined when a robot can drive straight between them with the same
margin. The spacing is at least a robot's diameter plus a gap, so robots at neighbouring
nodes do not touch. The grid's offset is chosen among sub-spacing shifts to put nodes in
as many narrow aisles as possible (an aisle narrower than two spacings holds one line of
nodes only where the grid happens to fall inside its free band). Edges may be one-way
(:func:`one_way`): ``neighbours[u, k]`` is then a step robots may take from ``u``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numba
import numpy as np
import numpy.typing as npt
from scipy import sparse
from scipy.sparse import csgraph
from scipy.spatial import cKDTree

from models.arrays import BoolArray, FloatArray, IntArray, UInt8Array
from models.errors import ModelError
from models.navigation.lanes import EAST, NORTH, SOUTH, TWO_WAY, WEST

STEPS: tuple[tuple[int, int], ...] = ((1, 0), (-1, 0), (0, 1), (0, -1))
"""The four grid moves (dx, dy) in node units; column k of :attr:`Roadmap.neighbours`."""
Int32Array = npt.NDArray[np.int32]
UNREACHABLE = np.iinfo(np.int32).max
"""Hop count of a node that cannot reach the goal."""


@dataclass(frozen=True)
class Roadmap:
    """Nodes and 4-neighbour edges of the traffic grid.

    Attributes:
        xy: (m, 2) node centres in ``map`` (m).
        neighbours: (m, 4) neighbouring node along each of :data:`STEPS`, or -1.
        spacing_m: distance between neighbouring nodes (m).
        component: (m,) strongly connected component of each node (derived): a robot
            reaches every node of its own component, and only those.
    """

    xy: FloatArray
    neighbours: IntArray
    spacing_m: float
    component: IntArray = field(init=False, repr=False, compare=False)
    _tree: cKDTree = field(init=False, repr=False, compare=False)
    _reverse: IntArray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        m = len(self.xy)
        rows = np.repeat(np.arange(m), 4)
        cols = self.neighbours.reshape(-1)
        keep = cols >= 0
        graph = sparse.csr_matrix(
            (np.ones(int(keep.sum())), (rows[keep], cols[keep])), shape=(m, m)
        )
        _, labels = csgraph.connected_components(graph, directed=True, connection="strong")
        # the reversed edges, built once: hops *to* a goal are a search from it against them
        reverse = np.full((m, 4), -1, dtype=np.int64)
        for k in range(4):
            linked = self.neighbours[:, k] >= 0
            reverse[self.neighbours[linked, k], k] = np.flatnonzero(linked)
        object.__setattr__(self, "_reverse", reverse)
        object.__setattr__(self, "component", labels.astype(np.int64))
        object.__setattr__(self, "_tree", cKDTree(self.xy if m else np.zeros((0, 2))))

    def __len__(self) -> int:
        return len(self.xy)

    def near(self, point: FloatArray, radius_m: float) -> list[int]:
        """Nodes whose centres lie within ``radius_m`` of ``point`` (m), nearest first."""
        found = self._tree.query_ball_point(np.asarray(point, dtype=float), radius_m)
        return sorted(found, key=lambda k: float(np.hypot(*(self.xy[k] - point))))

    def nearest_k(self, points: FloatArray, k: int) -> IntArray:
        """(p, k) the ``k`` nodes nearest each of (p, 2) points (m), nearest first."""
        _, index = self._tree.query(np.asarray(points, dtype=float).reshape(-1, 2), k=k)
        return np.asarray(index, dtype=np.int64).reshape(len(index), -1)

    def hops_to(self, goal: int) -> Int32Array:
        """(m,) int32 hops from every node to ``goal`` along the edges' directions.

        :data:`UNREACHABLE` where there is no way.
        """
        out = np.full(len(self.xy), UNREACHABLE, dtype=np.int32)
        _hops_to(self._reverse, goal, out)
        return out


def _hops_to_py(reverse: IntArray, goal: int, out: Int32Array) -> None:
    """Breadth-first search from ``goal`` along ``reverse`` ((m, 4) predecessors), into ``out``.

    ``out`` holds :data:`UNREACHABLE` everywhere on entry.
    """
    queue = np.empty(len(out), dtype=np.int64)
    queue[0] = goal
    out[goal] = 0
    head, tail = 0, 1
    while head < tail:
        u = queue[head]
        head += 1
        for k in range(4):
            v = reverse[u, k]
            if v >= 0 and out[v] == UNREACHABLE:
                out[v] = out[u] + 1
                queue[tail] = v
                tail += 1


_hops_to: Any = numba.njit(cache=True, nogil=True)(_hops_to_py)


def segment_clear(
    clear: BoolArray, a: FloatArray, b: FloatArray, origin: tuple[float, float], res: float
) -> BoolArray:
    """Whether every grid cell along each segment ``a[k] -> b[k]`` is clear.

    Args:
        clear: (rows, cols) cells that are clear, ``[iy, ix]``; outside the grid is not.
        a: (k, 2) segment starts in ``map`` (m).
        b: (k, 2) segment ends in ``map`` (m).
        origin: ``map`` position of the lower-left corner of cell (0, 0) (m).
        res: cell size (m); segments are sampled every half cell.
    """
    length = float(np.max(np.hypot(*(b - a).T))) if len(a) else 0.0
    samples = max(2, int(np.ceil(length / (0.5 * res))) + 1)
    t = np.linspace(0.0, 1.0, samples)
    pts = a[:, None, :] + (b - a)[:, None, :] * t[None, :, None]
    ix = np.floor((pts[..., 0] - origin[0]) / res).astype(np.int64)
    iy = np.floor((pts[..., 1] - origin[1]) / res).astype(np.int64)
    rows, cols = clear.shape
    inside = (ix >= 0) & (ix < cols) & (iy >= 0) & (iy < rows)
    ok = np.zeros(ix.shape, dtype=bool)
    ok[inside] = clear[iy[inside], ix[inside]]
    result: BoolArray = np.asarray(ok.all(axis=1))
    return result


def _grid(
    clear: BoolArray,
    origin: tuple[float, float],
    res: float,
    spacing_m: float,
    offset: tuple[float, float],
) -> tuple[FloatArray, IntArray]:
    """Node centres and neighbours of the grid shifted by ``offset`` (m)."""
    rows, cols = clear.shape
    x0 = origin[0] + offset[0]
    y0 = origin[1] + offset[1]
    xs = x0 + spacing_m * np.arange(int((cols * res - offset[0]) // spacing_m) + 1)
    ys = y0 + spacing_m * np.arange(int((rows * res - offset[1]) // spacing_m) + 1)
    gx, gy = np.meshgrid(xs, ys)
    centres = np.stack([gx.ravel(), gy.ravel()], axis=1)
    ix = np.floor((centres[:, 0] - origin[0]) / res).astype(np.int64)
    iy = np.floor((centres[:, 1] - origin[1]) / res).astype(np.int64)
    inside = (ix >= 0) & (ix < cols) & (iy >= 0) & (iy < rows)
    valid = np.zeros(len(centres), dtype=bool)
    valid[inside] = clear[iy[inside], ix[inside]]
    flat = np.full(len(centres), -1, dtype=np.int64)
    flat[valid] = np.arange(int(valid.sum()))
    index = flat.reshape(len(ys), len(xs))
    xy = centres[valid]
    neighbours = np.full((len(xy), 4), -1, dtype=np.int64)
    node_r, node_c = np.nonzero(index >= 0)
    for k, (dc, dr) in enumerate(STEPS):
        r, c = node_r + dr, node_c + dc
        ok = (r >= 0) & (r < len(ys)) & (c >= 0) & (c < len(xs))
        other = np.full(len(xy), -1, dtype=np.int64)
        other[ok] = index[r[ok], c[ok]]
        linked = other >= 0
        src = index[node_r, node_c]
        free = np.zeros(len(xy), dtype=bool)
        free[linked] = segment_clear(clear, xy[src[linked]], xy[other[linked]], origin, res)
        neighbours[src[free], k] = other[free]
    return xy, neighbours


def one_way(
    roadmap: Roadmap, lanes: UInt8Array, origin: tuple[float, float], res: float
) -> Roadmap:
    """The roadmap without the steps against a one-way lane at either end of them.

    Places the lanes would cut off from the rest (short lanes in a small room can leave a
    place only enterable, or only leavable) keep their steps both ways.

    Args:
        roadmap: a two-way roadmap.
        lanes: (rows, cols) lane direction per costmap cell (:mod:`models.navigation.lanes`).
        origin: ``map`` position of the lower-left corner of lane cell (0, 0) (m).
        res: lane cell size (m).
    """
    lane = _lanes_at(roadmap.xy, lanes, origin, res)
    against = {0: WEST, 1: EAST, 2: SOUTH, 3: NORTH}  # step k is against this lane
    neighbours = roadmap.neighbours.copy()
    for k in range(4):
        other = neighbours[:, k]
        linked = other >= 0
        bad = linked & (lane == against[k])
        bad[linked] |= lane[other[linked]] == against[k]
        neighbours[bad, k] = -1
    return _kept_connected(roadmap, neighbours)


def build_roadmap(
    distance_m: npt.NDArray[np.floating[Any]],
    origin_xy_m: tuple[float, float],
    resolution_m: float,
    spacing_m: float,
    clearance_m: float,
    shifts: int = 8,
) -> Roadmap:
    """The traffic grid over a static map.

    Args:
        distance_m: (rows, cols) distance (m) from each costmap cell centre to the nearest
            static obstacle, indexed ``[iy, ix]``.
        origin_xy_m: ``map`` position of the lower-left corner of cell (0, 0) (m).
        resolution_m: costmap cell size (m).
        spacing_m: node spacing (m), at least a robot's diameter plus a gap.
        clearance_m: least distance (m) from a node, or an edge, to any static obstacle.
        shifts: offsets tried per axis (``spacing_m / shifts`` apart).

    Raises:
        ModelError: if no offset leaves a single node.
    """
    clear = np.asarray(distance_m) >= clearance_m
    best: tuple[int, FloatArray, IntArray] | None = None
    for sx in range(shifts):
        for sy in range(shifts):
            offset = (spacing_m * (sx + 0.5) / shifts, spacing_m * (sy + 0.5) / shifts)
            xy, neighbours = _grid(clear, origin_xy_m, resolution_m, spacing_m, offset)
            score = int((neighbours >= 0).sum())  # edges: nodes that connect
            if best is None or score > best[0]:
                best = (score, xy, neighbours)
    if best is None or len(best[1]) == 0:
        raise ModelError(
            "navigation.traffic",
            "pibt",
            f"a floor with room for a {spacing_m:g} m grid of robot places",
        )
    _, xy, neighbours = best
    return Roadmap(xy, neighbours, spacing_m)


def one_way_floor(
    roadmap: Roadmap, lanes: UInt8Array, origin: tuple[float, float], res: float
) -> Roadmap:
    """The roadmap with its open floor as a grid of alternating one-way streets.

    Steps between two places off the lanes keep only the row's or column's direction:
    rows alternate east and west, columns north and south (a unidirectional flow-path
    network: Gaskins & Tanchoco, "Flow path design for automated guided vehicle
    systems", Int. J. of Production Research 25(5), 1987), so no two robots ever meet
    head-on. The rows' and the columns' parities are chosen to agree with most of the
    lanes' steps. Places that would lose their way to, or from, the rest are left two-way.
    """
    if not len(roadmap):
        return roadmap
    lane = _lanes_at(roadmap.xy, lanes, origin, res)
    col = np.rint((roadmap.xy[:, 0] - roadmap.xy[:, 0].min()) / roadmap.spacing_m).astype(np.int64)
    row = np.rint((roadmap.xy[:, 1] - roadmap.xy[:, 1].min()) / roadmap.spacing_m).astype(np.int64)
    along = {0: (row, EAST), 1: (row, WEST), 2: (col, NORTH), 3: (col, SOUTH)}

    def parity(k_plus: int, k_minus: int) -> int:
        """The parity whose streets run the lanes' way, by their steps (+: even lines)."""
        line, plus = along[k_plus]
        minus = along[k_minus][1]
        agree = int(
            np.sum((line % 2 == 0) & (lane == plus)) + np.sum((line % 2 == 1) & (lane == minus))
        )
        disagree = int(
            np.sum((line % 2 == 0) & (lane == minus)) + np.sum((line % 2 == 1) & (lane == plus))
        )
        return 0 if agree >= disagree else 1

    rows_even_east = parity(0, 1)
    cols_even_north = parity(2, 3)
    neighbours = roadmap.neighbours.copy()
    for k in range(4):
        other = neighbours[:, k]
        linked = other >= 0
        floor = linked & (lane == TWO_WAY)
        floor[linked] &= lane[other[linked]] == TWO_WAY
        line = row if k in (0, 1) else col
        offset = rows_even_east if k in (0, 1) else cols_even_north
        forward = (line + offset) % 2 == 0  # this line runs towards +x (+y)
        bad = floor & (forward != (k in (0, 2)))
        neighbours[bad, k] = -1
    return _kept_connected(roadmap, neighbours)


def _kept_connected(roadmap: Roadmap, neighbours: IntArray) -> Roadmap:
    """``roadmap`` with the steps ``neighbours`` keeps, and back both ways at stray places.

    A place that the one-way steps cut off from the largest part of its component (it
    could not reach it, or be reached from it) gets its steps back, both ways, until none
    is cut off: one-way streets must never leave a robot where it cannot get out.
    """
    directed = Roadmap(roadmap.xy, neighbours, roadmap.spacing_m)
    for _ in range(len(roadmap)):
        stray = _stray(roadmap.component, directed.component)
        if not stray.any():
            break
        restore = stray[:, None] | np.isin(roadmap.neighbours, np.flatnonzero(stray))
        neighbours = np.where(restore, roadmap.neighbours, neighbours)
        directed = Roadmap(roadmap.xy, neighbours, roadmap.spacing_m)
    return directed


def _lanes_at(
    xy: FloatArray, lanes: UInt8Array, origin: tuple[float, float], res: float
) -> UInt8Array:
    """The lane direction of the cell under each of (m, 2) points (m)."""
    ix = np.floor((xy[:, 0] - origin[0]) / res).astype(np.int64)
    iy = np.floor((xy[:, 1] - origin[1]) / res).astype(np.int64)
    found: UInt8Array = lanes[iy, ix]
    return found


def _stray(before: IntArray, after: IntArray) -> BoolArray:
    """Nodes cut off from the largest part (``after``) of their component ``before``."""
    stray = np.zeros(len(before), dtype=bool)
    for component in np.unique(before):
        members = before == component
        parts, counts = np.unique(after[members], return_counts=True)
        stray[members] = after[members] != parts[np.argmax(counts)]
    return stray
