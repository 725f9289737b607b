import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.navigation.traffic import TrafficParams, moving_points


def _numpy_moving_points(points, start, poses, distance, origin, resolution, margin):
    """The moving points in numpy terms (numpy's promotion rules decide the comparisons)."""
    owner = np.repeat(np.arange(len(start) - 1), np.diff(start))
    cells = np.floor((points - np.asarray(origin)) / resolution).astype(np.int64)
    rows, cols = distance.shape[-2:]
    inside = (cells[:, 0] >= 0) & (cells[:, 0] < cols) & (cells[:, 1] >= 0)
    inside &= cells[:, 1] < rows
    clear = np.zeros(len(points), dtype=bool)
    if distance.ndim == 3:
        d = distance[owner[inside], cells[inside, 1], cells[inside, 0]]
    else:
        d = distance[cells[inside, 1], cells[inside, 0]]
    clear[inside] = d > margin
    owner = owner[clear]
    x, y, yaw = poses[owner].T
    dx, dy = points[clear, 0] - x, points[clear, 1] - y
    ahead = dx * np.cos(yaw) + dy * np.sin(yaw)
    side = -dx * np.sin(yaw) + dy * np.cos(yaw)
    return owner, points[clear], ahead, side


@settings(max_examples=60, deadline=None)
@given(robots=st.integers(1, 5), own_maps=st.booleans(), seed=st.integers(0, 2**32 - 1))
def test_moving_points_match_their_numpy_formulation_bit_for_bit(robots, own_maps, seed):
    rng = np.random.default_rng(seed)
    counts = rng.integers(0, 30, robots)
    start = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    points = rng.uniform(-1.0, 7.0, (int(start[-1]), 2))  # some outside the 6 m x 5 m grid
    poses = np.column_stack(
        [rng.uniform(0, 6, robots), rng.uniform(0, 5, robots), rng.uniform(-7, 7, robots)]
    )
    shape = (robots, 50, 60) if own_maps else (50, 60)
    distance = rng.uniform(0.0, 0.4, shape).astype(np.float32)
    distance.flat[::7] = np.float32(0.2)  # ties with the margin, compared in float32
    params = TrafficParams(static_margin_m=0.2)
    got = moving_points(points, start, poses, distance, (0.0, 0.0), 0.1, params)
    want = _numpy_moving_points(points, start, poses, distance, (0.0, 0.0), 0.1, 0.2)
    for a, b in zip(got, want, strict=True):
        np.testing.assert_array_equal(a, b)
        assert a.dtype == b.dtype


def test_moving_points_are_the_hits_away_from_static_obstacles_in_their_owners_frames():
    distance = np.full((10, 10), 1.0, dtype=np.float32)
    distance[:, 0] = 0.0  # a wall along x = 0
    points = np.array([[0.05, 0.5], [0.5, 0.8], [2.0, 0.5]])  # the wall, ahead-left, outside
    start = np.array([0, 3], dtype=np.int64)
    pose = np.array([[0.5, 0.5, math.pi / 2]])  # facing +y
    moving = moving_points(points, start, pose, distance, (0.0, 0.0), 0.1, TrafficParams())
    assert list(moving.owner) == [0]
    assert moving.points == pytest.approx(np.array([[0.5, 0.8]]))
    assert moving.ahead == pytest.approx([0.3])
    assert moving.side == pytest.approx([0.0])
