import numpy as np
import pytest

from models.errors import ModelError
from models.geometry.occupancy import OCCUPIED, OccupancyGrid
from models.navigation.costmap import CostmapParams, StaticCostmap
from models.navigation.lanes import EAST, NORTH, SOUTH, TWO_WAY, WEST, aisle_lanes
from models.navigation.planner import plan

RES = 0.1


def _racks():
    """A 20 m x 12 m hall: three rows of two 6 m racks, 1.6 m aisles, a 1.6 m cross aisle.

    Racks (0.8 m deep) at y 2.0-2.8, 4.4-5.2 and 6.8-7.6; along x at 3-9 and 10.6-16.6.
    """
    obstacle = np.zeros((120, 200), dtype=bool)
    obstacle[0, :] = obstacle[-1, :] = obstacle[:, 0] = obstacle[:, -1] = True
    for y0 in (20, 44, 68):
        obstacle[y0 : y0 + 8, 30:90] = True
        obstacle[y0 : y0 + 8, 106:166] = True
    return obstacle


def test_neighbouring_aisles_run_in_opposite_directions():
    lanes = aisle_lanes(_racks(), RES, 2.5)
    lower, upper = lanes[36, 50], lanes[60, 50]  # aisles at y 2.8-4.4 and 5.2-6.8
    assert {int(lower), int(upper)} == {EAST, WEST}
    assert (lanes[28:44, 30:90] == lower).all()  # the whole aisle one way
    assert (lanes[28:44, 106:166] == lower).all()  # and on across the junction


def test_the_cross_aisle_between_racks_is_one_way_and_junctions_and_open_floor_are_two_way():
    lanes = aisle_lanes(_racks(), RES, 2.5)
    assert lanes[24, 98] in (NORTH, SOUTH)  # between two racks of a row
    assert lanes[36, 98] == TWO_WAY  # where the cross aisle meets an aisle
    assert lanes[100, 100] == TWO_WAY  # open floor above the racks
    assert (lanes[_racks()] == TWO_WAY).all()  # obstacles have no direction


def test_an_aisle_wider_than_the_limit_stays_two_way():
    lanes = aisle_lanes(_racks(), RES, 1.5)
    assert lanes[36, 50] == TWO_WAY


def test_lanes_refuse_a_width_or_resolution_that_is_not_a_positive_distance():
    with pytest.raises(ModelError, match="max_width_m"):
        aisle_lanes(_racks(), RES, 0.0)
    with pytest.raises(ModelError, match="resolution_m"):
        aisle_lanes(_racks(), float("inf"), 2.5)


def _costmap(obstacle):
    data = np.where(obstacle, OCCUPIED, 0).astype(np.int8)
    grid = OccupancyGrid(RES, (0.0, 0.0), data)
    return StaticCostmap.from_grid(grid, CostmapParams(robot_radius_m=0.3, inflation_radius_m=0.6))


@pytest.mark.parametrize("going", [EAST, WEST])
def test_a_path_along_the_racks_takes_the_aisle_that_runs_its_way(going):
    obstacle = _racks()[:100]  # the hall 10 m deep: every passage along x is an aisle
    obstacle[-1, :] = True
    static = _costmap(obstacle)
    lanes = aisle_lanes(obstacle, RES, 2.5)
    west_end, east_end = (1.5, 3.6), (18.5, 3.6)  # the open ends of one aisle
    start, goal = (west_end, east_end) if going == EAST else (east_end, west_end)
    cells = static.world_to_cell(start), static.world_to_cell(goal)
    result = plan(static.cost, *cells, resolution_m=RES, lanes=lanes, against=5.0)
    assert result.found
    middle = result.cells[(result.cells[:, 0] > 40) & (result.cells[:, 0] < 80)]
    assert (lanes[middle[:, 1], middle[:, 0]] == going).all()
    free = plan(static.cost, *cells, resolution_m=RES)
    assert result.cost_m >= free.cost_m  # lanes only make steps dearer


def test_a_plan_refuses_lanes_of_another_shape_or_a_factor_below_one():
    static = _costmap(_racks())
    cells = (20, 20), (30, 20)
    with pytest.raises(ModelError, match="lanes"):
        plan(static.cost, *cells, lanes=np.zeros((3, 3), dtype=np.uint8))
    with pytest.raises(ModelError, match="against"):
        plan(static.cost, *cells, lanes=aisle_lanes(_racks(), RES, 2.5), against=0.5)
