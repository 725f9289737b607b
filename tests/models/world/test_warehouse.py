import math

import numpy as np
import pytest
import shapely
from shapely.geometry import box

from models.errors import ModelError
from models.world.warehouse import WarehouseSpec, box_distance, generate_warehouse


def _gen(**kwargs):
    return generate_warehouse(WarehouseSpec(**kwargs), np.random.default_rng(0))


def _min_gap(boxes):
    """Smallest gap between racks (shelves touching end to end form one rack)."""
    merged = shapely.union_all([box(*b) for b in boxes])
    polys = list(getattr(merged, "geoms", [merged]))
    return min(
        polys[i].distance(polys[j]) for i in range(len(polys)) for j in range(i + 1, len(polys))
    )


@pytest.mark.parametrize("layout", ["random", "all_rows", "two_corridors"])
def test_every_layout_keeps_aisles_between_shelves_and_walls(layout):
    world = _gen(layout=layout, shelf_count=24)
    assert len(world.shelves) == 24
    assert _min_gap(world.shelves) >= 1.6 - 1e-9
    assert world.shelves[:, :2].min() >= 1.6 - 1e-9
    assert world.shelves[:, 2].max() <= 30 - 1.6 + 1e-9
    assert world.shelves[:, 3].max() <= 30 - 1.6 + 1e-9
    assert world.shelves[:, 1].min() >= world.dock_depth_m + 1.6 - 1e-9


@pytest.mark.parametrize("layout", ["random", "all_rows", "two_corridors"])
def test_the_free_space_for_a_robot_is_connected(layout):
    world = _gen(layout=layout, shelf_count=24)
    room = box(0, 0, 30, 30).buffer(-0.33)
    inflated = shapely.union_all([box(*b).buffer(0.33) for b in world.shelves])
    free = room.difference(inflated)
    assert free.geom_type == "Polygon"


def test_dock_placement_puts_robots_in_rows_along_the_south_wall_facing_north():
    world = _gen(robot_count=50, shelf_count=0)
    starts = world.starts
    assert starts.shape == (50, 3)
    assert np.all(starts[:, 2] == pytest.approx(math.pi / 2))
    gaps = np.hypot(*(starts[:, None, :2] - starts[None, :, :2]).transpose(2, 0, 1))
    np.fill_diagonal(gaps, np.inf)
    assert gaps.min() >= 2 * 0.33
    assert starts[:, 1].max() < world.dock_depth_m


def test_random_placement_keeps_robots_clear_of_shelves_and_each_other():
    world = _gen(robot_count=20, placement="random")
    clearance = box_distance(world.starts[:, :2], world.shelves).min(axis=1)
    assert clearance.min() >= 0.33
    assert world.is_free(world.starts[:, :2], 0.33).all()


def test_the_same_stream_gives_the_same_world_and_another_a_different_one():
    a = generate_warehouse(WarehouseSpec(), np.random.default_rng(5))
    b = generate_warehouse(WarehouseSpec(), np.random.default_rng(5))
    c = generate_warehouse(WarehouseSpec(), np.random.default_rng(6))
    np.testing.assert_array_equal(a.shelves, b.shelves)
    assert not np.array_equal(a.shelves, c.shelves)


def test_too_many_shelves_are_refused_naming_the_key():
    with pytest.raises(ModelError) as error:
        _gen(shelf_count=500)
    assert error.value.key == "world.shelf_count"
    assert "at most" in error.value.expected


def test_too_many_shelves_in_rows_are_refused_with_the_capacity():
    with pytest.raises(ModelError, match=r"at most \d+ shelves for layout 'all_rows'"):
        _gen(layout="all_rows", shelf_count=1000)


def test_a_robot_inside_an_obstacle_is_refused():
    with pytest.raises(ModelError) as error:
        _gen(
            shelf_count=0,
            obstacles=((4.0, 4.0, 6.0, 6.0),),
            placement="explicit",
            robot_count=2,
            positions=((1.0, 1.0, 0.0), (5.0, 5.0, 0.0)),
        )
    assert error.value.key == "robots.positions[1]"


def test_shelves_are_generated_around_explicit_start_poses():
    positions = tuple((x, y, 0.0) for x in (5.0, 15.0, 25.0) for y in (8.0, 16.0, 24.0))
    for layout in ("random", "all_rows"):
        world = _gen(
            layout=layout, shelf_count=20, placement="explicit", robot_count=9, positions=positions
        )
        assert world.is_free(world.starts[:, :2], 0.33).all()


def test_shelves_keep_an_aisle_from_extra_obstacles():
    obstacle = (10.0, 10.0, 14.0, 14.0)
    for layout in ("random", "all_rows", "two_corridors"):
        world = _gen(layout=layout, shelf_count=20, obstacles=(obstacle,))
        gaps = [box(*b).distance(box(*obstacle)) for b in world.shelves]
        assert min(gaps) >= 1.6 - 1e-9
        assert world.boxes.shape == (4 + 20 + 1, 4)


def test_an_obstacle_outside_the_room_is_refused():
    with pytest.raises(ModelError) as error:
        _gen(obstacles=((28.0, 5.0, 31.0, 6.0),))
    assert error.value.key == "world.obstacles[0]"


def test_an_obstacle_on_the_dock_is_refused():
    with pytest.raises(ModelError, match="clear of the dock strip"):
        _gen(shelf_count=0, obstacles=((14.0, 0.0, 16.0, 1.0),))


def test_overlapping_explicit_robots_are_refused():
    with pytest.raises(ModelError, match=r"at least 0\.66 m from robot 0"):
        _gen(
            shelf_count=0,
            placement="explicit",
            robot_count=2,
            positions=((5.0, 5.0, 0.0), (5.3, 5.0, 0.0)),
        )


def test_an_aisle_narrower_than_a_robot_is_refused():
    with pytest.raises(ModelError) as error:
        _gen(aisle_width_m=0.5)
    assert error.value.key == "world.aisle_width_m"


def test_more_robots_than_the_dock_holds_are_refused():
    with pytest.raises(ModelError) as error:
        _gen(size_m=(5.0, 5.0), robot_count=200, shelf_count=0)
    assert error.value.key == "robots.count"


def test_segments_outline_every_box():
    world = _gen(shelf_count=2)
    assert world.segments().shape == ((4 + 2) * 4, 4)
