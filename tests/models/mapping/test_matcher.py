import math

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
