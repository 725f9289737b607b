import numpy as np

from models.humans.yielding import Yielding, robots_ahead

ROBOT = np.array([[2.0, 0.0, 0.33]])


def _person(x, y=0.0):
    return np.array([[x, y, 0.25]])


def test_a_robot_right_in_front_blocks_a_walker_and_one_behind_or_aside_does_not():
    assert robots_ahead(_person(1.0), np.array([0.0]), 1.2, ROBOT)[0]  # facing it, 1 m
    assert not robots_ahead(_person(1.0), np.array([np.pi]), 1.2, ROBOT)[0]  # walking away
    assert not robots_ahead(_person(1.0, 1.5), np.array([0.0]), 1.2, ROBOT)[0]  # beside
    assert not robots_ahead(_person(-1.0), np.array([0.0]), 1.2, ROBOT)[0]  # too far yet


def test_without_robots_or_people_nobody_is_blocked():
    assert robots_ahead(np.zeros((0, 3)), np.zeros(0), 1.2, ROBOT).shape == (0,)
    assert not robots_ahead(_person(1.0), np.array([0.0]), 1.2, np.zeros((0, 3))).any()


def test_a_blocked_walker_stops_and_walks_on_once_clear():
    y = Yielding(give_up_ns=10**10)
    stop, go = y.update(0, ["w"], np.array([True]), np.array([True]))
    assert (stop, go) == (["w"], [])
    assert y.update(10**8, ["w"], np.array([True]), np.array([False])) == ([], [])
    assert y.update(2 * 10**8, ["w"], np.array([False]), np.array([False])) == ([], ["w"])
    assert y.yields == 1


def test_a_walker_waits_at_most_the_limit_then_is_not_stopped_again_for_as_long():
    y = Yielding(give_up_ns=5 * 10**9)
    y.update(0, ["w"], np.array([True]), np.array([True]))
    assert y.update(5 * 10**9, ["w"], np.array([True]), np.array([False])) == ([], ["w"])
    # still blocked, walking again: not stopped before the same time has passed
    assert y.update(6 * 10**9, ["w"], np.array([True]), np.array([True])) == ([], [])
    assert y.update(10 * 10**9, ["w"], np.array([True]), np.array([True])) == (["w"], [])


def test_someone_staying_at_a_station_is_not_stopped_and_someone_gone_is_forgotten():
    y = Yielding(give_up_ns=10**10)
    assert y.update(0, ["w"], np.array([True]), np.array([False])) == ([], [])
    y.update(0, ["v"], np.array([True]), np.array([True]))
    y.update(10**8, [], np.zeros(0, dtype=bool), np.zeros(0, dtype=bool))
    assert y.held == {}
