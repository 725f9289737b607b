"""Refining a match on the walls: exact scans end where they were taken, off cell centres."""

import math

import numpy as np
import pytest

from models.mapping.grid import LogOddsMap, MapGeometry
from models.mapping.matcher import MatcherParams, match, scan_points
from models.mapping.walls import refine_on_walls
from tests.models.mapping.conftest import ROOM, Lidar, integrate

SHIFT = np.array([0.017, 0.031, 0.017, 0.031])
"""The room moved off the grid's lines: its walls lie inside cells, not on their edges."""
TRUE = (6.013, 3.522, 0.4)


def _mapped(hit_centroids: bool) -> tuple[LogOddsMap, Lidar]:
    lidar = Lidar(ROOM + SHIFT)
    grid = LogOddsMap(
        MapGeometry.covering((-0.2, -0.2, 12.3, 8.3), 0.05, 1.0), hit_centroids=hit_centroids
    )
    for pose in [(2.0, 6.5, 0.0), (6.0, 4.0, 1.0), (10.5, 6.5, 2.0), (8.0, 2.5, -1.0)]:
        integrate(grid, lidar, pose)
    return grid, lidar


def _error(pose: tuple[float, float, float]) -> tuple[float, float]:
    return math.hypot(pose[0] - TRUE[0], pose[1] - TRUE[1]), abs(pose[2] - TRUE[2])


@pytest.mark.parametrize("offset", [(0.0, 0.0, 0.0), (0.12, -0.09, 0.03), (-0.2, 0.17, -0.06)])
def test_an_exact_scan_is_placed_within_a_few_millimetres_of_where_it_was_taken(offset):
    grid, lidar = _mapped(hit_centroids=True)
    points = scan_points(lidar.angles, lidar.scan(TRUE), 0.1, 10.0, 240)
    prior = (TRUE[0] + offset[0], TRUE[1] + offset[1], TRUE[2] + offset[2])
    result = match(grid, prior, points, MatcherParams(refine_against="walls"))
    metres, radians = _error(result.pose)
    assert result.matched and metres < 0.005 and radians < 0.002


def test_the_score_refine_leaves_an_exact_scan_off_by_more_than_the_walls_refine():
    grid, lidar = _mapped(hit_centroids=True)
    points = scan_points(lidar.angles, lidar.scan(TRUE), 0.1, 10.0, 240)
    on_score = match(grid, TRUE, points, MatcherParams(refine_against="score")).pose
    on_walls = match(grid, TRUE, points, MatcherParams(refine_against="walls")).pose
    assert _error(on_walls)[0] < 0.002 < _error(on_score)[0]


def test_a_map_that_does_not_keep_its_returns_is_refused_naming_what_it_needs():
    grid, lidar = _mapped(hit_centroids=False)
    points = scan_points(lidar.angles, lidar.scan(TRUE), 0.1, 10.0, 240)
    with pytest.raises(ValueError, match="hit_centroids=True"):
        refine_on_walls(grid, points, TRUE, 8)


def test_with_too_few_points_on_walls_the_pose_is_left_as_it_is():
    grid, _ = _mapped(hit_centroids=True)
    few = np.array([[1.0, 0.0], [0.0, 1.0]])
    assert refine_on_walls(grid, few, TRUE, 8) == TRUE
