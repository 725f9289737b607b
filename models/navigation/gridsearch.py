"""Numba kernels of the global planner: A* on an 8-connected cost grid, line of sight.

Private to :mod:`models.navigation.planner`, which states the cost model and the escape
rule. Grids are uint8 ``[iy, ix]``; cells are flat indices ``iy * width + ix`` inside
the kernels and ``(ix, iy)`` pairs at their boundary.

Why the A* looks the way it does (measured on the 608 x 608 fleet50 hall,
``bench/planner_bench.py``): the priority queue dominates, not the neighbour loop, so
the heap is an indexed binary heap with decrease-key (one entry per cell, no stale
entries to pop), the ``f`` and ``g`` of an entry sit side by side, the pop is Floyd's
(the hole descends along the better child, chosen without a branch, then the last
entry rises), and the sifts are written out inline (as numba helper calls they cost a
third more). Per-cell state lives in one allocation, because several grid-sized
arrays per call cost more in page faults than a short search, and it is not zeroed: a
byte per cell says where it is valid (zeroing the whole hall's state each call would cost
more than a failed plan of a robot boxed in by its neighbours).
The heap grows only between expansions, which keeps its arrays fixed inside the hot
loops.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np
import numpy.typing as npt

from models.arrays import IntArray, UInt8Array
from models.navigation.costmap import MAX_NON_OBSTACLE

SQRT2 = math.sqrt(2.0)
"""Length of a diagonal step (cells)."""

DX = np.array([1, -1, 0, 0, 1, 1, -1, -1], dtype=np.int64)
"""x offsets of the 8 moves: 4 straight, then 4 diagonal."""
DY = np.array([0, 0, 1, -1, 1, -1, 1, -1], dtype=np.int64)
"""y offsets of the 8 moves."""
_F_STEPS = 2.0**28
"""A*'s ``f`` is rounded to multiples of ``1 / _F_STEPS`` cells (see the A*)."""
UNREACHED = int(np.iinfo(np.int32).max)
"""Stored landmark distance of a cell that no path from the landmark reaches."""


def readonly(array: npt.NDArray[Any]) -> npt.NDArray[Any]:
    """A read-only view of an array, for the inputs of numba kernels.

    numba compiles a kernel once per argument type, and writability is part of the type:
    giving every kernel read-only inputs (the static layer's arrays are read-only) keeps
    it to one compilation.
    """
    view = array.view()
    view.flags.writeable = False
    return view


def _escape_r2_py(cost: UInt8Array, sx: int, sy: int, lethal: int) -> int:
    """Squared distance (cells) from the start to the nearest enterable cell.

    0 when the start itself is enterable, -1 when no cell is.
    """
    height, width = cost.shape
    if cost[sy, sx] < lethal:
        return 0
    best = -1
    for k in range(1, max(height, width)):
        if best >= 0 and best <= k * k:
            break
        for j in range(-k, k + 1):
            for i in range(-k, k + 1):
                if max(abs(i), abs(j)) != k:
                    continue
                x, y = sx + i, sy + j
                if 0 <= x < width and 0 <= y < height and cost[y, x] < lethal:
                    d2 = i * i + j * j
                    if best < 0 or d2 < best:
                        best = d2
    return best


def _astar_py(
    cost: UInt8Array,
    sx: int,
    sy: int,
    gx: int,
    gy: int,
    weight: float,
    lethal: int,
    escape_r2: int,
    dxs: IntArray,
    dys: IntArray,
    lanes: UInt8Array,
    against: float,
    fields: npt.NDArray[np.int32],
    field_scale: float,
    floor: UInt8Array,
) -> tuple[bool, IntArray, int, int, float, int, int]:
    """A* with an indexed binary heap (decrease-key) ordered by ``(f, -g)``.

    Per cell: ``seen``; ``g``; ``pos``, its heap index + 1 while open (-1 closed);
    ``parent``, the move ``k`` that entered it. ``g``, ``pos`` and ``parent`` are valid
    where ``seen``, and live in one allocation that is left as it comes (freed memory
    reused, not zeroed: only ``seen``, a byte per cell, is). Heap entry ``i`` is
    ``heap_k[2i] = f``, ``heap_k[2i + 1] = g`` (side by side for locality) and
    ``heap_n[i]`` = cell; the heap starts small and doubles when full.

    ``f`` is rounded to a multiple of 2^-28 cells. Costs are sums of steps of 1 and
    ``sqrt(2)`` (times cost factors), so equal costs summed in different orders differ
    in their last bits, and the 8-connected grid has vast sets of equal-cost paths
    across open floor: without the rounding those last bits rather than the ``-g``
    tie-break ordered the heap, and A* closed much of such a set (on the 100 m x 100 m
    hall, 100 random plans: 4.0 million expansions at cost weight 0, 1.45 million with
    the rounding; 5.4 and 3.3 million at weight 1). The step lies well above that noise
    (about 1e-11 cells at 10^3 cells; the expansions are the same for steps from 2^-20
    to 2^-32) and well below real cost differences: a found cost can exceed the least
    only where two unequal costs of one cell round alike, by less than a step each time,
    and at cost weight 0 unequal costs up to 10^3 cells differ by 1e-4 cells or more.

    ``lanes`` (rows, cols) one-way directions (:mod:`models.navigation.lanes`) or an
    empty (0, 0) array: a step whose move runs against the lane of the cell it enters
    costs ``against`` times more.

    ``fields`` (rows * cols, K) landmark distances and ``field_scale`` their scale
    (:class:`models.navigation.landmarks.Landmarks`), or an empty (0, 0) array: the
    heuristic is then the larger of the octile distance and the landmark bound, and a
    cell the landmarks show to be cut off from the goal is never opened. ``floor``
    (rows, cols) are the static costs the fields were computed on: the search stops at
    the first enterable cell it reads whose cost is below them (the bound would not
    hold there).

    Returns found, the path cells (n, 2), its straight and diagonal step counts, its
    cost in cells, the number of expansions, and the flat index of a cell below
    ``floor`` (-1 if none was read).
    """
    height, width = cost.shape
    n = width * height
    grid = cost.ravel()
    lane = lanes.ravel()
    use_lanes = lane.shape[0] == n
    marks = fields.shape[1] if fields.shape[0] == n else 0
    goal_marks = np.empty(marks, dtype=np.int32)
    for f in range(marks):
        goal_marks[f] = fields[gy * width + gx, f]
    least = floor.ravel()
    offsets = dys * width + dxs
    buf = np.empty(n + (5 * n + 7) // 8)
    seen = np.zeros(n, dtype=np.bool_)
    g = buf[:n]
    pos = buf[n:].view(np.int32)[:n]
    parent = buf[n:].view(np.uint8)[4 * n : 5 * n]
    cap = 1024
    heap_k = np.empty(2 * cap)
    heap_n = np.empty(cap, dtype=np.int64)
    start = sy * width + sx
    goal = gy * width + gx
    g[start] = 0.0
    heap_k[0], heap_k[1], heap_n[0] = 0.0, 0.0, start
    pos[start] = 1
    seen[start] = True
    size = 1
    expansions = 0
    found = False
    scale = weight / MAX_NON_OBSTACLE
    while size > 0:
        if size + 8 > cap:  # room for every neighbour of this expansion
            cap *= 2
            grown_k = np.empty(2 * cap)
            grown_k[: 2 * size] = heap_k[: 2 * size]
            grown_n = np.empty(cap, dtype=np.int64)
            grown_n[:size] = heap_n[:size]
            heap_k, heap_n = grown_k, grown_n
        node = heap_n[0]
        node_g = heap_k[1]
        pos[node] = -1
        expansions += 1
        # pop: move the last entry to the root and sift it down
        size -= 1
        if size > 0:
            lf, lg, ln = heap_k[2 * size], heap_k[2 * size + 1], heap_n[size]
            # Floyd's pop: the hole goes down to a leaf along the better children (chosen
            # without a branch), then the last entry sifts up from there
            i = 0
            c = 1
            while c < size:
                if c + 1 < size:
                    f1, f2 = heap_k[2 * c], heap_k[2 * c + 2]
                    c += (f2 < f1) | ((f2 == f1) & (heap_k[2 * c + 3] > heap_k[2 * c + 1]))
                heap_k[2 * i] = heap_k[2 * c]
                heap_k[2 * i + 1] = heap_k[2 * c + 1]
                heap_n[i] = heap_n[c]
                pos[heap_n[i]] = i + 1
                i = c
                c = 2 * i + 1
            while i > 0:
                p = (i - 1) // 2
                if lf < heap_k[2 * p] or (lf == heap_k[2 * p] and lg > heap_k[2 * p + 1]):
                    heap_k[2 * i] = heap_k[2 * p]
                    heap_k[2 * i + 1] = heap_k[2 * p + 1]
                    heap_n[i] = heap_n[p]
                    pos[heap_n[i]] = i + 1
                    i = p
                else:
                    break
            heap_k[2 * i], heap_k[2 * i + 1], heap_n[i] = lf, lg, ln
            pos[ln] = i + 1
        if node == goal:
            found = True
            break
        y = node // width
        x = node - y * width
        border = x == 0 or y == 0 or x == width - 1 or y == height - 1
        for k in range(8):
            nx = x + dxs[k]
            ny = y + dys[k]
            if border and (nx < 0 or ny < 0 or nx >= width or ny >= height):
                continue
            nb = node + offsets[k]
            slot = pos[nb] if seen[nb] else 0
            if slot < 0:
                continue
            c_nb = int(grid[nb])
            if marks > 0 and c_nb < least[nb] and c_nb < lethal:
                return False, np.zeros((0, 2), dtype=np.int64), 0, 0, np.inf, expansions, nb
            if c_nb >= lethal:
                if not _escapes(nx, ny, sx, sy, escape_r2):
                    continue
                c_nb = MAX_NON_OBSTACLE
            step = 1.0
            if k >= 4:
                # no corner cutting: both cells the diagonal passes between must be enterable
                if grid[node + dxs[k]] >= lethal and not _escapes(nx, y, sx, sy, escape_r2):
                    continue
                if grid[node + dys[k] * width] >= lethal and not _escapes(x, ny, sx, sy, escape_r2):
                    continue
                step = SQRT2
            step *= 1.0 + scale * c_nb
            if use_lanes:
                d = lane[nb]
                if (
                    (d == 1 and dxs[k] < 0)
                    or (d == 2 and dxs[k] > 0)
                    or (d == 3 and dys[k] < 0)
                    or (d == 4 and dys[k] > 0)
                ):
                    step *= against
            ng = node_g + step
            if slot > 0 and ng >= g[nb]:
                continue
            hx, hy = abs(nx - gx), abs(ny - gy)
            h = (hx + hy) + (SQRT2 - 2.0) * min(hx, hy)
            if marks > 0:
                bound = _landmark_bound(fields, nb, goal_marks)
                if bound < 0:
                    pos[nb] = -1  # cut off from the goal: never open it
                    seen[nb] = True
                    continue
                h = max(h, bound * field_scale)
            g[nb] = ng
            parent[nb] = k
            nf = math.floor((ng + h) * _F_STEPS + 0.5) / _F_STEPS
            if slot == 0:
                i = size
                size += 1
            else:
                i = slot - 1  # decrease-key: the key only falls, so sift up
            while i > 0:
                p = (i - 1) // 2
                if nf < heap_k[2 * p] or (nf == heap_k[2 * p] and ng > heap_k[2 * p + 1]):
                    heap_k[2 * i], heap_k[2 * i + 1], heap_n[i] = (
                        heap_k[2 * p],
                        heap_k[2 * p + 1],
                        heap_n[p],
                    )
                    pos[heap_n[i]] = i + 1
                    i = p
                else:
                    break
            heap_k[2 * i], heap_k[2 * i + 1], heap_n[i] = nf, ng, nb
            pos[nb] = i + 1
            seen[nb] = True
    if not found:
        return False, np.zeros((0, 2), dtype=np.int64), 0, 0, np.inf, expansions, -1
    count = 1
    node = goal
    while node != start:
        node -= offsets[parent[node]]
        count += 1
    path = np.empty((count, 2), dtype=np.int64)
    node = goal
    diagonal = 0
    for i in range(count - 1, -1, -1):
        path[i, 0] = node % width
        path[i, 1] = node // width
        if i > 0:
            diagonal += parent[node] >= 4
            node -= offsets[parent[node]]
    return True, path, count - 1 - diagonal, diagonal, g[goal], expansions, -1


def _landmark_bound_py(
    fields: npt.NDArray[np.int32], cell: int, goal_marks: npt.NDArray[np.int32]
) -> int:
    """The largest ``|D_k[goal] - D_k[cell]|`` (stored units); -1 if ``cell`` is cut off.

    Every landmark lies in the same connected region, so a cell is reached by all of
    them or by none: one field tells which, and the loop over the rest has no branch.
    """
    first = fields[cell, 0]
    if (first == UNREACHED) != (goal_marks[0] == UNREACHED):
        return -1
    if first == UNREACHED:
        return 0
    best = np.int32(0)
    for f in range(goal_marks.shape[0]):
        best = max(best, abs(goal_marks[f] - fields[cell, f]))
    return int(best)


def _escapes_py(x: int, y: int, sx: int, sy: int, r2: int) -> bool:
    """Whether cell ``(x, y)`` lies within the start's escape disc."""
    ex, ey = x - sx, y - sy
    return ex * ex + ey * ey <= r2


def _line_ok_py(cost: UInt8Array, ax: int, ay: int, bx: int, by: int, cap: int) -> bool:
    """Whether every cell the segment between two cell centres touches costs <= cap.

    Exact integer walk: the segment crosses an x boundary after ``(0.5 + i) / |dx|`` and
    a y boundary after ``(0.5 + j) / |dy|`` of its length; through a corner exactly, both
    cells beside the corner count as touched.
    """
    ddx, ddy = abs(bx - ax), abs(by - ay)
    sx = 1 if bx > ax else -1
    sy = 1 if by > ay else -1
    x, y, i, j = ax, ay, 0, 0
    while i < ddx or j < ddy:
        tx = (1 + 2 * i) * ddy
        ty = (1 + 2 * j) * ddx
        if tx < ty:
            x += sx
            i += 1
        elif ty < tx:
            y += sy
            j += 1
        else:
            if cost[y, x + sx] > cap or cost[y + sy, x] > cap:
                return False
            x += sx
            y += sy
            i += 1
            j += 1
        if cost[y, x] > cap:
            return False
    return True


def _prune_py(cost: UInt8Array, cells: IntArray, lethal: int, keep_clearance: bool) -> IntArray:
    """Greedy line-of-sight shortcuts, then removal of collinear waypoints."""
    n = cells.shape[0]
    keep = np.zeros(n, dtype=np.bool_)
    keep[0] = True
    keep[n - 1] = True
    i = 0
    while i < n - 1:
        j = i + 1
        worst = max(cost[cells[i, 1], cells[i, 0]], cost[cells[j, 1], cells[j, 0]])
        while j + 1 < n:
            worst_next = max(worst, cost[cells[j + 1, 1], cells[j + 1, 0]])
            if worst_next >= lethal:
                break  # no shortcut across the escape from a blocked start
            cap = worst_next if keep_clearance else lethal - 1
            if not _line_ok(cost, cells[i, 0], cells[i, 1], cells[j + 1, 0], cells[j + 1, 1], cap):
                break
            worst = worst_next
            j += 1
        keep[j] = True
        i = j
    kept = cells[keep]
    m = kept.shape[0]
    out = np.empty((m, 2), dtype=np.int64)
    out[0] = kept[0]
    count = 1
    for k in range(1, m - 1):
        ax, ay = kept[k, 0] - out[count - 1, 0], kept[k, 1] - out[count - 1, 1]
        bx, by = kept[k + 1, 0] - kept[k, 0], kept[k + 1, 1] - kept[k, 1]
        if ax * by - ay * bx != 0 or ax * bx + ay * by <= 0:
            out[count] = kept[k]
            count += 1
    if m > 1:
        out[count] = kept[m - 1]
        count += 1
    return out[:count].copy()


# numba resolves the helpers when a kernel is first compiled, so their order is free
_escapes: Any = numba.njit(cache=True, nogil=True)(_escapes_py)
_landmark_bound: Any = numba.njit(cache=True, nogil=True, inline="always")(_landmark_bound_py)
_line_ok: Any = numba.njit(cache=True, nogil=True)(_line_ok_py)
escape_r2: Any = numba.njit(cache=True, nogil=True)(_escape_r2_py)
astar: Any = numba.njit(cache=True, nogil=True)(_astar_py)
prune: Any = numba.njit(cache=True, nogil=True)(_prune_py)
