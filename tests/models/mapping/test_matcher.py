import math
from typing import Any

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.mapping.grid import COARSE
from models.mapping.matcher import MatcherParams, _search, match, scan_points
from tests.models.mapping.conftest import ROOM, Lidar, integrate, room_map

TRUE = (6.0, 3.5, 0.4)


def _mapped_room() -> tuple:
    lidar = Lidar(ROOM)
    grid = room_map()
    for pose in [(2.0, 6.5, 0.0), (6.0, 4.0, 1.0), (10.5, 6.5, 2.0), (8.0, 2.5, -1.0)]:
        integrate(grid, lidar, pose)
    return grid, lidar


def _points(lidar: Lidar, pose: tuple[float, float, float]) -> np.ndarray:
    return scan_points(lidar.angles, lidar.scan(pose), 0.1, 10.0, 240)


@pytest.mark.parametrize("offset", [(0.17, -0.12, 0.05), (-0.25, 0.2, -0.1), (0.0, 0.0, 0.0)])
def test_a_scan_taken_off_the_prior_is_placed_where_it_was_taken(offset):
    grid, lidar = _mapped_room()
    prior = (TRUE[0] + offset[0], TRUE[1] + offset[1], TRUE[2] + offset[2])
    result = match(grid, prior, _points(lidar, TRUE), MatcherParams())
    assert result.matched and result.score > 0.8
    assert math.hypot(result.pose[0] - TRUE[0], result.pose[1] - TRUE[1]) < 0.02
    assert abs(result.pose[2] - TRUE[2]) < 0.005


def test_without_a_map_or_points_the_prior_stands():
    grid, lidar = _mapped_room()
    empty = room_map()
    assert match(empty, TRUE, _points(lidar, TRUE), MatcherParams()).matched is False
    assert match(grid, TRUE, np.zeros((0, 2)), MatcherParams()).pose == TRUE


def test_a_scan_of_another_place_does_not_match():
    grid, _ = _mapped_room()
    elsewhere = Lidar(np.array([[0.0, 0.0, 0.5, 9.0], [4.0, 0.0, 4.5, 9.0]]))
    result = match(grid, TRUE, _points(elsewhere, (2.0, 4.0, 0.0)), MatcherParams(min_score=0.5))
    assert not result.matched and result.pose == TRUE


def _brute_force(grid, prior, points, offsets, n_lin, penalty):
    g = grid.geometry
    best = -1.0
    n_rot = len(offsets)
    for a, da in enumerate(offsets):
        c, s = math.cos(prior[2] + da), math.sin(prior[2] + da)
        bx = np.floor(
            (prior[0] + c * points[:, 0] - s * points[:, 1] - g.origin_xy_m[0]) / g.resolution_m
        )
        by = np.floor(
            (prior[1] + s * points[:, 0] + c * points[:, 1] - g.origin_xy_m[1]) / g.resolution_m
        )
        for ky in range(-n_lin, n_lin + 1):
            for kx in range(-n_lin, n_lin + 1):
                cx, cy = (bx + kx).astype(int), (by + ky).astype(int)
                ok = (cx >= 0) & (cy >= 0) & (cx < g.width) & (cy < g.height)
                total = grid.score[cy[ok], cx[ok]].astype(float).sum()
                d2 = 0.5 * (
                    (kx * kx + ky * ky) / n_lin**2 + (a - n_rot // 2) ** 2 / (n_rot // 2) ** 2
                )
                best = max(best, total / (255 * len(points)) * (1 - penalty * d2))
    return best


@settings(max_examples=10, deadline=None)
@given(
    dx=st.floats(-0.2, 0.2), dy=st.floats(-0.2, 0.2), dyaw=st.floats(-0.05, 0.05),
    seed=st.integers(0, 1000),
)  # fmt: skip
def test_branch_and_bound_finds_the_exhaustive_search_optimum(dx, dy, dyaw, seed):
    grid, lidar = _mapped_room()
    rng = np.random.default_rng(seed)
    points = _points(lidar, TRUE)[rng.choice(240, 60, replace=False)]
    prior = (TRUE[0] + dx, TRUE[1] + dy, TRUE[2] + dyaw)
    offsets = np.linspace(-0.04, 0.04, 9)
    n_lin = 5
    g = grid.geometry
    *_, score, _ = _search(
        grid.score, grid.coarse, g.origin_xy_m[0], g.origin_xy_m[1], g.resolution_m,
        points[:, 0].copy(), points[:, 1].copy(), *prior, offsets, n_lin, COARSE, 0.1, 0.0,
    )  # fmt: skip
    assert score == pytest.approx(_brute_force(grid, prior, points, offsets, n_lin, 0.1))


# The search as it was written first, translation by translation over every point: the
# reference the point-by-point sums (fewer cache misses, no checks inside the grid) must
# equal, result for result, ties and effort included.
def _search_by_translation_py(
    fine: Any,
    coarse: Any,
    ox: float,
    oy: float,
    res: float,
    px: Any,
    py: Any,
    x0: float,
    y0: float,
    yaw0: float,
    offsets: Any,
    n_lin: int,
    c: int,
    penalty: float,
    margin: float,
) -> tuple[int, int, int, float, int]:
    """Branch and bound over (rotation, translation block, translation)."""
    height, width = fine.shape
    n_pts = px.shape[0]
    n_rot = offsets.shape[0]
    span = 2 * n_lin + 1
    blocks = (span + c - 1) // c
    # the cell each point falls in at zero translation, per rotation
    bx = np.empty((n_rot, n_pts), dtype=np.int64)
    by = np.empty((n_rot, n_pts), dtype=np.int64)
    for a in range(n_rot):
        ca = math.cos(yaw0 + offsets[a])
        sa = math.sin(yaw0 + offsets[a])
        for i in range(n_pts):
            bx[a, i] = math.floor((x0 + ca * px[i] - sa * py[i] - ox) / res)
            by[a, i] = math.floor((y0 + sa * px[i] + ca * py[i] - oy) / res)
    # the bound of every (rotation, block): sum of coarse scores at the block's corner
    n_nodes = n_rot * blocks * blocks
    bounds = np.empty(n_nodes, dtype=np.float64)
    for a in range(n_rot):
        for bj in range(blocks):
            for bi in range(blocks):
                kx = -n_lin + bi * c
                ky = -n_lin + bj * c
                total = 0
                for i in range(n_pts):
                    cx = bx[a, i] + kx
                    cy = by[a, i] + ky
                    # a window hanging over the low edge is bounded by the edge's window
                    if -c < cx < 0:
                        cx = 0
                    if -c < cy < 0:
                        cy = 0
                    if 0 <= cx < width and 0 <= cy < height:
                        total += int(coarse[cy, cx])
                bounds[(a * blocks + bj) * blocks + bi] = total / (255.0 * n_pts)
    order = np.argsort(-bounds)
    # the prior itself (no translation, middle rotation) is the first candidate: another
    # must beat it by ``margin`` to be chosen, so equal scores keep the odometry
    center = n_rot // 2
    total = 0
    for i in range(n_pts):
        cx = bx[center, i]
        cy = by[center, i]
        if 0 <= cx < width and 0 <= cy < height:
            total += int(fine[cy, cx])
    best = total / (255.0 * n_pts) + margin
    best_kx, best_ky, best_a = 0, 0, center
    evaluated = 1
    w_lin = float(n_lin) * n_lin
    w_rot = float(n_rot // 2) * (n_rot // 2) if n_rot > 1 else 1.0
    for node in order:
        if bounds[node] <= best:
            break
        a = node // (blocks * blocks)
        bj = (node // blocks) % blocks
        bi = node % blocks
        da = a - n_rot // 2
        for ky in range(-n_lin + bj * c, min(-n_lin + bj * c + c, n_lin + 1)):
            for kx in range(-n_lin + bi * c, min(-n_lin + bi * c + c, n_lin + 1)):
                total = 0
                for i in range(n_pts):
                    cx = bx[a, i] + kx
                    cy = by[a, i] + ky
                    if 0 <= cx < width and 0 <= cy < height:
                        total += int(fine[cy, cx])
                evaluated += 1
                d2 = 0.5 * ((kx * kx + ky * ky) / w_lin + da * da / w_rot)
                score = total / (255.0 * n_pts) * (1.0 - penalty * d2)
                if score > best:
                    best = score
                    best_kx, best_ky, best_a = kx, ky, a
    if best_kx == 0 and best_ky == 0 and best_a == center:
        best -= margin
    return best_kx, best_ky, best_a, best, evaluated


_search_by_translation = numba.njit(_search_by_translation_py)


@pytest.mark.slow
@settings(max_examples=25, deadline=None)
@given(
    x=st.floats(-1.5, 13.5), y=st.floats(-1.5, 9.5), yaw=st.floats(-3.1, 3.1),
    n_lin=st.integers(1, 9), n_rot=st.integers(1, 12), seed=st.integers(0, 1000),
)  # fmt: skip
def test_the_search_summed_point_by_point_equals_the_search_translation_by_translation(
    x, y, yaw, n_lin, n_rot, seed
):
    """Priors across the room and off its grid: points off the grid and on its edges too."""
    grid, lidar = _mapped_room()
    rng = np.random.default_rng(seed)
    points = _points(lidar, TRUE)[rng.choice(240, 120, replace=False)]
    offsets = np.linspace(-0.06, 0.06, n_rot) if n_rot > 1 else np.zeros(1)
    g = grid.geometry
    args = (
        grid.score, grid.coarse, g.origin_xy_m[0], g.origin_xy_m[1], g.resolution_m,
        points[:, 0].copy(), points[:, 1].copy(), x, y, yaw, offsets, n_lin, COARSE, 0.1, 0.02,
    )  # fmt: skip
    assert _search(*args) == _search_by_translation(*args)


@settings(max_examples=60, deadline=None)
@given(
    shape=st.tuples(st.integers(8, 50), st.integers(8, 50)),
    prior=st.tuples(st.floats(-1.0, 6.0), st.floats(-1.0, 6.0), st.floats(-3.1, 3.1)),
    n_lin=st.integers(1, 9), n_rot=st.integers(1, 7), flat=st.booleans(), seed=st.integers(0, 999),
)  # fmt: skip
def test_the_search_summed_point_by_point_breaks_ties_as_the_search_translation_by_translation(
    shape, prior, n_lin, n_rot, flat, seed
):
    """Any scores (bounds that do not bound included), few values: many equal candidates,
    of which the first one met must win; points off every edge of a small grid."""
    rng = np.random.default_rng(seed)
    fine = rng.integers(0, 3, shape).astype(np.uint8)
    coarse = rng.integers(0, 6, shape).astype(np.uint8)
    points = rng.uniform(-3.0, 3.0, (40, 2))
    offsets = np.linspace(-0.1, 0.1, n_rot) if n_rot > 1 else np.zeros(1)
    penalty, margin = (0.0, 0.0) if flat else (0.1, 0.02)
    args = (
        fine, coarse, 0.0, 0.0, 0.1, points[:, 0].copy(), points[:, 1].copy(), *prior,
        offsets, n_lin, COARSE, penalty, margin,
    )  # fmt: skip
    assert _search(*args) == _search_by_translation(*args)
