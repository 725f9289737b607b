import math

import numpy as np

from models.mapping.grid import LogOddsMap, MapGeometry
from models.mapping.matcher import scan_points
from models.mapping.uncertainty import ResponseWindow, match_covariance
from tests.models.mapping.conftest import GEOMETRY, Lidar, integrate, room_map

# a featureless corridor along x: two walls 2.4 m apart, 40 m long
CORRIDOR = np.array([[-20.0, -1.4, 20.0, -1.2], [-20.0, 1.2, 20.0, 1.4]])


def _spread(grid: LogOddsMap, lidar: Lidar, pose, window=None):
    window = window or ResponseWindow()
    points = scan_points(lidar.angles, lidar.scan(pose), 0.1, 10.0, 180)
    covariance = match_covariance(grid, pose, points, window)
    return covariance, np.sqrt(np.linalg.eigvalsh(covariance[:2, :2]))


def test_a_match_in_a_room_is_sure_every_way(lidar):
    grid = room_map()
    for seen_from in ((2.0, 6.0, 0.0), (10.0, 3.0, 1.0)):
        integrate(grid, lidar, seen_from)
    _, sigmas = _spread(grid, lidar, (6.03, 3.02, 0.2))
    assert sigmas.max() < 0.06


def test_a_match_in_a_corridor_is_sure_across_it_and_unsure_along_it():
    lidar = Lidar(CORRIDOR)
    grid = LogOddsMap(MapGeometry.covering((-20.0, -1.4, 20.0, 1.4), 0.05, 1.0))
    for seen_from in ((-4.0, 0.1, 0.0), (4.0, -0.1, 0.05)):  # mapped from elsewhere
        grid.integrate(seen_from, lidar.angles, lidar.scan(seen_from), range_min_m=0.1,
                       range_max_m=10.0, clear_no_return_m=3.0)  # fmt: skip
    covariance, sigmas = _spread(grid, lidar, (0.33, 0.05, 0.01))
    along, across = math.sqrt(covariance[0, 0]), math.sqrt(covariance[1, 1])
    assert along > 0.25 and across < 0.05  # the whole window along it fits as well
    assert sigmas.max() / sigmas.min() > 5


def test_the_floors_bound_the_spread_below(lidar):
    grid = room_map()
    pose = (6.0, 3.0, 0.2)
    integrate(grid, lidar, pose)
    floors = ResponseWindow(floor_m=0.1, floor_rad=0.05)
    covariance, sigmas = _spread(grid, lidar, pose, floors)
    assert sigmas.min() >= 0.1 and math.sqrt(covariance[2, 2]) >= 0.05
    assert GEOMETRY.beams == len(lidar.angles)
