"""The costmap's compiled loops against plain references: stamping, distances, costs."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.navigation.cost_kernels import (
    FREE,
    INSCRIBED,
    LETHAL,
    MAX_NON_OBSTACLE,
    NO_INFORMATION,
    _combine_py,
    _costs_of,
    _squared_edt,
    _stamp_discs,
    _stamp_points,
)
from models.navigation.costmap import CostmapParams, cost_table, inflation_kernel


def test_the_cost_values_are_nav2s():
    assert (FREE, MAX_NON_OBSTACLE, INSCRIBED, LETHAL, NO_INFORMATION) == (0, 252, 253, 254, 255)


def test_a_stamp_takes_the_higher_cost_but_unknown_yields_only_to_obstacles():
    values = [np.uint8(v) for v in (0, 1, 100, 252, 253, 254, 255)]
    for old in values:
        for new in values:
            got = _combine_py(old, new)
            if old == NO_INFORMATION:
                assert got == (new if new >= INSCRIBED else NO_INFORMATION), (old, new)
            else:
                assert got == max(old, new), (old, new)


def _edt_reference(obstacle: np.ndarray) -> np.ndarray:
    cells = np.argwhere(obstacle)
    rows, cols = np.indices(obstacle.shape)
    if not len(cells):
        return np.full(obstacle.shape, -1, dtype=np.int64)
    d2 = (rows[..., None] - cells[:, 0]) ** 2 + (cols[..., None] - cells[:, 1]) ** 2
    return d2.min(axis=-1)


@settings(max_examples=60, deadline=None)
@given(
    shape=st.tuples(st.integers(1, 16), st.integers(1, 16)),
    density=st.sampled_from([0.0, 0.02, 0.1, 0.5, 1.0]),
    seed=st.integers(0, 2**16),
)
def test_the_squared_distance_transform_is_exact_to_the_nearest_obstacle_centre(
    shape, density, seed
):
    obstacle = np.random.default_rng(seed).random(shape) < density
    d2 = np.empty(shape, dtype=np.int64)
    _squared_edt(np.ascontiguousarray(obstacle, dtype=np.bool_), d2)
    assert np.array_equal(d2, _edt_reference(obstacle))


def test_distances_and_costs_come_from_the_squared_distance_and_the_table():
    params = CostmapParams(robot_radius_m=0.33)
    res = 0.05
    table = cost_table(params, res)
    table.setflags(write=False)
    d2 = np.array([[-1, 0, 1], [2, 25, len(table) + 10]], dtype=np.int64)
    distance = np.empty(d2.shape, dtype=np.float32)
    cost = np.empty(d2.shape, dtype=np.uint8)
    _costs_of(d2, res, table, distance, cost)
    assert math.isinf(distance[0, 0]) and cost[0, 0] == FREE  # no obstacle anywhere
    assert distance[0, 1] == 0.0 and cost[0, 1] == LETHAL
    assert distance[1, 1] == np.float32(5 * res) and cost[1, 1] == table[25]
    assert distance[1, 0] == np.float32(math.sqrt(2) * res)
    assert cost[1, 2] == FREE  # beyond the table


def _stamp_reference(cost, cells, kernel):
    out = cost.copy()
    k = kernel.shape[0] // 2
    h, w = cost.shape
    for cx, cy in cells:
        for ky in range(kernel.shape[0]):
            for kx in range(kernel.shape[1]):
                x, y = cx - k + kx, cy - k + ky
                if 0 <= x < w and 0 <= y < h and kernel[ky, kx]:
                    out[y, x] = _combine_py(out[y, x], kernel[ky, kx])
    return out


@settings(max_examples=40, deadline=None)
@given(
    points=st.lists(st.tuples(st.integers(-12, 30), st.integers(-12, 25)), max_size=6),
    seed=st.integers(0, 2**16),
)
def test_stamping_points_takes_the_kernels_maximum_around_each_clipped_at_the_edges(points, seed):
    kernel = inflation_kernel(CostmapParams(robot_radius_m=0.33), 0.05)
    kernel.setflags(write=False)  # as the costmap compiles it
    rng = np.random.default_rng(seed)
    cost = rng.choice(np.array([0, 10, 200, 255], dtype=np.uint8), size=(14, 18))
    cells = np.array(points, dtype=np.int64).reshape(-1, 2)
    want = _stamp_reference(cost, cells, kernel)
    _stamp_points(cost, cells, kernel)
    assert np.array_equal(cost, want)


def _disc_reference(shape, discs, origin, res, robot_r, reach, scaling):
    cost = np.zeros(shape, dtype=np.uint8)
    for px, py, pr in discs:
        for iy in range(shape[0]):
            for ix in range(shape[1]):
                dx = origin[0] + (ix + 0.5) * res - px
                dy = origin[1] + (iy + 0.5) * res - py
                d = math.hypot(dx, dy) - pr
                holds = ix == math.floor((px - origin[0]) / res) and iy == math.floor(
                    (py - origin[1]) / res
                )
                if d <= 1e-9 or holds:
                    v = LETHAL
                elif d <= robot_r + 1e-9:
                    v = INSCRIBED
                elif d <= reach + 1e-9:
                    v = math.floor(MAX_NON_OBSTACLE * math.exp(-scaling * (d - robot_r)))
                else:
                    continue
                cost[iy, ix] = max(cost[iy, ix], v)
    return cost


def test_discs_are_lethal_inside_inscribed_within_the_radius_and_inflated_beyond():
    params = CostmapParams(robot_radius_m=0.33)
    res, origin = 0.1, (-1.0, -0.5)
    discs = np.array([[0.3, 0.4, 0.35], [1.55, 1.2, 0.02]])
    cost = np.zeros((30, 35), dtype=np.uint8)
    args = (origin[0], origin[1], res, params.robot_radius_m, params.inflation_radius_m)
    _stamp_discs(cost, discs, *args, params.cost_scaling, 0, 0)
    want = _disc_reference(cost.shape, discs, origin, res, *args[3:], params.cost_scaling)
    assert np.array_equal(cost, want)
    # the tiny disc still makes the cell holding its centre lethal
    assert cost[math.floor((1.2 + 0.5) / res), math.floor((1.55 + 1.0) / res)] == LETHAL


def test_a_window_stamped_with_its_offset_equals_that_part_of_the_whole_grid():
    params = CostmapParams(robot_radius_m=0.33)
    discs = np.array([[1.0, 1.0, 0.3]])
    args = (0.0, 0.0, 0.05, params.robot_radius_m, params.inflation_radius_m, params.cost_scaling)
    whole = np.zeros((60, 60), dtype=np.uint8)
    _stamp_discs(whole, discs, *args, 0, 0)
    window = np.zeros((20, 25), dtype=np.uint8)
    _stamp_discs(window, discs, *args, 12, 15)
    assert np.array_equal(window, whole[15:35, 12:37])
    assert window.any()


def test_a_disc_never_lowers_a_cost_and_unknown_cells_take_only_obstacle_costs():
    params = CostmapParams(robot_radius_m=0.33)
    cost = np.full((40, 40), NO_INFORMATION, dtype=np.uint8)
    cost[:, 20:] = 250
    args = (0.0, 0.0, 0.05, params.robot_radius_m, params.inflation_radius_m, params.cost_scaling)
    _stamp_discs(cost, np.array([[1.0, 1.0, 0.1]]), *args, 0, 0)
    assert set(np.unique(cost[:, :20]).tolist()) <= {INSCRIBED, LETHAL, NO_INFORMATION}
    assert (cost[:, 20:] >= 250).all()


@pytest.mark.parametrize("radius", [0.0, 0.05])
def test_a_disc_outside_the_grid_stamps_nothing(radius):
    params = CostmapParams(robot_radius_m=0.33)
    cost = np.zeros((10, 10), dtype=np.uint8)
    args = (0.0, 0.0, 0.05, params.robot_radius_m, params.inflation_radius_m, params.cost_scaling)
    _stamp_discs(cost, np.array([[50.0, -40.0, radius]]), *args, 0, 0)
    assert not cost.any()
