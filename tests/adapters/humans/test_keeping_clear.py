"""People keep clear of robots: a worker whose way passes a parked robot never walks into it."""

import numpy as np
import pytest

import cosim
from cosim.runner.execute import run

pytestmark = pytest.mark.slow

ROBOT_XY = (7.0, 0.8)
"""A robot parked in the middle of the lower corridor (1.6 m wide): nobody fits past it."""


def _parked_robot(*, avoid_robots):
    return cosim.load_scenario(
        "warehouse-humans",
        {
            "world.size_m": [14.0, 9.0],
            "world.layout": "random",
            "world.shelf_count": 0,
            "world.obstacles": [[4.0, 1.6, 10.0, 6.4]],
            "robots.count": 1,
            "robots.placement": "explicit",
            "robots.positions": [[*ROBOT_XY, 0.0]],
            "robots.driver": "navigation",
            "navigation.goals": [list(ROBOT_XY)],
            "humans.workers": 8,
            "humans.avoid_robots": avoid_robots,
            "scenario.duration_s": 60.0,
            "record.bag": "none",
        },
    )


def _closest_person_m(result):
    humans = result.tables["humans"]
    gap = np.hypot(humans["x_m"] - ROBOT_XY[0], humans["y_m"] - ROBOT_XY[1])
    return float(gap.min()) - 0.25 - result.scenario.robots.radius_m


def test_workers_walking_at_a_parked_robot_wait_short_of_it_and_never_touch_it():
    result = run(_parked_robot(avoid_robots=True), seed=2)
    summary = result.summary
    assert summary["humans_collisions"] == 0
    assert len(result.tables["collisions"]) == 0
    assert 0.0 < _closest_person_m(result) < 0.2  # they came right up to it, then waited
    assert summary["humans_min_distance_m"] > 0.0
    assert summary["humans_yields"] > 0
    assert summary["humans_trips"] > 0
    poses = result.tables["poses"]
    assert np.ptp(poses["x_m"]) == 0.0  # the robot never moved: people did all the keeping clear


def test_without_keeping_clear_the_same_workers_walk_into_the_parked_robot():
    result = run(_parked_robot(avoid_robots=False), seed=2)
    hits = result.tables["collisions"]
    assert (hits["kind"] == "person").sum() > 0
    assert (hits["speed_mps"] == 0.0).all()  # the robot stood still: people walked into it
    assert _closest_person_m(result) < 0.0
