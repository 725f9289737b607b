import numpy as np
import pytest

from adapters.navigation.layers import StaticLayers, _traversable
from cosim.core.messages import OccupancyGrid as GridMessage
from models.navigation.costmap import CostmapParams, StaticCostmap
from models.occupancy import FREE, OCCUPIED, UNKNOWN, OccupancyGrid, resample

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
