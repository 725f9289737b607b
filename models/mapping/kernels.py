"""Compiled inner loops of mapping: scan integration and score upkeep (numba).

Kept apart from :mod:`models.mapping.grid` so that the class reads as the model and this
file as the arithmetic. Every function works on whole arrays in place; none allocates
per call beyond a few scalars.
"""

from __future__ import annotations

import math
from typing import Any

import numba

from models.geometry.occupancy import FREE, OCCUPIED, UNKNOWN


def _traverse_py(
    stamp: Any,
    scan: int,
    ox: float,
    oy: float,
    res: float,
    x: float,
    y: float,
    yaw: float,
    angles: Any,
    ranges: Any,
    range_min: float,
    range_max: float,
    clear_m: float,
    cells: Any,
    hits: Any,
    means: Any,
    counts: Any,
) -> int:
    """The cells one scan updates, each once: returns first (hit), then crossed cells (miss).

    Writes ``iy * width + ix`` into ``cells`` and whether it is a return into ``hits``;
    returns how many. ``stamp`` marks the cells this scan (number ``scan``) has listed.
    Every return (two in one cell both) is also folded into its cell's mean position in
    ``means`` and ``counts`` (:func:`_fold_hit_py`), unless those are empty.
    """
    height, width = stamp.shape
    keep_hits = counts.shape[0] > 0
    n = 0
    # returns first: a cell with a return is occupied evidence even if another beam crosses it
    for b in range(ranges.shape[0]):
        r = ranges[b]
        if not (r >= range_min) or not (r <= range_max):
            continue
        a = yaw + angles[b]
        hx = (x + r * math.cos(a) - ox) / res
        hy = (y + r * math.sin(a) - oy) / res
        ix = math.floor(hx)
        iy = math.floor(hy)
        if ix < 0 or iy < 0 or ix >= width or iy >= height:
            continue
        if keep_hits:
            _fold_hit(means, counts, ix, iy, hx - ix, hy - iy)
        if stamp[iy, ix] == scan:
            continue
        stamp[iy, ix] = scan
        cells[n] = iy * width + ix
        hits[n] = True
        n += 1
    cx0 = math.floor((x - ox) / res)
    cy0 = math.floor((y - oy) / res)
    fx = (x - ox) / res
    fy = (y - oy) / res
    for b in range(ranges.shape[0]):
        r = ranges[b]
        if not (r >= range_min):  # NaN (dropout) or too near: no information
            continue
        returned = r <= range_max
        length = r if returned else clear_m
        if length <= 0.0:
            continue
        a = yaw + angles[b]
        dx = math.cos(a)
        dy = math.sin(a)
        end_x = math.floor((x + length * dx - ox) / res)
        end_y = math.floor((y + length * dy - oy) / res)
        # Amanatides-Woo traversal of the cells the beam crosses, in cell units
        ix, iy = cx0, cy0
        step_x = 1 if dx > 0 else -1
        step_y = 1 if dy > 0 else -1
        t_max_x = ((ix + (1 if dx > 0 else 0)) - fx) / dx if dx != 0 else math.inf
        t_max_y = ((iy + (1 if dy > 0 else 0)) - fy) / dy if dy != 0 else math.inf
        t_dx = abs(1.0 / dx) if dx != 0 else math.inf
        t_dy = abs(1.0 / dy) if dy != 0 else math.inf
        limit = length / res
        while True:
            at_end = ix == end_x and iy == end_y
            if returned and at_end:
                break  # the return's own cell is not crossed
            if ix < 0 or iy < 0 or ix >= width or iy >= height:
                break
            if stamp[iy, ix] != scan:
                stamp[iy, ix] = scan
                cells[n] = iy * width + ix
                hits[n] = False
                n += 1
            if at_end:
                break
            # an axis already at the end cell's index is not stepped again: a component of
            # the direction too small to move the end point (its floor computed in floats)
            # would otherwise step the chain off the end cell for good
            along_x = t_max_x < t_max_y
            if ix == end_x and iy != end_y:
                along_x = False
            elif iy == end_y and ix != end_x:
                along_x = True
            if along_x:
                if t_max_x > limit:
                    break
                t_max_x += t_dx
                ix += step_x
            else:
                if t_max_y > limit:
                    break
                t_max_y += t_dy
                iy += step_y
    return n


def _fold_hit_py(means: Any, counts: Any, ix: int, iy: int, dx: float, dy: float) -> None:
    """Fold one return into its cell's mean offset ``(dx, dy)`` (cells, 0-1 each way).

    ``means[iy, ix]`` is the mean offset of the cell's returns from its lower-left corner
    in 255ths of a cell each way (0.2 mm at 5 cm cells), ``counts[iy, ix]`` how many it
    holds, up to 255. A return moves the stored mean only if its share of the difference,
    ``(offset - mean) / n``, rounds to at least one 255th: a cell of n returns ignores one
    closer than about ``n / 510`` cells to its mean (half a cell when full), so a cell's
    mean settles as its returns add up.
    """
    n = min(int(counts[iy, ix]) + 1, 255)
    for k, offset in ((0, dx), (1, dy)):
        mean = means[iy, ix, k] / 255.0
        mean += (offset - mean) / n
        means[iy, ix, k] = min(255, max(0, round(mean * 255.0)))
    counts[iy, ix] = n


def _apply_py(
    logodds: Any,
    cells: Any,
    hits: Any,
    n: int,
    hit: float,
    miss: float,
    lo: float,
    hi: float,
    occupied: float,
    flips: Any,
    changes: Any,
) -> int:
    """Add a scan's listed updates to a map, clamped; list the cells whose state flipped.

    The changes actually made are also added to ``changes`` unless it is empty (a robot's
    evidence not yet sent to its neighbours). Returns the number of flips, or -1 when
    ``flips`` overflowed (the caller then rebuilds the scores from scratch).
    """
    width = logodds.shape[1]
    track = changes.shape[0] > 0
    count = 0
    capacity = flips.shape[0]
    overflow = False
    for k in range(n):
        f = cells[k]
        iy = f // width
        ix = f - iy * width
        old = logodds[iy, ix]
        new = min(hi, max(lo, old + (hit if hits[k] else miss)))
        logodds[iy, ix] = new
        if track:
            changes[iy, ix] += new - old
        if (old >= occupied) != (new >= occupied):
            if count < capacity:
                flips[count] = f
                count += 1
            else:
                overflow = True
    return -1 if overflow else count


def _recompute_score_py(
    logodds: Any, score: Any, kernel: Any, iy: int, ix: int, occ: float
) -> None:
    """The fine score of one cell: the kernel's maximum over occupied cells around it."""
    height, width = logodds.shape
    r = kernel.shape[0] // 2
    best = 0
    for ky in range(-r, r + 1):
        y = iy + ky
        if y < 0 or y >= height:
            continue
        for kx in range(-r, r + 1):
            xx = ix + kx
            if xx < 0 or xx >= width:
                continue
            v = kernel[ky + r, kx + r]
            if v > best and logodds[y, xx] >= occ:
                best = v
    score[iy, ix] = best


def _max4_py(row: Any, x: int) -> int:
    """The largest of ``row[x:x + 4]``."""
    return max(max(row[x], row[x + 1]), max(row[x + 2], row[x + 3]))  # type: ignore[no-any-return]


def _refresh_coarse_py(score: Any, coarse: Any, iy: int, ix: int, c: int) -> None:
    """The coarse score of one cell: the largest fine score of the c x c cells from it."""
    height, width = score.shape
    best = 0
    for y in range(iy, min(iy + c, height)):
        for x in range(ix, min(ix + c, width)):
            if score[y, x] > best:
                best = score[y, x]
    coarse[iy, ix] = best


def _refresh_scores_py(
    logodds: Any,
    score: Any,
    coarse: Any,
    kernel: Any,
    flips: Any,
    occ: float,
    c: int,
    dirty: Any,
) -> int:
    """Bring the scores up to date around flipped cells; return the net occupied change.

    ``dirty`` is an all-zero uint8 grid on entry and on return: it marks each cell to
    recompute once, however many flipped cells' windows overlap there (a robot seen and
    then gone flips a blob of neighbouring cells).
    """
    height, width = logodds.shape
    r = kernel.shape[0] // 2
    net = 0
    # cleared cells: mark the cells whose score may have come from them. A cell scoring
    # more than a cleared cell gave it keeps its score: the occupied cell that gave it is
    # still there (were it cleared too, the cell would score no more than it gave)
    for f in flips:
        iy, ix = f // width, f % width
        if logodds[iy, ix] >= occ:
            net += 1
            continue
        net -= 1
        for y in range(max(0, iy - r), min(height, iy + r + 1)):
            for x in range(max(0, ix - r), min(width, ix + r + 1)):
                given = kernel[y - iy + r, x - ix + r]
                if given > 0 and score[y, x] <= given:
                    dirty[y, x] |= 1
    for f in flips:
        iy, ix = f // width, f % width
        if logodds[iy, ix] >= occ:
            continue
        for y in range(max(0, iy - r), min(height, iy + r + 1)):
            for x in range(max(0, ix - r), min(width, ix + r + 1)):
                if dirty[y, x] & 1:
                    _recompute_score(logodds, score, kernel, y, x, occ)
                    dirty[y, x] &= 2
    # new occupied cells: their kernel raises the scores around them
    for f in flips:
        iy, ix = f // width, f % width
        if logodds[iy, ix] < occ:
            continue
        for ky in range(-r, r + 1):
            y = iy + ky
            if y < 0 or y >= height:
                continue
            for kx in range(-r, r + 1):
                x = ix + kx
                if 0 <= x < width and kernel[ky + r, kx + r] > score[y, x]:
                    score[y, x] = kernel[ky + r, kx + r]
    # coarse cells whose window holds a changed fine cell: each refreshed when first met
    # (every fine score is final by now), then the marks cleared window by window
    for f in flips:
        iy, ix = f // width, f % width
        for y in range(max(0, iy - r - c + 1), min(height, iy + r + 1)):
            for x in range(max(0, ix - r - c + 1), min(width, ix + r + 1)):
                if dirty[y, x] & 2:
                    continue
                dirty[y, x] |= 2
                if c == 4 and y + 4 <= height and x + 4 <= width:  # the default, unrolled
                    top = max(_max4(score[y], x), _max4(score[y + 1], x))
                    coarse[y, x] = max(top, _max4(score[y + 2], x), _max4(score[y + 3], x))
                else:
                    _refresh_coarse(score, coarse, y, x, c)
    for f in flips:
        iy, ix = f // width, f % width
        y0, x0 = max(0, iy - r - c + 1), max(0, ix - r - c + 1)
        dirty[y0 : min(height, iy + r + 1), x0 : min(width, ix + r + 1)] = 0
    return net


def _rebuild_scores_py(
    logodds: Any, score: Any, coarse: Any, kernel: Any, occ: float, c: int
) -> int:
    """Recompute both scores from the log-odds; return the number of occupied cells."""
    height, width = logodds.shape
    r = kernel.shape[0] // 2
    score[:, :] = 0
    count = 0
    for iy in range(height):
        for ix in range(width):
            if logodds[iy, ix] < occ:
                continue
            count += 1
            for ky in range(-r, r + 1):
                y = iy + ky
                if y < 0 or y >= height:
                    continue
                for kx in range(-r, r + 1):
                    x = ix + kx
                    if 0 <= x < width and kernel[ky + r, kx + r] > score[y, x]:
                        score[y, x] = kernel[ky + r, kx + r]
    for iy in range(height):
        for ix in range(width):
            _refresh_coarse(score, coarse, iy, ix, c)
    return count


def _classify_py(logodds: Any, free: Any, occupied: Any, cells: Any) -> None:
    """Trinary cells of a log-odds grid: 100 from ``occupied`` on, 0 up to ``free``, else -1."""
    height, width = logodds.shape
    for iy in range(height):
        for ix in range(width):
            v = logodds[iy, ix]
            cells[iy, ix] = OCCUPIED if v >= occupied else (FREE if v <= free else UNKNOWN)


_fold_hit: Any = numba.njit(cache=True, nogil=True, inline="always")(_fold_hit_py)
traverse: Any = numba.njit(cache=True, nogil=True)(_traverse_py)
classify: Any = numba.njit(cache=True, nogil=True)(_classify_py)
apply: Any = numba.njit(cache=True, nogil=True)(_apply_py)
_recompute_score: Any = numba.njit(cache=True, nogil=True)(_recompute_score_py)
_max4: Any = numba.njit(cache=True, nogil=True, inline="always")(_max4_py)
_refresh_coarse: Any = numba.njit(cache=True, nogil=True)(_refresh_coarse_py)
refresh_scores: Any = numba.njit(cache=True, nogil=True)(_refresh_scores_py)
rebuild_scores: Any = numba.njit(cache=True, nogil=True)(_rebuild_scores_py)

__all__ = ["apply", "rebuild_scores", "refresh_scores", "traverse"]
