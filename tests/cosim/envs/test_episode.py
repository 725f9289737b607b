from typing import ClassVar

import numpy as np
import pytest

import cosim
from cosim.core.plugins import PluginError
from cosim.core.registry import registered
from cosim.envs import WarehouseEnv
from cosim.envs.episode import Episode, agents_scenario
from cosim.runner.assembly import adapter_names
from cosim.scenario.arguments import ArgumentError


class Wild:
    """Test part: the robot's x, but once past 1 s it reports NaN."""

    name: ClassVar[str] = "wild"

    def __init__(self, view):
        self.low, self.high = np.zeros(1, np.float32), np.full(1, 100.0, np.float32)

    def observe(self, view, out):
        out[:, 0] = view.fleet.x if view.now_ns < 1_000_000_000 else np.nan


class Crashing:
    """Test term: raises once past 1 s."""

    name: ClassVar[str] = "crashing"

    def __init__(self, view):
        pass

    def total(self, view):
        if view.now_ns >= 1_000_000_000:
            raise KeyError("robot_9")
        return np.zeros(len(view))


def _drive(env):
    env.reset(seed=1)
    for _ in range(30):
        env.step(np.full(env.action_space.shape, 0.2, np.float32))


def test_a_part_writing_nan_is_named_and_what_ran_is_kept():
    with registered("cosim.agent_observations", "wild", Wild):
        env = WarehouseEnv("lab-room", overrides={"agents.observe": ["wild"]}, duration_s=5.0)
        with pytest.raises(PluginError) as caught:
            _drive(env)
    error = caught.value
    assert "agent observation part 'wild'" in str(error)
    assert "observe() wrote nan for robot_1 at index 0" in str(error)
    assert "[0, 100]" in str(error)
    kept = error.kept
    assert kept is not None and kept.summary["failure"]["kind"] == "plugin"
    assert kept.summary["sim_time_s"] == pytest.approx(1.0)
    assert kept.tables["poses"]["t_s"].max() == pytest.approx(0.9)  # sampled at 10 Hz


def test_a_reward_term_raising_is_blamed_on_it_with_its_traceback():
    overrides = {"agents.rewards": ["progress", "crashing"], "agents.reward_weights": [1.0, 1.0]}
    with registered("cosim.agent_rewards", "crashing", Crashing):
        env = WarehouseEnv("lab-room", overrides=overrides, duration_s=5.0)
        with pytest.raises(PluginError) as caught:
            _drive(env)
    assert "raised KeyError: 'robot_9'" in str(caught.value)
    assert "Crashing.total" in str(caught.value)
    assert caught.value.kept.summary["sim_time_s"] == pytest.approx(1.0)


def test_bad_actions_are_refused_and_the_episode_goes_on():
    env = WarehouseEnv("lab-room", duration_s=1.0)
    env.reset(seed=1)
    with pytest.raises(ValueError, match=r"action \[nan, 0.0\] for robot_3: expected finite"):
        env.step(np.array([[0, 0], [0, 0], [np.nan, 0], [0, 0]], np.float32))
    with pytest.raises(ValueError, match=r"shape \(3, 2\): expected \(4, 2\)"):
        env.step(np.zeros((3, 2), np.float32))
    env.step(np.zeros((4, 2), np.float32))
    assert env.agents.now_ns == 100_000_000


def test_a_goal_choice_out_of_range_is_refused():
    env = WarehouseEnv("lab-room", overrides={"agents.action": "goal"}, duration_s=1.0)
    env.reset(seed=1)
    with pytest.raises(ValueError, match=r"action 8 for robot_1: expected a whole number 0..7"):
        env.step(np.array([8, 0, 0, 0]))


def test_the_scenario_runs_the_agents_driver_and_what_the_action_needs():
    scenario = agents_scenario("warehouse-random", {"agents.action": "goal"})
    assert scenario.robots.driver == "agents"
    assert "navigation" in adapter_names(scenario)  # the goal action drives through it
    assert "navigation" not in adapter_names(agents_scenario("lab-room"))
    loaded = cosim.load_scenario("lab-room")
    assert agents_scenario(loaded).robots.driver == "agents"
    with pytest.raises(ArgumentError, match="overrides go with a preset name"):
        agents_scenario(loaded, {"robots.count": 2})


def test_an_episode_closed_early_covers_the_time_it_ran():
    episode = Episode(agents_scenario("lab-room"))
    episode.advance(700_000_000)
    result = episode.close()
    assert result.summary["sim_time_s"] == pytest.approx(0.7)
    assert "failed" not in result.summary
    assert episode.close() is result
