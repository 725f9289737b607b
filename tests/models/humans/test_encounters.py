import numpy as np
import pytest

from models.humans.encounters import Encounters

ROBOT = np.array([[0.0, 0.0, 0.3]])


def _person(x):
    return np.array([[x, 0.0, 0.25]])


def test_a_near_miss_is_counted_once_per_approach_and_again_after_the_pair_parted():
    e = Encounters(near_miss_m=0.5, stop_radius_m=1.5)
    began = []
    for x in [3.0, 1.2, 0.9, 0.8, 0.9, 1.3, 2.0, 1.0, 3.0]:
        new, _ = e.update(ROBOT, np.array([0.0]), _person(x), ["w"])
        began += new
    assert len(began) == 2  # at 0.9 (clearance 0.35) and again at 1.0 after parting at 1.3
    assert began[0].clearance_m == pytest.approx(0.9 - 0.55)
    assert e.min_clearance_m == pytest.approx(0.8 - 0.55)


def test_a_moving_robot_that_halts_next_to_a_person_is_a_stop_caused_by_people():
    e = Encounters(near_miss_m=0.5, stop_radius_m=1.5)
    assert e.update(ROBOT, np.array([0.5]), _person(1.5), ["w"])[1] == []
    _, stops = e.update(ROBOT, np.array([0.0]), _person(1.5), ["w"])
    assert [(s.robot, s.person) for s in stops] == [(0, "w")]
    # standing still is not a new stop
    assert e.update(ROBOT, np.array([0.0]), _person(1.5), ["w"])[1] == []


def test_a_halt_with_nobody_near_is_not_blamed_on_people():
    e = Encounters(near_miss_m=0.5, stop_radius_m=1.5)
    e.update(ROBOT, np.array([0.5]), _person(5.0), ["w"])
    assert e.update(ROBOT, np.array([0.0]), _person(5.0), ["w"])[1] == []
    e.update(ROBOT, np.array([0.5]), np.zeros((0, 3)), [])
    assert e.update(ROBOT, np.array([0.0]), np.zeros((0, 3)), [])[1] == []
    assert e.min_clearance_m > 4


def test_slowing_between_the_thresholds_keeps_the_robot_moving():
    e = Encounters(near_miss_m=0.5, stop_radius_m=1.5)
    e.update(ROBOT, np.array([0.5]), _person(1.5), ["w"])
    assert e.update(ROBOT, np.array([0.03]), _person(1.5), ["w"])[1] == []
    assert len(e.update(ROBOT, np.array([0.01]), _person(1.5), ["w"])[1]) == 1
