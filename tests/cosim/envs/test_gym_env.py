import warnings

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import cosim.envs
from cosim.core.errors import ConfigError
from cosim.envs import ENV_ID, WarehouseEnv


@pytest.mark.parametrize("preset", ["lab-room", "warehouse-random", "warehouse-humans"])
def test_gymnasiums_checker_passes_on_three_presets(preset):
    env = gymnasium.make(ENV_ID, scenario=preset, duration_s=2.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a checker's warning fails the test
        warnings.filterwarnings("ignore", message=".*alternative render modes.*")
        check_env(env.unwrapped)
    env.close()


def test_the_module_path_form_of_the_id_imports_cosim_on_its_own():
    env = gymnasium.make("cosim.envs:cosim/Warehouse-v0", duration_s=1.0)
    assert isinstance(env.unwrapped, WarehouseEnv)
    assert cosim.envs.ENV_ID in gymnasium.registry


def _episode(seed, steps=40, **overrides):
    env = WarehouseEnv("lab-room", overrides=overrides, duration_s=steps / 10)
    obs, _ = env.reset(seed=seed)
    rng = np.random.default_rng(7)
    low, high = env.action_space.low, env.action_space.high
    observations, rewards = [obs], []
    done = False
    while not done:
        obs, reward, terminated, truncated, _ = env.step(rng.uniform(low, high).astype(np.float32))
        observations.append(obs)
        rewards.append(reward)
        done = terminated or truncated
    return np.array(observations), np.array(rewards), env.result()


def test_the_same_seed_gives_the_same_episode_and_tables():
    obs_a, rewards_a, result_a = _episode(5)
    obs_b, rewards_b, result_b = _episode(5)
    assert np.array_equal(obs_a, obs_b)
    assert np.array_equal(rewards_a, rewards_b)
    for name in ("poses", "messages", "agent_arrivals", "collisions"):
        assert result_a.tables[name].equals(result_b.tables[name]), name
    obs_c, _, _ = _episode(6)
    assert not np.array_equal(obs_a, obs_c)


def test_an_episode_ends_truncated_at_its_duration_and_its_tables_cover_it():
    obs, _rewards, result = _episode(1, steps=25)
    assert len(obs) == 26
    assert result.summary["sim_time_s"] == pytest.approx(2.5)
    poses = result.tables["poses"]
    assert poses["t_s"].max() < 2.5
    assert set(poses["robot"]) == {"robot_1", "robot_2", "robot_3", "robot_4"}


def test_resets_without_a_seed_draw_the_next_episodes_seeds_from_the_first():
    def seeds():
        env = WarehouseEnv("lab-room", duration_s=0.2)
        env.reset(seed=11)
        drawn = []
        for _ in range(3):
            env.step(np.zeros((4, 2), np.float32))
            env.reset()
            drawn.append(env.agents.episode.scenario.seed)
        return drawn

    first = seeds()
    assert first == seeds()
    assert len(set(first)) == 3


def test_a_single_robot_drives_as_commanded():
    env = WarehouseEnv(
        "lab-room", overrides={"robots.count": 1, "robots.positions": [[2.0, 1.0, 1.5708]]}
    )
    env.reset(seed=1)
    for _ in range(20):
        env.step(np.array([[0.5, 0.0]], np.float32))
    poses = env.result().tables["poses"]
    assert poses["y_m"].iloc[-1] > 1.0 + 0.5 * 1.5  # 2 s at 0.5 m/s, less the acceleration


def test_a_bad_override_is_refused_naming_the_key_and_what_was_expected():
    with pytest.raises(ConfigError, match=r"agents.*decision_hz.*-1"):
        WarehouseEnv("lab-room", overrides={"agents.decision_hz": -1.0})
    with pytest.raises(ConfigError, match="reward_weights"):
        WarehouseEnv("lab-room", overrides={"agents.reward_weights": [1.0]})
    with pytest.raises(ConfigError, match=r"lidar\.beams > 0"):
        WarehouseEnv("lab-room", overrides={"lidar.beams": 0})
    with pytest.raises(ValueError, match="render_mode"):
        WarehouseEnv("lab-room", render_mode="human")


def test_a_closed_episode_is_never_reused_by_the_next_reset():
    env = WarehouseEnv("lab-room", duration_s=1.0)
    env.reset(seed=3)
    env.close()
    env.reset(seed=3)
    env.step(np.zeros((4, 2), np.float32))
    assert env.agents.now_ns == 100_000_000
    assert env.result().summary["sim_time_s"] == pytest.approx(0.1)
