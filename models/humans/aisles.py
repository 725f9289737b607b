"""The aisle graph: where people walk in a warehouse (frame ``map``).

Every layout is made of axis-aligned boxes, so aisles are bands between box edges. Lines
are laid along the centres of the gaps between consecutive box edges (widest gaps first,
at least ``spacing_m`` apart; open stretches get evenly spaced extra lines), crossing
each other on a grid. A grid point is a node where a person fits (``clearance_m`` from
every box); neighbouring nodes on one line are joined where the whole segment keeps that
clearance. The largest connected part is kept and straight chains are merged, so an
aisle is one edge and its junctions are where cross-aisles meet it.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from models.arrays import FloatArray
from models.errors import ModelError
from models.world.warehouse import Warehouse, box_distance

SAMPLE_M = 0.1
"""Spacing of the points at which an edge's clearance is checked (m)."""
MAX_WIDTH_M = 3.0
"""Widest walking lane an edge gets, however open the space around it (m)."""
FILL_FACTOR = 3.0
"""Open stretches wider than this many ``spacing_m`` get evenly spaced extra lines."""

IntArray = npt.NDArray[np.int64]


@dataclass(frozen=True)
class AisleGraph:
    """An undirected graph of straight walking edges.

    Attributes:
        nodes: (k, 2) node positions ``x_m, y_m`` in ``map``.
        edges: (m, 2) node indices ``a, b`` of each edge (a < b).
        width_m: (m,) lane width of each edge: twice its smallest clearance, capped (m).
    """

    nodes: FloatArray
    edges: IntArray
    width_m: FloatArray

    @property
    def length_m(self) -> FloatArray:
        """(m,) edge lengths (m)."""
        a, b = self.nodes[self.edges[:, 0]], self.nodes[self.edges[:, 1]]
        lengths: FloatArray = np.hypot(*(b - a).T)
        return lengths

    def point(self, edge: int, offset_m: float) -> tuple[float, float]:
        """The point ``offset_m`` along ``edge`` from its first node (m, ``map``)."""
        a, b = self.nodes[self.edges[edge, 0]], self.nodes[self.edges[edge, 1]]
        t = offset_m / float(np.hypot(*(b - a)))
        x, y = a + t * (b - a)
        return float(x), float(y)

    def nearest(self, points: FloatArray) -> tuple[IntArray, FloatArray, FloatArray]:
        """Snap points (n, 2) to their nearest edges.

        Returns:
            edge index (n,), offset along the edge from its first node (n,) (m) and the
            distance from each point to the edge (n,) (m).
        """
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        a = self.nodes[self.edges[:, 0]]
        d = self.nodes[self.edges[:, 1]] - a
        length = np.hypot(d[:, 0], d[:, 1])
        rel = pts[:, None, :] - a[None, :, :]
        t = np.clip((rel * d[None]).sum(axis=2) / length**2, 0.0, 1.0)
        foot = a[None] + t[..., None] * d[None]
        gap = np.hypot(*(pts[:, None, :] - foot).transpose(2, 0, 1))
        best = gap.argmin(axis=1)
        rows = np.arange(len(pts))
        return best, t[rows, best] * length[best], gap[rows, best]


def aisle_graph(world: Warehouse, *, clearance_m: float, spacing_m: float) -> AisleGraph:
    """Build the walking graph of ``world``.

    Args:
        world: the warehouse.
        clearance_m: the smallest distance from an edge to any box (m): a person's
            half-width plus a margin.
        spacing_m: the least distance between two parallel lines (m).

    Raises:
        ModelError: if no two points of the room can be joined (no room to walk).
    """
    boxes = world.boxes
    width, height = world.size_m
    xs = _lines(boxes[:, [0, 2]], width, clearance_m, spacing_m)
    ys = _lines(boxes[:, [1, 3]], height, clearance_m, spacing_m)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    grid = np.stack([gx.ravel(), gy.ravel()], axis=1)
    free = world.clearance(grid) >= clearance_m
    index = np.arange(len(grid)).reshape(len(xs), len(ys))
    pairs = np.concatenate(
        [
            np.stack([index[:-1, :].ravel(), index[1:, :].ravel()], axis=1),
            np.stack([index[:, :-1].ravel(), index[:, 1:].ravel()], axis=1),
        ]
    )
    pairs = pairs[free[pairs[:, 0]] & free[pairs[:, 1]]]
    least = _segment_clearance(world, grid, pairs)
    keep = least >= clearance_m
    pairs, least = pairs[keep], least[keep]
    if len(pairs) == 0:
        raise ModelError(
            "humans.worker_radius_m",
            clearance_m,
            f"a person narrow enough to walk between the shelves (no line through the room "
            f"keeps {clearance_m:g} m from every shelf and wall)",
        )
    pairs, least = _largest_part(len(grid), pairs, least)
    nodes, pairs, least = _merge_chains(grid, pairs, least)
    widths = np.minimum(2.0 * least, MAX_WIDTH_M)
    return AisleGraph(nodes, pairs, widths)


def _lines(extents: FloatArray, size: float, clearance: float, spacing: float) -> FloatArray:
    """Line coordinates along one axis: centres of the gaps between box edges."""
    edges = np.clip(extents.ravel(), 0.0, size)
    coords = np.unique(np.concatenate([edges, [0.0, size]]))
    gaps = np.diff(coords)
    mids = (coords[:-1] + coords[1:]) / 2
    usable = gaps >= 2 * clearance
    order = np.argsort(-gaps[usable], kind="stable")
    chosen: list[float] = []
    for m in mids[usable][order].tolist():
        if all(abs(m - c) >= spacing for c in chosen):
            chosen.append(m)
    lines = sorted(chosen)
    # open stretches (and the borders of the room) get evenly spaced lines too
    bounds = [clearance, *lines, size - clearance]
    filled: list[float] = []
    for lo, hi in itertools.pairwise(bounds):
        parts = int((hi - lo) // (FILL_FACTOR * spacing))
        filled.extend(np.linspace(lo, hi, parts + 2)[1:-1].tolist() if parts > 0 else [])
    result = sorted(lines + filled)
    if len(result) < 2:  # an open room: at least two lines to cross
        result = sorted({*result, size / 4, 3 * size / 4})
    return np.array(result, dtype=float)


def _segment_clearance(world: Warehouse, grid: FloatArray, pairs: IntArray) -> FloatArray:
    """The smallest clearance along each segment (m), sampled every ``SAMPLE_M``, in one call."""
    if len(pairs) == 0:
        return np.zeros(0)
    a, b = grid[pairs[:, 0]], grid[pairs[:, 1]]
    counts = np.maximum(2, np.ceil(np.hypot(*(b - a).T) / SAMPLE_M).astype(np.int64) + 1)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    owner = np.repeat(np.arange(len(pairs)), counts)
    t = (np.arange(counts.sum()) - starts[owner]) / (counts[owner] - 1)
    points = a[owner] + t[:, None] * (b - a)[owner]
    least: FloatArray = np.minimum.reduceat(world.clearance(points), starts)
    return least


def _largest_part(count: int, pairs: IntArray, least: FloatArray) -> tuple[IntArray, FloatArray]:
    adjacency = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), (count, count))
    _, labels = connected_components(adjacency, directed=False)
    sizes = np.bincount(labels[pairs[:, 0]], minlength=labels.max() + 1)
    keep = labels[pairs[:, 0]] == sizes.argmax()
    return pairs[keep], least[keep]


def _merge_chains(
    grid: FloatArray, pairs: IntArray, least: FloatArray
) -> tuple[FloatArray, IntArray, FloatArray]:
    """Drop nodes that only continue a straight line; renumber the rest."""
    neighbours: dict[int, list[tuple[int, float]]] = {}
    for (i, j), c in zip(pairs.tolist(), least.tolist(), strict=True):
        neighbours.setdefault(i, []).append((j, c))
        neighbours.setdefault(j, []).append((i, c))

    def straight(node: int) -> bool:
        links = neighbours[node]
        if len(links) != 2:
            return False
        (a, _), (b, _) = links
        da, db = grid[a] - grid[node], grid[b] - grid[node]
        return bool(abs(da[0] * db[1] - da[1] * db[0]) < 1e-9)

    kept = sorted(n for n in neighbours if not straight(n))
    merged: dict[tuple[int, int], float] = {}
    for start in kept:
        for nxt, c in neighbours[start]:
            prev, here, low = start, nxt, c
            while straight(here):
                (a, ca), (b, cb) = neighbours[here]
                step, cost = (b, cb) if a == prev else (a, ca)
                prev, here, low = here, step, min(low, cost)
            key = (min(start, here), max(start, here))
            merged[key] = min(low, merged.get(key, np.inf))
    renumber = {old: new for new, old in enumerate(kept)}
    edges = np.array([(renumber[a], renumber[b]) for a, b in merged], dtype=np.int64)
    widths = np.array(list(merged.values()), dtype=float)
    return grid[kept], edges.reshape(-1, 2), widths


def dock_points(graph: AisleGraph) -> tuple[IntArray, FloatArray]:
    """Spots on the walking line nearest the dock (south) wall (edge index, offset m).

    One spot per node of that line (nodes within 0.5 m of the southernmost one), west to
    east: the dock's drop-off points.
    """
    south = graph.nodes[:, 1].min()
    inside = np.flatnonzero(graph.nodes[:, 1] <= south + 0.5)
    inside = inside[np.argsort(graph.nodes[inside, 0], kind="stable")]
    return _spots_at_nodes(graph, inside)


def _spots_at_nodes(graph: AisleGraph, nodes: IntArray) -> tuple[IntArray, FloatArray]:
    edges, offsets = [], []
    lengths = graph.length_m
    for node in nodes.tolist():
        first = np.flatnonzero(graph.edges[:, 0] == node)
        if len(first):
            edges.append(int(first[0]))
            offsets.append(min(0.5, lengths[first[0]] / 2))
            continue
        last = int(np.flatnonzero(graph.edges[:, 1] == node)[0])
        edges.append(last)
        offsets.append(max(lengths[last] - 0.5, lengths[last] / 2))
    return np.array(edges, dtype=np.int64), np.array(offsets, dtype=float)


def pick_stations(
    world: Warehouse, graph: AisleGraph, count: int, rng: np.random.Generator
) -> tuple[IntArray, FloatArray]:
    """``count`` spots beside shelves, outside the dock (edge index, offset m).

    Spots are drawn along the edges, in proportion to their length, among the points
    within 1 m of a shelf's face beyond the edge's own clearance; without shelves, any
    point outside the dock strip.

    Raises:
        ModelError: if no edge leaves the dock strip.
    """
    lengths = graph.length_m
    starts = np.concatenate([[0.0], np.cumsum(lengths)])
    along = np.arange(SAMPLE_M, starts[-1], SAMPLE_M * 5)
    edge = np.clip(np.searchsorted(starts, along, side="right") - 1, 0, len(lengths) - 1)
    offset = along - starts[edge]
    a = graph.nodes[graph.edges[edge, 0]]
    b = graph.nodes[graph.edges[edge, 1]]
    points = a + (offset / lengths[edge])[:, None] * (b - a)
    ok = (points[:, 1] > world.dock_depth_m) & (offset > 0.3) & (offset < lengths[edge] - 0.3)
    if len(world.shelves):
        near = box_distance(points, world.shelves).min(axis=1)
        beside = ok & (near <= graph.width_m[edge] / 2 + 1.0)
        ok = beside if beside.any() else ok
    candidates = np.flatnonzero(ok)
    if len(candidates) == 0:
        raise ModelError(
            "world.layout", "(this layout)", "aisles beyond the dock strip for pick stations"
        )
    chosen = rng.choice(candidates, size=count, replace=count > len(candidates))
    return edge[chosen].astype(np.int64), offset[chosen]
