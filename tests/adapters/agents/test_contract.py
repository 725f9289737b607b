from typing import ClassVar

import pytest

import cosim
from adapters.agents.contract import ACTIONS, OBSERVATIONS, REWARDS
from cosim.core.errors import RegistryError
from cosim.core.registry import registered


def test_cosims_own_parts_are_registered_as_plugins_are():
    assert set(OBSERVATIONS.installed().names()) >= {
        "pose",
        "velocity",
        "goal",
        "lidar",
        "inbox",
        "places",
    }
    assert set(ACTIONS.installed().names()) >= {"velocity", "goal"}
    assert set(REWARDS.installed().names()) >= {
        "progress",
        "arrived",
        "time",
        "contact",
        "messages",
    }


class NoTotal:
    name: ClassVar[str] = "no_total"


def test_a_reward_term_without_total_is_refused_naming_the_contract():
    with registered("cosim.agent_rewards", "no_total", NoTotal):
        scenario = cosim.load_scenario(
            "lab-room", {"agents.rewards": ["no_total"], "agents.reward_weights": [1.0]}
        )
        with pytest.raises(RegistryError, match=r"no_total.*total\(\)"):
            REWARDS.installed().get("no_total")
        assert scenario.agents.rewards == ("no_total",)
