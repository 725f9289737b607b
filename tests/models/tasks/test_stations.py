import numpy as np

from models.tasks.stations import pick_stations


def test_stations_face_the_middle_of_each_long_side():
    shelves = np.array([[2.0, 2.0, 4.0, 2.8], [6.0, 1.0, 6.8, 3.0]])
    stations = pick_stations(shelves, 0.3, 0.2, lambda p: np.ones(len(p), dtype=bool))
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
    stations = pick_stations(shelves, 0.3, 0.2, lambda p: p[:, 1] > 2.0)
    assert len(stations) == 1 and stations[0, 1] > 2.8
