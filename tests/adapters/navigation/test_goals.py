"""The random goal sender: a new goal after each one reached, given up or unreachable."""

import numpy as np

import adapters.navigation.goals as goals
import cosim
from adapters.navigation.places import FleetPlaces


def test_after_an_unreachable_goal_the_next_goes_out_a_second_later_not_at_once(monkeypatch):
    # every goal off the fleet manager's places: each is answered `unreachable` at once,
    # which sent the next at once, goal after goal within one instant, until Python's
    # recursion limit ended the run (a robot stranded in a pocket of two places did this)
    monkeypatch.setattr(FleetPlaces, "goal_place", lambda self, i, goal: -1)
    scenario = cosim.load_scenario(
        "fleet50",
        {"robots.count": 3, "scenario.duration_s": 4.5, "record.bag": "none"},
    )
    result = cosim.run(scenario)
    navigation = result.tables["navigation"]
    assert result.summary["arrivals"] == 0
    for robot in ("robot_1", "robot_2", "robot_3"):
        rows = navigation[navigation["robot"] == robot]
        sent = rows.loc[rows["event"] == "goal", "t_s"].to_numpy()
        unreachable = rows[rows["event"] == "unreachable"]
        assert np.allclose(sent, np.arange(5) * goals.RETRY_S)  # RETRY_S is 1 s
        assert len(unreachable) == 5
