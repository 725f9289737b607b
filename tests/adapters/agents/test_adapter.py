import numpy as np
import pytest

import cosim
from adapters.agents.adapter import AGENT_STATES
from cosim.envs import Agents


def _drive_to_goals(agents, steps):
    """A hand-written policy: turn towards the goal, then drive."""
    for _ in range(steps):
        obs = agents.observe()
        ahead, left = obs[:, 2], obs[:, 3]
        heading = np.arctan2(left, ahead)
        v = np.where(np.abs(heading) < 0.4, 0.5, 0.0)
        agents.act(np.arange(len(agents)), np.column_stack([v, np.clip(2 * heading, -2, 2)]))
        agents.advance_all()


def test_an_agent_reaching_its_goal_is_recorded_and_given_the_next():
    overrides = {"robots.count": 1, "robots.positions": [[2.0, 1.0, 1.5708]]}
    agents = Agents("lab-room", overrides=overrides, duration_s=40.0)
    agents.reset(seed=2)
    first = agents.episode.view.goal_xy[0].copy()
    _drive_to_goals(agents, 400)
    result = agents.finish()
    arrivals = result.tables["agent_arrivals"]
    assert len(arrivals) >= 3
    assert (arrivals["goal_x_m"].iloc[0], arrivals["goal_y_m"].iloc[0]) == tuple(first)
    assert (arrivals["took_s"] > 0).all() and (arrivals["straight_m"] >= 0).all()
    assert result.summary["agent_arrivals"] == len(arrivals)
    poses = result.tables["poses"]
    for t, x, y in zip(arrivals["t_s"], arrivals["goal_x_m"], arrivals["goal_y_m"], strict=True):
        row = poses[poses["t_s"] <= t].iloc[-1]
        assert np.hypot(row["x_m"] - x, row["y_m"] - y) < 0.3 + 0.05  # within tolerance, a tick


def test_goals_follow_the_navigation_series_in_turn():
    series = [[1.0, 2.0], [3.0, 6.0]]
    agents = Agents("lab-room", overrides={"navigation.goals": series}, duration_s=1.0)
    goals = agents.episode.view.goal_xy
    assert goals.tolist() == [[1.0, 2.0], [3.0, 6.0], [1.0, 2.0], [3.0, 6.0]]


def test_a_plain_run_with_the_agents_driver_shares_poses_and_stands_still():
    scenario = cosim.load_scenario("lab-room", {"robots.driver": "agents"})
    result = cosim.run(scenario, duration_s=2.0)
    assert result.summary["agent_poses_sent"] == 4 * 10  # 5 Hz for 2 s, 4 robots
    assert result.summary["agent_poses_heard"] == 4 * 10 * 3
    messages = result.tables["messages"]
    states = messages[messages["topic"] == AGENT_STATES]
    assert (states["src_host"] != states["dst_host"]).sum() == 4 * 10 * 3
    assert result.tables["poses"].groupby("robot")["v_mps"].max().max() == pytest.approx(0.0)
