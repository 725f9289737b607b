import math

import numpy as np
import pytest

from models.errors import ModelError
from models.geometry.occupancy import (
    FREE,
    OCCUPIED,
    UNKNOWN,
    OccupancyGrid,
    rasterize_boxes,
    resample,
    resampled_obstacles,
)
from models.world.warehouse import WarehouseSpec, generate_warehouse, ground_truth_grid


def _occupied_cells(grid):
    rows, cols = np.nonzero(grid.data == OCCUPIED)
    return set(zip(rows.tolist(), cols.tolist(), strict=True))


def test_a_box_on_cell_boundaries_occupies_exactly_its_cells():
    grid = rasterize_boxes(np.array([[0.3, 0.2, 0.5, 0.6]]), (0.0, 0.0, 1.0, 1.0), 0.1)
    assert grid.data.shape == (10, 10)
    # x in [0.3, 0.5] -> cols 3, 4; y in [0.2, 0.6] -> rows 2..5; neighbours only touch
    assert _occupied_cells(grid) == {(r, c) for r in range(2, 6) for c in (3, 4)}


def test_cells_partly_overlapped_by_a_box_are_occupied():
    grid = rasterize_boxes(np.array([[0.25, 0.05, 0.31, 0.11]]), (0.0, 0.0, 1.0, 1.0), 0.1)
    assert _occupied_cells(grid) == {(0, 2), (0, 3), (1, 2), (1, 3)}


def test_a_box_touching_a_cell_only_at_an_edge_or_corner_leaves_it_free():
    # two boxes sharing the line x = 0.5 and a third touching them at a corner
    boxes = np.array([[0.2, 0.2, 0.5, 0.4], [0.5, 0.2, 0.7, 0.4], [0.7, 0.4, 0.9, 0.6]])
    grid = rasterize_boxes(boxes, (0.0, 0.0, 1.0, 1.0), 0.1)
    expected = {(r, c) for r in (2, 3) for c in range(2, 7)}
    expected |= {(r, c) for r in (4, 5) for c in (7, 8)}
    assert _occupied_cells(grid) == expected


def test_a_box_without_area_occupies_nothing():
    boxes = np.array([[0.25, 0.2, 0.25, 0.6], [0.1, 0.35, 0.9, 0.35]])
    grid = rasterize_boxes(boxes, (0.0, 0.0, 1.0, 1.0), 0.1)
    assert not np.any(grid.data == OCCUPIED)


def test_boxes_beyond_the_bounds_are_clipped_to_the_grid():
    grid = rasterize_boxes(np.array([[-5.0, 0.9, 5.0, 5.0]]), (0.0, 0.0, 1.0, 1.0), 0.1)
    assert _occupied_cells(grid) == {(9, c) for c in range(10)}


def test_the_grid_origin_is_the_lower_left_corner_of_the_bounds():
    grid = rasterize_boxes(np.zeros((0, 4)), (-0.2, -0.4, 1.0, 0.6), 0.2)
    assert grid.origin_xy_m == (-0.2, -0.4)
    assert (grid.height, grid.width) == (5, 6)
    assert grid.extent == pytest.approx((-0.2, -0.4, 1.0, 0.6))
    assert np.all(grid.data == FREE)


def test_row_zero_is_the_lowest_y():
    grid = rasterize_boxes(np.array([[0.0, 0.0, 1.0, 0.1]]), (0.0, 0.0, 1.0, 1.0), 0.1)
    assert np.all(grid.data[0] == OCCUPIED)
    assert np.all(grid.data[1:] == FREE)


def test_bounds_not_on_a_cell_boundary_are_covered_by_one_more_cell():
    grid = rasterize_boxes(np.zeros((0, 4)), (0.0, 0.0, 1.05, 0.5), 0.1)
    assert (grid.height, grid.width) == (5, 11)


@pytest.mark.parametrize("resolution", [0.0, -0.05, math.nan, math.inf, 1e-5])
def test_a_nonsensical_resolution_is_a_model_error_naming_it(resolution):
    with pytest.raises(ModelError) as caught:
        rasterize_boxes(np.zeros((0, 4)), (0.0, 0.0, 30.0, 30.0), resolution)
    assert caught.value.key == "resolution_m"


def test_values_at_reads_cells_and_reports_unknown_outside():
    grid = rasterize_boxes(np.array([[0.0, 0.0, 0.5, 0.5]]), (0.0, 0.0, 1.0, 1.0), 0.1)
    values = grid.values_at(np.array([[0.25, 0.25], [0.75, 0.75], [1.5, 0.5], [-0.01, 0.2]]))
    assert values.tolist() == [OCCUPIED, FREE, UNKNOWN, UNKNOWN]


def test_a_grid_keeps_its_own_read_only_copy_of_the_data():
    data = np.zeros((2, 3), dtype=np.int8)
    grid = OccupancyGrid(resolution_m=0.1, origin_xy_m=(0.0, 0.0), data=data)
    data[0, 0] = OCCUPIED
    assert grid.data[0, 0] == FREE
    with pytest.raises(ValueError):
        grid.data[0, 0] = OCCUPIED


def test_grids_are_equal_when_resolution_origin_and_cells_are():
    a = rasterize_boxes(np.array([[0.2, 0.2, 0.4, 0.4]]), (0.0, 0.0, 1.0, 1.0), 0.1)
    b = rasterize_boxes(np.array([[0.2, 0.2, 0.4, 0.4]]), (0.0, 0.0, 1.0, 1.0), 0.1)
    c = rasterize_boxes(np.array([[0.2, 0.2, 0.5, 0.4]]), (0.0, 0.0, 1.0, 1.0), 0.1)
    assert a == b
    assert a != c


@pytest.mark.parametrize("layout", ["random", "all_rows", "two_corridors"])
@pytest.mark.parametrize("resolution", [0.05, 0.1, 0.07])
def test_a_warehouse_grid_has_every_wall_cell_occupied_and_every_start_free(layout, resolution):
    world = generate_warehouse(
        WarehouseSpec(layout=layout, robot_count=12), np.random.default_rng(3)
    )
    grid = ground_truth_grid(world, resolution)
    assert grid.origin_xy_m == world.bounds[:2]
    # the centres of all cells inside a wall's interior
    for xmin, ymin, xmax, ymax in world.walls:
        xs = np.arange(xmin + resolution / 2, xmax, resolution / 4)
        ys = np.arange(ymin + resolution / 2, ymax, resolution / 4)
        points = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
        assert np.all(grid.values_at(points) == OCCUPIED)
    assert np.all(grid.values_at(world.starts[:, :2]) == FREE)
    # the outer ring of cells is wall all round
    assert np.all(grid.data[[0, -1], :] == OCCUPIED)
    assert np.all(grid.data[:, [0, -1]] == OCCUPIED)


def test_a_warehouse_grid_occupies_every_shelf_and_is_conservative():
    world = generate_warehouse(WarehouseSpec(layout="random"), np.random.default_rng(5))
    grid = ground_truth_grid(world, 0.05)
    rows, cols = np.nonzero(grid.data == OCCUPIED)
    x0, y0 = grid.origin_xy_m
    cells = np.stack([x0 + cols * 0.05, y0 + rows * 0.05], axis=1)
    boxes = world.boxes
    # every occupied cell overlaps some obstacle with positive area
    overlap_x = (cells[:, None, 0] < boxes[None, :, 2]) & (
        cells[:, None, 0] + 0.05 > boxes[None, :, 0]
    )
    overlap_y = (cells[:, None, 1] < boxes[None, :, 3]) & (
        cells[:, None, 1] + 0.05 > boxes[None, :, 1]
    )
    assert np.all((overlap_x & overlap_y).any(axis=1))
    # every shelf's corners (nudged inside) land on occupied cells
    for xmin, ymin, xmax, ymax in world.shelves:
        corners = np.array([[xmin, ymin], [xmax, ymin], [xmin, ymax], [xmax, ymax]])
        inward = corners + np.array([[1, 1], [-1, 1], [1, -1], [-1, -1]]) * 1e-4
        assert np.all(grid.values_at(inward) == OCCUPIED)


@pytest.mark.parametrize(
    ("shape", "from_res", "to_res"),
    [((648, 648), 0.05, 0.1), ((37, 53), 0.05, 0.15), ((20, 21), 0.1, 0.1), ((9, 8), 0.025, 0.1)],
)
def test_obstacles_found_in_whole_blocks_are_those_of_the_resampled_grid(shape, from_res, to_res):
    rng = np.random.default_rng(11)
    data = rng.choice(
        np.array([UNKNOWN, FREE, OCCUPIED], dtype=np.int8), shape, p=[0.6, 0.39, 0.01]
    )
    expected = resample(OccupancyGrid(from_res, (0.0, 0.0), data), to_res).data >= OCCUPIED
    obstacles = resampled_obstacles(data, from_res, to_res)
    assert obstacles is not None
    assert obstacles.any() and np.array_equal(obstacles, expected)


def test_obstacles_are_not_found_by_blocks_when_cells_do_not_fit_whole():
    data = np.zeros((10, 10), dtype=np.int8)
    assert resampled_obstacles(data, 0.05, 0.12) is None
    assert resampled_obstacles(data, 0.1, 0.05) is None
