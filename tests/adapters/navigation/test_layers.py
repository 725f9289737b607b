import numpy as np
import pytest

from adapters.navigation.layers import StaticLayers, _traversable, open_goal, padded
from cosim.core.messages import OccupancyGrid as GridMessage
from models.geometry.occupancy import FREE, OCCUPIED, UNKNOWN, OccupancyGrid, resample
from models.navigation.costmap import INSCRIBED, CostmapParams, StaticCostmap
from models.navigation.planner import plan

PARAMS = CostmapParams(robot_radius_m=0.33, inflation_radius_m=1.0, cost_scaling=3.0)
ORIGIN = (-1.0, -2.0)


def _map(resolution_m, shape, seed):
    rng = np.random.default_rng(seed)
    data = rng.choice(
        np.array([UNKNOWN, FREE, OCCUPIED], dtype=np.int8), shape, p=[0.5, 0.48, 0.02]
    )
    return OccupancyGrid(resolution_m, ORIGIN, data)


def _message(grid):
    rows, cols = grid.data.shape
    return GridMessage(
        0, "map", grid.resolution_m, cols, rows, *grid.origin_xy_m, grid.data.tobytes()
    )


@pytest.mark.parametrize(
    ("map_resolution_m", "shape"),
    [(0.05, (120, 90)), (0.05, (121, 93)), (0.1, (60, 45)), (0.04, (150, 112))],
)
def test_a_robots_new_map_gives_the_layer_of_its_resampled_traversable_grid(
    map_resolution_m, shape
):
    """Whole blocks (0.05 and 0.1 m to 0.1 m) skip the resampling; 0.04 m resamples."""
    empty = OccupancyGrid(map_resolution_m, ORIGIN, np.full(shape, UNKNOWN, dtype=np.int8))
    layers = StaticLayers.unexplored(empty, 3, PARAMS, 0.1)
    for seed in range(3):
        grid = _map(map_resolution_m, shape, seed)
        layers.update(1, _message(grid))
        expected = StaticCostmap.from_grid(_traversable(resample(grid, 0.1)), PARAMS)
        layer = layers[1]
        assert np.array_equal(layer.cost, expected.cost)
        assert np.array_equal(layer.distance_m, expected.distance_m)
        assert np.array_equal(layers.distance[1], expected.distance_m)
        assert (layer.resolution_m, layer.origin_xy_m) == (0.1, ORIGIN)
        assert (layer.cost == 254).any()
    assert layers.updates == 3
    assert np.isinf(layers.distance[0]).all()  # the others' maps are theirs


def _gap_room(gap_m):
    """A 4 m x 3 m room at 0.05 m cells split by a wall at y = 1.5 m with one gap in it."""
    data = np.zeros((60, 80), dtype=np.int8)
    data[[0, -1], :] = OCCUPIED
    data[:, [0, -1]] = OCCUPIED
    cells = round(gap_m / 0.05)
    data[29:31, :] = OCCUPIED
    data[29:31, 40 - cells // 2 : 40 - cells // 2 + cells] = FREE
    return StaticCostmap.from_grid(OccupancyGrid(0.05, (0.0, 0.0), data), PARAMS)


@pytest.mark.parametrize(("gap_m", "passable"), [(0.8, False), (1.0, True)])
def test_the_padding_closes_a_gap_narrower_than_the_footprint_and_the_padding_on_both_sides(
    gap_m, passable
):
    static = _gap_room(gap_m)
    start, goal = static.world_to_cell((2.0, 0.7)), static.world_to_cell((2.0, 2.3))
    assert plan(static.cost, start, goal).found  # the footprint alone fits either gap
    # 0.8 m < 2 x (0.33 + 0.1) m: the local controller would halt at its mouth
    assert plan(padded(static, 0.1).cost, start, goal).found is passable


def test_the_padding_blocks_only_its_band_and_none_is_the_layer_itself():
    static = _gap_room(1.0)
    pad = padded(static, 0.1)
    changed = pad.cost != static.cost
    near = static.distance_m[changed]
    assert changed.any() and near.min() > 0.33 and near.max() <= 0.43 + 1e-6
    assert (pad.cost[changed] == INSCRIBED).all()
    assert padded(static, 0.0) is static


def test_a_goal_in_the_padding_gets_a_way_in_and_nothing_else_is_opened():
    static = _gap_room(1.0)
    pad = padded(static, 0.1)
    goal_xy = np.array([1.0, 1.91])  # 0.4 m from the wall cells (centre 1.525 m): in the band
    start, goal = static.world_to_cell((1.0, 2.4)), static.world_to_cell(goal_xy)
    assert not plan(pad.cost, start, goal).found
    cost = np.array(pad.cost)
    open_goal(cost, static, pad, goal_xy, 0.25)
    assert plan(cost, start, goal).found
    opened = cost != pad.cost
    assert (cost[opened] == static.cost[opened]).all()
    ys, xs = np.nonzero(opened)
    centres = np.stack([(xs + 0.5) * 0.05, (ys + 0.5) * 0.05], axis=1)
    assert np.hypot(*(centres - goal_xy).T).max() <= 0.25 + 0.05
