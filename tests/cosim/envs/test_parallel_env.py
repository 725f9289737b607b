import numpy as np
import pytest
from pettingzoo.test import parallel_api_test, parallel_seed_test

from cosim.envs import WarehouseParallelEnv, parallel_env


@pytest.mark.parametrize(
    ("preset", "overrides"),
    [
        ("lab-room", {}),
        ("warehouse-random", {"agents.observe": ["pose", "velocity", "goal", "inbox"]}),
        ("lab-room", {"agents.action": "goal", "agents.observe": ["goal", "places", "lidar"]}),
    ],
)
def test_pettingzoos_parallel_checker_passes(preset, overrides):
    parallel_api_test(parallel_env(scenario=preset, overrides=overrides, duration_s=3.0), 50)


def test_pettingzoos_seed_test_passes():
    parallel_seed_test(lambda: WarehouseParallelEnv("lab-room", duration_s=2.0), num_cycles=15)


def test_each_agent_is_rewarded_for_its_own_progress():
    env = WarehouseParallelEnv(
        "lab-room", overrides={"agents.rewards": ["progress"], "agents.reward_weights": [1.0]}
    )
    obs, _ = env.reset(seed=2)
    total = dict.fromkeys(env.agents, 0.0)
    for _ in range(30):  # robot_1 turns to its goal and drives; the others stand
        ahead, left, _ = obs["robot_1"][2:5]
        turn = float(np.clip(2.0 * np.arctan2(left, ahead), -2.0, 2.0))
        actions = {a: np.zeros(2, np.float32) for a in env.agents}
        actions["robot_1"] = np.array([0.5 if abs(turn) < 0.5 else 0.0, turn], np.float32)
        obs, rewards, *_ = env.step(actions)
        for agent, reward in rewards.items():
            total[agent] += reward
    assert total["robot_1"] > 0.5
    assert all(abs(total[a]) < 1e-9 for a in ("robot_2", "robot_3", "robot_4"))
