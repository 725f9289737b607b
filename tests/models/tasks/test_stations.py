import numpy as np

from models.tasks.stations import clear_of, pick_stations
from models.world.warehouse import Warehouse


def test_stations_face_the_middle_of_each_long_side():
    shelves = np.array([[2.0, 2.0, 4.0, 2.8], [6.0, 1.0, 6.8, 3.0]])
    stations = pick_stations(shelves, 0.3, 0.2, lambda p, _r: np.ones(len(p), dtype=bool))
    np.testing.assert_allclose(
        stations,
        [
            [3.0, 1.5, np.pi / 2],
            [3.0, 3.3, -np.pi / 2],
            [5.5, 2.0, 0.0],
            [7.3, 2.0, np.pi],
        ],
    )


def test_stations_where_a_robot_cannot_stand_are_dropped():
    shelves = np.array([[2.0, 2.0, 4.0, 2.8]])
    stations = pick_stations(shelves, 0.3, 0.2, lambda p, _r: p[:, 1] > 2.0)
    assert len(stations) == 1 and stations[0, 1] > 2.8


def _room(shelves: list[list[float]]) -> Warehouse:
    """A 6 m x 6 m room with these shelves (walls outside the room, as generated)."""
    return Warehouse((6.0, 6.0), 0.2, np.zeros((0, 4)), np.array(shelves), np.zeros((0, 3)), 0.0)


def test_a_station_squeezed_between_its_shelf_and_a_wall_is_dropped():
    world = _room([[0.93, 2.0, 1.33, 3.0], [4.6, 2.0, 5.0, 3.0]])
    stations = pick_stations(world.shelves, 0.33, 0.25, world.is_free)
    # west of the first shelf the footprint fits with 2 cm to the wall: dropped; east of
    # the second one 9 cm are left: kept
    assert [tuple(s.round(2)) for s in stations[:, :2]] == [(1.91, 2.5), (4.02, 2.5), (5.58, 2.5)]
    assert world.is_free(np.array([[0.35, 2.5]]), 0.33).all()


def test_the_station_s_own_shelf_face_does_not_count_against_its_clearance():
    world = _room([[2.0, 2.0, 4.0, 2.8]])
    assert len(pick_stations(world.shelves, 0.3, 0.2, world.is_free)) == 2


def test_stations_near_a_taken_one_are_not_clear_and_with_none_taken_all_are():
    stations = np.array([[0.0, 0.0, 0.0], [0.9, 0.0, 0.0], [1.0, 0.0, 0.0], [3.0, 0.0, 0.0]])
    assert clear_of(stations, np.array([[0.0, 0.0]]), 0.91).tolist() == [False, False, True, True]
    assert clear_of(stations, np.zeros((0, 2)), 0.91).all()
