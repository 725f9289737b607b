import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.errors import ModelError
from models.geometry.occupancy import OCCUPIED, UNKNOWN, OccupancyGrid
from models.navigation.costmap import (
    INSCRIBED,
    LETHAL,
    NO_INFORMATION,
    CostmapParams,
    StaticCostmap,
    inflation_cost,
    stamp_discs,
    with_obstacles,
)

RES = 0.05
PARAMS = CostmapParams(robot_radius_m=0.3, inflation_radius_m=1.0, cost_scaling=3.0)


def _grid(shape=(60, 60), occupied=(), unknown=(), res=RES, origin=(0.0, 0.0)):
    data = np.zeros(shape, dtype=np.int8)
    for iy, ix in occupied:
        data[iy, ix] = OCCUPIED
    for iy, ix in unknown:
        data[iy, ix] = UNKNOWN
    return OccupancyGrid(resolution_m=res, origin_xy_m=origin, data=data)


def _nav2(d_m):
    """Nav2's InflationLayer::computeCost for a distance in metres (robot 0.3 m)."""
    if d_m == 0:
        return 254
    if d_m <= 0.3 + 1e-9:
        return 253
    if d_m > 1.0 + 1e-9:
        return 0
    return int(252 * math.exp(-3.0 * (d_m - 0.3)))


def test_inflation_costs_follow_the_nav2_formula_at_a_few_distances():
    static = StaticCostmap.from_grid(_grid(occupied=[(30, 10)]), PARAMS)
    row = static.cost[30]
    # cells along +x from the obstacle cell: centre distances 0, 0.05, ..., exactly as Nav2
    for cells in (0, 1, 6, 7, 10, 14, 20, 21, 30):
        assert row[10 + cells] == _nav2(cells * RES), cells
    assert row[10] == LETHAL
    assert row[16] == INSCRIBED  # exactly on the robot radius counts as touching
    assert row[17] == int(252 * math.exp(-3.0 * 0.05)) == 216
    assert row[20] == int(252 * math.exp(-3.0 * 0.2)) == 138
    assert row[30] == int(252 * math.exp(-3.0 * 0.7)) == 30
    assert row[31] == 0
    # diagonal distances too: (3, 4) cells away is 0.25 m, inscribed; (6, 8) is 0.5 m
    assert static.cost[34, 13] == INSCRIBED
    assert static.cost[38, 16] == _nav2(0.5)


def test_inflation_cost_matches_the_formula_on_an_array_of_distances():
    d = np.array([0.0, 0.1, 0.3, 0.4, 0.99, 1.0, 1.01, np.inf])
    want = [_nav2(x) if math.isfinite(x) else 0 for x in d]
    assert inflation_cost(d, PARAMS).tolist() == want


def test_the_distance_field_is_metres_to_the_nearest_obstacle_cell_centre():
    static = StaticCostmap.from_grid(_grid(occupied=[(30, 10)]), PARAMS)
    assert static.distance_m.dtype == np.float32
    assert static.distance_m[30, 10] == 0.0
    assert static.distance_m[34, 13] == pytest.approx(0.25)
    assert static.distance_m[30, 50] == pytest.approx(40 * RES)


def test_a_map_without_obstacles_is_free_everywhere_with_infinite_clearance():
    static = StaticCostmap.from_grid(_grid(), PARAMS)
    assert (static.cost == 0).all()
    assert np.isinf(static.distance_m).all()


def test_unknown_cells_stay_unknown_unless_an_obstacle_touches_them():
    grid = _grid(occupied=[(30, 30)], unknown=[(30, 32), (30, 40), (5, 5)])
    static = StaticCostmap.from_grid(grid, PARAMS)
    assert static.cost[30, 32] == INSCRIBED  # within the robot radius: inflated over
    assert static.cost[30, 40] == NO_INFORMATION  # 0.5 m away: stays unknown
    assert static.cost[5, 5] == NO_INFORMATION


def test_the_static_costmap_is_read_only_and_keeps_the_grid_geometry():
    static = StaticCostmap.from_grid(_grid(origin=(-1.0, 2.0)), PARAMS)
    assert not static.cost.flags.writeable
    assert (static.width, static.height) == (60, 60)
    assert static.origin_xy_m == (-1.0, 2.0)
    with pytest.raises(ValueError):
        static.cost[0, 0] = 1


def test_world_and_cell_coordinates_convert_both_ways():
    static = StaticCostmap.from_grid(_grid(origin=(-1.0, 2.0)), PARAMS)
    assert static.world_to_cell((-1.0, 2.0)) == (0, 0)
    assert static.world_to_cell((-0.96, 2.051)) == (0, 1)
    assert static.cell_to_world((0, 1)) == pytest.approx((-0.975, 2.075))
    assert static.world_to_cell(static.cell_to_world((17, 42))) == (17, 42)
    assert static.in_bounds((59, 59))
    assert not static.in_bounds((60, 0))
    assert not static.in_bounds(static.world_to_cell((-1.01, 2.5)))


def test_a_dynamic_point_stamps_the_same_costs_as_a_static_obstacle_in_its_cell():
    empty = StaticCostmap.from_grid(_grid(), PARAMS)
    one = StaticCostmap.from_grid(_grid(occupied=[(12, 40)]), PARAMS)
    point = np.array([[40.5 * RES, 12.2 * RES]])
    assert np.array_equal(with_obstacles(empty, point), one.cost)


def test_dynamic_points_take_the_maximum_with_the_static_costs_on_a_copy():
    static = StaticCostmap.from_grid(_grid(occupied=[(30, 10)]), PARAMS)
    before = static.cost.copy()
    cost = with_obstacles(static, np.array([[1.0, 1.5], [1.02, 1.5]]))
    assert np.array_equal(static.cost, before)
    assert cost.flags.writeable
    assert (cost >= static.cost).all()
    assert cost[30, 20] == LETHAL
    assert cost[30, 10] == LETHAL  # the static obstacle is untouched


def test_points_without_a_return_or_far_off_the_grid_are_ignored():
    static = StaticCostmap.from_grid(_grid(), PARAMS)
    points = np.array([[np.inf, 1.0], [np.nan, np.nan], [100.0, 100.0], [-5.0, 1.0]])
    assert np.array_equal(with_obstacles(static, points), static.cost)


def test_a_point_just_off_the_grid_still_inflates_the_cells_inside():
    static = StaticCostmap.from_grid(_grid(), PARAMS)
    cost = with_obstacles(static, np.array([[-0.12, 1.5]]))  # 3 cells left of column 0
    assert cost[30, 0] == INSCRIBED
    assert cost[30, 4] == _nav2(7 * RES)
    assert cost[30, 20] == 0


def test_obstacles_seen_in_unknown_space_are_marked_but_do_not_clear_it():
    static = StaticCostmap.from_grid(
        _grid(unknown=[(y, x) for y in range(60) for x in range(30)]), PARAMS
    )
    cost = with_obstacles(static, np.array([[1.475, 1.5]]))  # cell (29, 30)
    assert cost[30, 29] == LETHAL
    assert cost[30, 27] == INSCRIBED
    assert cost[30, 20] == NO_INFORMATION  # a low inflation cost does not make it known
    assert cost[30, 35] == _nav2(6 * RES)


def test_stamped_discs_are_lethal_inside_and_inflated_from_their_edge():
    static = StaticCostmap.from_grid(_grid(), PARAMS)
    cost = static.cost.copy()
    disc = np.array([[1.525, 1.525, 0.2]])  # centred on cell (30, 30)
    stamp_discs(static, cost, disc)
    assert cost[30, 30] == LETHAL
    assert cost[30, 33] == LETHAL  # 0.15 m from the centre: inside
    assert cost[30, 35] == INSCRIBED  # 0.25 m: 0.05 m from the edge
    assert cost[30, 42] == int(252 * math.exp(-3.0 * (0.4 - 0.3)))  # 0.4 m from the edge
    assert cost[30, 57] == 0  # 1.15 m from the edge
    assert np.array_equal(cost, with_obstacles(static, np.zeros((0, 2)), discs=disc))


def test_a_disc_smaller_than_a_cell_still_marks_its_cell_lethal():
    static = StaticCostmap.from_grid(_grid(), PARAMS)
    cost = with_obstacles(static, np.zeros((0, 2)), discs=np.array([[1.51, 1.51, 0.001]]))
    assert cost[30, 30] == LETHAL
    assert (cost == LETHAL).sum() == 1


def test_other_inflation_parameters_give_a_different_kernel():
    static = StaticCostmap.from_grid(_grid(), PARAMS)
    small = CostmapParams(robot_radius_m=0.1, inflation_radius_m=0.2)
    cost = with_obstacles(static, np.array([[1.5, 1.5]]), small)
    assert cost[30, 32] == INSCRIBED
    assert cost[30, 33] == int(252 * math.exp(-3.0 * 0.05))
    assert cost[30, 35] == 0


@pytest.mark.parametrize(
    ("kwargs", "key"),
    [
        ({"robot_radius_m": -0.1}, "robots.radius_m"),
        ({"robot_radius_m": 0.3, "inflation_radius_m": 0.2}, "navigation.inflation_radius_m"),
        ({"robot_radius_m": 0.3, "cost_scaling": math.nan}, "navigation.cost_scaling"),
    ],
)
def test_impossible_inflation_parameters_are_rejected_with_their_key(kwargs, key):
    with pytest.raises(ModelError) as err:
        CostmapParams(**kwargs)
    assert err.value.key == key


def _scipy_layer(obstacle, res, params):
    """The static layer as it was built before the compiled transform: scipy, then numpy."""
    from scipy import ndimage

    if obstacle.any():
        distance = ndimage.distance_transform_edt(~obstacle) * res
    else:
        distance = np.full(obstacle.shape, np.inf)
    return inflation_cost(distance, params), distance.astype(np.float32)


@settings(max_examples=300, deadline=None)
@given(
    shape=st.tuples(st.integers(1, 40), st.integers(1, 40)),
    density=st.sampled_from([0.0, 0.002, 0.02, 0.2, 0.7, 1.0]),
    seed=st.integers(0, 2**32 - 1),
    res=st.sampled_from([0.05, 0.1, 0.3]),
)
def test_distances_and_costs_equal_scipys_exact_transform_bit_for_bit(shape, density, seed, res):
    obstacle = np.random.default_rng(seed).random(shape) < density
    grid = OccupancyGrid(res, (0.0, 0.0), np.where(obstacle, OCCUPIED, 0).astype(np.int8))
    layer = StaticCostmap.from_grid(grid, PARAMS)
    cost, distance = _scipy_layer(obstacle, res, PARAMS)
    assert np.array_equal(layer.distance_m, distance)
    assert np.array_equal(layer.cost, cost)


def test_distances_equal_scipys_on_a_large_sparse_map_with_ties():
    """Obstacles on a lattice: many cells are as far from two or four of them."""
    obstacle = np.zeros((324, 300), dtype=bool)
    obstacle[::17, ::23] = True
    obstacle[100:140, 200] = True
    grid = OccupancyGrid(0.1, (0.0, 0.0), np.where(obstacle, OCCUPIED, 0).astype(np.int8))
    layer = StaticCostmap.from_grid(grid, PARAMS)
    cost, distance = _scipy_layer(obstacle, 0.1, PARAMS)
    assert np.array_equal(layer.distance_m, distance)
    assert np.array_equal(layer.cost, cost)


def test_a_layer_from_obstacle_cells_equals_the_layer_of_their_grid():
    obstacle = np.random.default_rng(3).random((50, 70)) < 0.05
    data = np.where(obstacle, OCCUPIED, 0).astype(np.int8)
    expected = StaticCostmap.from_grid(OccupancyGrid(0.1, (-1.5, 2.0), data), PARAMS)
    layer = StaticCostmap.from_obstacles(obstacle, 0.1, (-1.5, 2.0), PARAMS)
    assert np.array_equal(layer.cost, expected.cost)
    assert np.array_equal(layer.distance_m, expected.distance_m)
    assert (layer.resolution_m, layer.origin_xy_m) == (0.1, (-1.5, 2.0))
