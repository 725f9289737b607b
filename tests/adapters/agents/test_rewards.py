import numpy as np
import pytest

from cosim.envs import Agents

TERMS = ["progress", "arrived", "time", "contact", "messages"]


def test_every_term_is_a_running_total_and_a_reward_its_weighted_change():
    overrides = {"agents.rewards": TERMS, "agents.reward_weights": [0, 0, 1, 0, 0]}
    agents = Agents("lab-room", overrides=overrides, duration_s=2.0)
    agents.reset(seed=1)
    rewards = []
    while not agents.ended:
        agents.act(np.arange(4), np.zeros((4, 2)))
        agents.advance_all()
        rewards.append(agents.rewards(np.arange(4)))
    np.testing.assert_allclose(np.array(rewards), 0.1)  # one decision period of time each
    totals = {t.name: t.total(agents.episode.view) for t in agents.episode.parts.rewards}
    np.testing.assert_allclose(totals["time"], 2.0)
    np.testing.assert_array_equal(totals["messages"], 10)  # 5 Hz for 2 s
    np.testing.assert_array_equal(totals["arrived"], 0)
    np.testing.assert_allclose(totals["progress"], 0.0, atol=1e-9)  # nobody moved


def test_progress_carries_over_from_one_goal_to_the_next():
    overrides = {"robots.count": 1, "robots.positions": [[2.0, 1.0, 1.5708]]}
    agents = Agents("lab-room", overrides=overrides, duration_s=30.0)
    agents.reset(seed=2)
    view = agents.episode.view
    term = agents.episode.parts.rewards[0]
    assert term.name == "progress"
    previous = 0.0
    while not agents.ended and view.arrivals[0] < 2:
        obs = agents.observe()
        heading = np.arctan2(obs[0, 3], obs[0, 2])
        agents.act(np.array([0]), np.array([[0.5 if abs(heading) < 0.4 else 0.0, 2 * heading]]))
        agents.advance_all()
        total = float(term.total(view)[0])
        assert total >= previous - 0.06  # no jump back when a goal is replaced
        previous = total
    assert view.arrivals[0] == 2
    assert previous == pytest.approx(
        view.progress_base_m[0] + view.goal_start_m[0] - view.goal_distance_m()[0]
    )
