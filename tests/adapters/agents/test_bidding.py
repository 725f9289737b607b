import numpy as np
import pytest

import cosim
from cosim.core.errors import ConfigError
from cosim.envs import WarehouseParallelEnv

BIDS = {
    "agents.action": "bid",
    "assignment.protocol": "agent_bids",
    "agents.observe": ["velocity", "tasks"],
    "agents.rewards": ["tasks"],
}


def nearest_free(observation):
    """Bid for the cheapest free slot: the greedy protocol's rule, as a policy."""
    slots = observation[2:].reshape(4, 4)
    return np.where(slots[:, 3] > 0, 1.0 / (1.0 + slots[:, 2]), 0.0).astype(np.float32)


def _episode(policy, seed=1, duration_s=60.0, **more):
    env = WarehouseParallelEnv(
        "warehouse-random", overrides={**BIDS, **more}, duration_s=duration_s
    )
    obs, _ = env.reset(seed=seed)
    rewarded = dict.fromkeys(env.possible_agents, 0.0)
    while env.agents:
        obs, rewards, *_ = env.step({a: policy(obs[a]) for a in env.agents})
        for agent, reward in rewards.items():
            rewarded[agent] += reward
    return env.result(), rewarded


def test_robots_serve_the_tasks_their_agents_bid_for_and_are_rewarded_for_them():
    result, rewarded = _episode(nearest_free)
    tasks = result.tables["tasks"]
    done = tasks[tasks["t_completed_s"].notna()]
    assert len(done) >= 4
    served = done.groupby("robot").size()
    for agent, reward in rewarded.items():
        assert reward == pytest.approx(10.0 * served.get(agent, 0))  # the tasks term's weight


def test_agents_that_decline_or_never_bid_leave_every_task_open():
    declined, _ = _episode(lambda obs: np.zeros(4, np.float32))  # a bid of 0 declines
    assert declined.summary["tasks_completed"] == 0
    late, _ = _episode(nearest_free, **{"agents.decision_hz": 0.01})  # one decision, at 0 s
    assert late.summary["tasks_completed"] == 0  # a bid counts once the tasks reached it


def test_the_tasks_part_shows_the_epoch_the_robot_heard():
    env = WarehouseParallelEnv("warehouse-random", overrides=BIDS, duration_s=5.0)
    obs, _ = env.reset(seed=2)
    for _ in range(5):
        obs, *_ = env.step({a: np.zeros(4, np.float32) for a in env.agents})
    view = env.core.episode.view
    epoch = view.epochs[0]
    assert epoch is not None
    slots = obs["robot_1"][2:].reshape(4, 4)
    k = min(4, len(epoch.tasks))
    fleet = view.fleet
    for j in range(k):
        station = np.hypot(epoch.tasks[j].x_m - fleet.x[0], epoch.tasks[j].y_m - fleet.y[0])
        assert np.hypot(slots[j, 0], slots[j, 1]) == pytest.approx(station, rel=1e-4)
    assert (slots[k:, 3] == 0).all()


def test_the_bid_action_needs_its_protocol_and_the_protocol_its_agents():
    with pytest.raises(
        ConfigError, match=r"protocol = 'distributed_simplex': expected 'agent_bids'"
    ):
        WarehouseParallelEnv("warehouse-random", overrides={"agents.action": "bid"})
    scenario = cosim.load_scenario(
        "warehouse-random", {"robots.driver": "tasks", "assignment.protocol": "agent_bids"}
    )
    with pytest.raises(ConfigError, match=r"expected robots.driver = 'agents'"):
        cosim.run(scenario, duration_s=5.0)
