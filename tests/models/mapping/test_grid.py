import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.geometry.occupancy import FREE, OCCUPIED, UNKNOWN
from models.mapping.grid import COARSE, LogOddsMap, LogOddsParams, MapGeometry, merged
from models.mapping.kernels import rebuild_scores
from tests.models.mapping.conftest import GEOMETRY, ROOM, Lidar, integrate, room_map

POSE = (6.0, 3.0, 0.3)


def _cell(grid: LogOddsMap, x: float, y: float) -> tuple[int, int]:
    g = grid.geometry
    return (
        math.floor((y - g.origin_xy_m[1]) / g.resolution_m),
        math.floor((x - g.origin_xy_m[0]) / g.resolution_m),
    )


def test_a_scan_marks_the_walls_it_hits_and_clears_the_way_to_them(lidar):
    grid = room_map()
    integrate(grid, lidar, (6.0, 3.0, 0.0))
    p = grid.params
    # the beam straight ahead ends on the east wall's face at x = 12.0
    iy, ix = _cell(grid, 12.0, 3.0)
    assert (grid.logodds[iy, ix - 1 : ix + 1] == np.float32(p.hit)).any()
    assert grid.logodds[_cell(grid, 9.0, 3.0)] == np.float32(p.miss)
    assert grid.logodds[_cell(grid, 6.0, 3.0)] == np.float32(p.miss)
    # beyond the wall nothing changed
    assert grid.logodds[_cell(grid, 12.6, 3.0)] == 0.0


def test_every_cell_changes_at_most_once_per_scan():
    grid = room_map()
    integrate(grid, Lidar(ROOM), POSE)
    p = grid.params
    values = set(np.unique(grid.logodds).tolist())
    assert values <= {0.0, np.float32(p.hit).item(), np.float32(p.miss).item()}


def test_beams_without_a_return_clear_only_up_to_their_clearing_range():
    grid = room_map()
    ranges = np.full(GEOMETRY.beams, np.inf, dtype=np.float32)
    ranges[:10] = np.nan  # dropouts say nothing
    grid.integrate(
        POSE, GEOMETRY.angles(), ranges, range_min_m=0.1, range_max_m=10.0, clear_no_return_m=2.0
    )
    assert grid.empty, "no return is never an obstacle"
    g = grid.geometry
    ys, xs = np.nonzero(grid.logodds < 0)
    cx = g.origin_xy_m[0] + (xs + 0.5) * g.resolution_m
    cy = g.origin_xy_m[1] + (ys + 0.5) * g.resolution_m
    assert np.hypot(cx - POSE[0], cy - POSE[1]).max() <= 2.0 + g.resolution_m
    assert len(xs) > 0


def test_a_robot_that_sees_nothing_does_not_corrupt_a_map_it_built():
    lidar = Lidar(ROOM)
    grid = room_map()
    for x in (2.0, 5.0, 8.0):
        integrate(grid, lidar, (x, 6.5, 0.0))
    before = grid.occupancy()
    blind = np.full(GEOMETRY.beams, np.inf, dtype=np.float32)
    for _ in range(50):
        grid.integrate(
            (5.0, 6.5, 0.0), GEOMETRY.angles(), blind, range_min_m=0.1, range_max_m=10.0,
            clear_no_return_m=0.0,
        )  # fmt: skip
    assert np.array_equal(grid.occupancy(), before)


def test_trinary_cells_follow_the_thresholds():
    grid = room_map()
    p = grid.params
    grid.logodds[0, 0:4] = [p.occupied, p.occupied - 0.01, p.free, p.free + 0.01]
    assert grid.occupancy()[0, 0:4].tolist() == [OCCUPIED, UNKNOWN, FREE, UNKNOWN]


def _rebuilt(grid: LogOddsMap) -> tuple[np.ndarray, np.ndarray, int]:
    score = np.zeros_like(grid.score)
    coarse = np.zeros_like(grid.coarse)
    count = rebuild_scores(grid.logodds, score, coarse, grid._kernel, grid.params.occupied, COARSE)
    return score, coarse, count


@settings(max_examples=25, deadline=None)
@given(
    poses=st.lists(
        st.tuples(st.floats(0.5, 11.5), st.floats(0.5, 7.5), st.floats(-math.pi, math.pi)),
        min_size=1,
        max_size=6,
    ),
    clutter=st.lists(st.tuples(st.floats(1.0, 10.0), st.floats(1.0, 6.0)), min_size=0, max_size=4),
)
def test_scores_kept_up_cell_by_cell_equal_scores_rebuilt_from_scratch(poses, clutter):
    """Boxes that come and go (robots passing) flip cells both ways."""
    grid = room_map()
    for k, pose in enumerate(poses):
        extra = np.array([[x, y, x + 0.5, y + 0.5] for x, y in clutter]).reshape(-1, 4)
        boxes = ROOM if k % 2 else np.vstack([ROOM, extra])
        integrate(grid, Lidar(boxes), pose)
    score, coarse, count = _rebuilt(grid)
    assert np.array_equal(grid.score, score)
    assert np.array_equal(grid.coarse, coarse)
    assert grid.occupied_cells == count


def test_changes_taken_from_one_map_rebuild_its_log_odds_in_another():
    lidar = Lidar(ROOM)
    geometry = MapGeometry.covering((-0.2, -0.2, 12.2, 8.2), 0.05, 1.0)
    sender = LogOddsMap(geometry, track_changes=True)
    integrate(sender, lidar, POSE)
    integrate(sender, lidar, (3.0, 6.0, 1.0))
    changes = sender.take_changes()
    assert changes is not None and sender.take_changes() is None
    receiver = LogOddsMap(geometry)
    receiver.add_logodds(0, 0, changes)
    assert np.allclose(receiver.logodds, sender.logodds, atol=1e-6)
    score, _, _ = _rebuilt(receiver)
    assert np.array_equal(receiver.score, score)


def test_a_map_too_large_for_a_typo_is_refused():
    try:
        MapGeometry.covering((0, 0, 1000, 1000), 0.01)
    except Exception as error:
        assert "mapping.resolution_m" in str(error)
    else:
        raise AssertionError("a 10^10-cell map was accepted")


def test_the_default_update_rule_is_octomaps_with_a_weak_miss():
    p = LogOddsParams()
    assert math.isclose(p.hit, math.log(0.7 / 0.3))
    assert math.isclose(p.miss, math.log(0.48 / 0.52))
    assert math.isclose(p.occupied, math.log(0.65 / 0.35))


def test_maps_fused_one_after_the_other_equal_the_sum_of_their_stack_bit_for_bit():
    """float32 sums depend on their order: the fleet map keeps that of np.sum over axis 0."""
    rng = np.random.default_rng(7)
    geometry = MapGeometry.covering((-0.2, -0.2, 12.2, 8.2), 0.05, 1.0)
    maps = [LogOddsMap(geometry) for _ in range(12)]
    for grid in maps:
        values = rng.normal(0.0, 2.0, grid.logodds.shape).astype(np.float32)
        grid.logodds[:] = np.where(rng.random(values.shape) < 0.5, values, 0.0)
    p = maps[0].params
    # one cell whose class depends on the order: (free + 1e8) - 1e8 is 0 in float32
    maps[0].logodds[5, 5], maps[1].logodds[5, 5], maps[2].logodds[5, 5] = p.free - 1.0, 1e8, -1e8
    for grid in maps[3:]:
        grid.logodds[5, 5] = 0.0
    total = np.clip(np.sum([m.logodds for m in maps], axis=0), p.clamp_min, p.clamp_max)
    expected = np.full(total.shape, UNKNOWN, dtype=np.int8)
    expected[total <= p.free] = FREE
    expected[total >= p.occupied] = OCCUPIED
    fused = merged(maps).data
    assert np.array_equal(fused, expected)
    assert (fused == FREE).any() and (fused == OCCUPIED).any() and (fused == UNKNOWN).any()
    assert fused[5, 5] == UNKNOWN  # added the other way round it would be free


@pytest.mark.parametrize("wide", [False, True])
def test_trinary_cells_equal_those_of_numpys_comparisons_at_and_around_the_thresholds(wide):
    """numpy compares float32 log-odds with a float threshold in float32, with a float64
    one in float64; the compiled classification must do the same, at the edges too."""
    geometry = MapGeometry.covering((0.0, 0.0, 2.0, 2.0), 0.05, 0.0)
    kind = np.float64 if wide else float
    # float32(0.7) < 0.7: the cell at float32(0.7) is occupied in float64 only
    params = LogOddsParams(occupied=kind(0.7), free=kind(-0.7))
    grid = LogOddsMap(geometry, params)
    edges = []
    for t in (params.free, params.occupied):
        for v in (np.float32(t), np.float64(t)):
            edges += [np.nextafter(np.float32(v), np.float32(-9)), np.float32(v)]
            edges += [np.nextafter(np.float32(v), np.float32(9))]
    values = np.random.default_rng(2).normal(0.0, 1.0, grid.logodds.size).astype(np.float32)
    values[: len(edges)] = edges
    grid.logodds[:] = values.reshape(grid.logodds.shape)
    expected = np.full(grid.logodds.shape, UNKNOWN, dtype=np.int8)
    expected[grid.logodds <= params.free] = FREE
    expected[grid.logodds >= params.occupied] = OCCUPIED
    assert np.array_equal(grid.occupancy(), expected)


@pytest.mark.parametrize("cleared", [[(20, 20)], [(20, 20), (20, 21)], [(20, 21), (22, 20)]])
def test_cells_cleared_next_to_equal_obstacles_leave_the_scores_rebuilt_from_scratch(cleared):
    """Scores tied between neighbouring obstacles: clearing one keeps the other's, clearing
    both lowers them; only cells scoring no more than a cleared cell gave are recomputed."""
    geometry = MapGeometry.covering((0.0, 0.0, 3.0, 3.0), 0.05, 0.0)
    grid = LogOddsMap(geometry)
    high = grid.params.clamp_max
    block = np.zeros((5, 5), dtype=np.float32)
    block[[0, 0, 2], [0, 1, 0]] = high  # cells (20, 20), (20, 21), (22, 20)
    grid.add_logodds(20, 20, block)
    for iy, ix in cleared:
        clear = np.full((1, 1), -2 * high, dtype=np.float32)
        assert grid.add_logodds(iy, ix, clear) == 1
    score, coarse, count = _rebuilt(grid)
    assert np.array_equal(grid.score, score)
    assert np.array_equal(grid.coarse, coarse)
    assert grid.occupied_cells == count == 3 - len(cleared)


def test_a_map_that_keeps_its_returns_knows_where_in_a_cell_a_wall_lies():
    # a wall at x = 1.013 m, 13 mm into cell 20 of 5 cm cells: every return falls there
    geometry = MapGeometry((0.0, 0.0), 0.05, 40, 40)
    grid = LogOddsMap(geometry, hit_centroids=True)
    assert grid.has_hit_centroids and not LogOddsMap(geometry).has_hit_centroids
    angles = np.linspace(-0.3, 0.3, 31)
    ranges = (1.013 - 0.5) / np.cos(angles)
    grid.integrate(
        (0.5, 1.0, 0.0), angles, ranges, range_min_m=0.1, range_max_m=5.0, clear_no_return_m=1.0
    )
    cells = grid.hit_counts > 0
    columns = np.flatnonzero(cells.any(axis=0))
    assert columns.tolist() == [20] and grid.hit_counts.sum() == len(angles)
    within = grid.hit_means[cells][:, 0] / 255.0
    assert np.allclose(within, 0.26, atol=0.5 / 255)  # 13 mm of a 5 cm cell
    grid.clear()
    assert not grid.hit_counts.any() and not grid.hit_means.any()
