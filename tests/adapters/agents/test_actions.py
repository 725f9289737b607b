import numpy as np
import pytest

from cosim.envs import Agents


def test_velocity_commands_are_clipped_to_the_drive_limits():
    overrides = {"robots.count": 1, "robots.positions": [[2.0, 1.0, 1.5708]]}
    agents = Agents("lab-room", overrides=overrides, duration_s=3.0)
    agents.reset(seed=1)
    while not agents.ended:
        agents.act(np.array([0]), np.array([[9.0, 0.0]]))  # far past the 0.5 m/s limit
        agents.advance_all()
    poses = agents.finish().tables["poses"]
    assert poses["v_mps"].max() == pytest.approx(0.5)
    assert poses["y_m"].iloc[-1] < 1.0 + 0.5 * 3.0


def test_a_goal_choice_is_driven_to_by_the_navigation():
    overrides = {
        "agents.action": "goal",
        "agents.observe": ["goal", "places"],
        "robots.count": 1,
        "robots.positions": [[2.0, 1.0, 1.5708]],
    }
    agents = Agents("lab-room", overrides=overrides, duration_s=40.0)
    agents.reset(seed=3)
    places = agents.episode.view.places
    assert places.shape == (8, 2)
    while not agents.ended:  # always the place nearest the goal: the goal itself
        goal = agents.episode.view.goal_xy[0]
        choice = int(np.argmin(np.hypot(*(places - goal).T)))
        agents.act(np.array([0]), np.array([choice]))
        agents.advance_all()
    result = agents.finish()
    assert result.summary["agent_arrivals"] >= 3
    arrivals = result.tables["agent_arrivals"]
    on_places = {tuple(p) for p in places.round(6)}
    assert {
        (round(x, 6), round(y, 6))
        for x, y in zip(arrivals.goal_x_m, arrivals.goal_y_m, strict=True)
    } <= on_places
