import numpy as np
import pytest

from cosim.envs import WarehouseAECEnv, WarehouseParallelEnv


@pytest.mark.parametrize("kind", [WarehouseParallelEnv, WarehouseAECEnv])
def test_both_pettingzoo_environments_name_their_agents_after_the_robots_and_share_spaces(kind):
    env = kind("lab-room", duration_s=1.0)
    assert env.possible_agents == ["robot_1", "robot_2", "robot_3", "robot_4"]
    assert env.observation_space("robot_2") is env.observation_space("robot_4")
    assert env.action_space("robot_1").shape == (2,)
    assert env.metadata["render_fps"] == 10.0


@pytest.mark.parametrize("kind", [WarehouseParallelEnv, WarehouseAECEnv])
def test_resets_without_a_seed_follow_the_last_seed_given(kind):
    def seeds():
        env = kind("lab-room", duration_s=0.3)
        env.reset(seed=21)
        drawn = []
        for _ in range(2):
            env.state()  # every agent's observation, stacked
            env.core.act(np.arange(4), np.zeros((4, 2)))
            env.core.advance_all()
            env.reset()
            drawn.append(env.core.episode.scenario.seed)
        return drawn

    assert seeds() == seeds()
