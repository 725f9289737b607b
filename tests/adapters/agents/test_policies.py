from typing import ClassVar

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from cosim.core.errors import ConfigError
from cosim.core.plugins import PluginError
from cosim.core.registry import registered
from cosim.envs import WarehouseEnv

OVERRIDES = {"agents.observe": ["velocity", "goal", "lidar"]}


def seek(observations):
    """Turn towards the goal, drive when facing it (a pure function of what agents see)."""
    ahead, left = observations[:, 2], observations[:, 3]
    heading = np.arctan2(left, ahead)
    v = np.where(np.abs(heading) < 0.4, 0.5, 0.0)
    return np.column_stack([v, np.clip(2.0 * heading, -2.0, 2.0)])


class Seeker:
    name: ClassVar[str] = "seeker"

    def __init__(self, view, parts, observation_size):
        assert observation_size == 2 + 3 + 16

    def act(self, observations):
        return seek(observations)


class Sloppy:
    name: ClassVar[str] = "sloppy"

    def __init__(self, view, parts, observation_size):
        self.count = len(view)

    def act(self, observations):
        return np.full((self.count, 2), np.nan)


def test_a_policy_run_is_the_episode_an_environment_gives_with_the_same_decisions():
    with registered("cosim.agent_policies", "seeker", Seeker):
        scenario = cosim.load_scenario(
            "lab-room", {**OVERRIDES, "robots.driver": "agents", "agents.policy": "seeker"}
        )
        run = cosim.run(scenario, duration_s=6.0, seed=4)
    env = WarehouseEnv("lab-room", overrides=OVERRIDES, duration_s=6.0)
    obs, _ = env.reset(seed=4)
    done = False
    while not done:
        obs, _, _, done, _ = env.step(seek(obs).astype(np.float32))
    episode = env.result()
    for table in ("poses", "agent_arrivals", "collisions"):
        assert run.tables[table].equals(episode.tables[table]), table
    assert run.summary["agent_arrivals"] == episode.summary["agent_arrivals"] > 0


def test_the_random_policy_is_seeded_by_the_run():
    scenario = cosim.load_scenario(
        "lab-room", {"robots.driver": "agents", "agents.policy": "random"}
    )
    first = cosim.run(scenario, duration_s=2.0, seed=1).tables["poses"]
    assert first.equals(cosim.run(scenario, duration_s=2.0, seed=1).tables["poses"])
    assert not first.equals(cosim.run(scenario, duration_s=2.0, seed=2).tables["poses"])
    assert first["v_mps"].abs().max() > 0


def test_a_policy_handing_back_nan_is_named_and_the_run_kept():
    with registered("cosim.agent_policies", "sloppy", Sloppy):
        scenario = cosim.load_scenario(
            "lab-room", {"robots.driver": "agents", "agents.policy": "sloppy"}
        )
        with pytest.raises(
            PluginError,
            match=r"policy 'sloppy'.*act\(\) returned action \[nan, nan\] for robot_1: expected",
        ) as caught:
            cosim.run(scenario, duration_s=2.0)
    assert caught.value.kept.summary["failure"]["kind"] == "plugin"


def test_the_sb3_policy_needs_a_model_file():
    with pytest.raises(ConfigError, match=r"policy_file.*a model saved by Stable-Baselines3"):
        cosim.load_scenario("lab-room", {"agents.policy": "sb3"})
    with pytest.raises(ConfigError, match=r"policy_file.*an existing file"):
        cosim.load_scenario("lab-room", {"agents.policy": "sb3", "agents.policy_file": "nope.zip"})
    with pytest.raises(ConfigError, match=r"sb3_algorithm.*only"):
        cosim.load_scenario("lab-room", {"agents.sb3_algorithm": "A2C"})


def test_an_environment_refuses_a_scenario_whose_policy_decides_itself():
    with pytest.raises(ConfigError, match=r"policy = 'random': expected 'none' in an environment"):
        WarehouseEnv("lab-room", overrides={"agents.policy": "random"})


def test_the_sb3_policy_without_stable_baselines3_is_refused_when_the_run_is_built(monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util,
        "find_spec",
        lambda name, *a: None if name == "stable_baselines3" else real(name, *a),
    )
    model = "studies/policies/lab_goals_ppo.zip"
    scenario = cosim.load_scenario(
        "lab-room",
        {"robots.driver": "agents", "agents.policy": "sb3", "agents.policy_file": model},
    )  # a study naming the model loads anywhere
    with pytest.raises(ConfigError, match=r"policy = 'sb3': expected stable-baselines3 installed"):
        cosim.run(scenario, duration_s=1.0)


@settings(max_examples=25, deadline=None)
@given(st.binary(max_size=256))
def test_a_policy_file_that_is_no_saved_model_is_refused_naming_it(tmp_path_factory, content):
    model = tmp_path_factory.mktemp("garbage") / "model.zip"
    model.write_bytes(content)
    overrides = {"agents.policy": "sb3", "agents.policy_file": str(model)}
    with pytest.raises(ConfigError, match=r"policy_file = .*model\.zip.*Stable-Baselines3"):
        cosim.load_scenario("lab-room", overrides)
