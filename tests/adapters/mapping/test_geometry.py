import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from adapters.mapping.geometry import MARGIN_M, map_geometry, unknown_grid
from cosim.runner.assembly import assemble
from models.geometry.occupancy import UNKNOWN
from models.world.warehouse import Warehouse
from tests.conftest import SMALL


@pytest.fixture(scope="module")
def world() -> Warehouse:
    scenario = cosim.load_scenario("warehouse-random", SMALL)
    return assemble(scenario, names=["world"]).run.service(Warehouse)


def test_the_maps_reach_a_metre_beyond_the_walls_outer_faces(world):
    geometry = map_geometry(world, 0.1)
    xmin, ymin, xmax, ymax = world.bounds  # 12 m x 12 m inside 0.2 m walls
    assert (xmin, ymin, xmax, ymax) == pytest.approx((-0.2, -0.2, 12.2, 12.2))
    assert MARGIN_M == 1.0
    assert geometry.origin_xy_m == pytest.approx((-1.2, -1.2))
    assert (geometry.resolution_m, geometry.width, geometry.height) == (0.1, 144, 144)


@settings(max_examples=40, deadline=None)
@given(resolution_m=st.floats(min_value=0.01, max_value=1.0))
def test_the_grid_covers_the_world_and_its_margin_at_any_cell_size(world, resolution_m):
    geometry = map_geometry(world, resolution_m)
    x0, y0 = geometry.origin_xy_m
    xmin, ymin, xmax, ymax = world.bounds
    assert (x0, y0) == pytest.approx((xmin - MARGIN_M, ymin - MARGIN_M))
    assert x0 + geometry.width * resolution_m >= xmax + MARGIN_M - 1e-9
    assert y0 + geometry.height * resolution_m >= ymax + MARGIN_M - 1e-9
    # no more than one cell beyond it
    assert geometry.width == math.ceil((xmax + MARGIN_M - x0) / resolution_m)
    assert geometry.height == math.ceil((ymax + MARGIN_M - y0) / resolution_m)


def test_a_robot_that_has_seen_nothing_has_every_cell_unknown_on_the_common_grid(world):
    geometry = map_geometry(world, 0.25)
    grid = unknown_grid(geometry)
    assert grid.data.shape == (geometry.height, geometry.width)
    assert (grid.data == UNKNOWN).all() and grid.data.dtype.name == "int8"
    assert grid.resolution_m == 0.25
    assert grid.origin_xy_m == geometry.origin_xy_m
