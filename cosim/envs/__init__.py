"""Learning environments over any scenario: Gymnasium and PettingZoo.

``import cosim.envs`` registers ``cosim/Warehouse-v0`` with Gymnasium::

    import gymnasium
    import cosim.envs

    env = gymnasium.make("cosim/Warehouse-v0", scenario="lab-room",
                         overrides={"robots.count": 1})

(``gymnasium.make("cosim.envs:cosim/Warehouse-v0", ...)`` imports it on its own.) PettingZoo's
parallel and AEC environments are :class:`WarehouseParallelEnv` and
:class:`WarehouseAECEnv` (:func:`parallel_env`, :func:`env`). What the agents see, do and
are rewarded for is ``[agents]`` (:mod:`adapters.agents`).
"""

from __future__ import annotations

from typing import Any

import gymnasium

from cosim.envs.aec_env import WarehouseAECEnv
from cosim.envs.agents import Agents
from cosim.envs.episode import Episode, agents_scenario
from cosim.envs.gym_env import WarehouseEnv
from cosim.envs.parallel_env import WarehouseParallelEnv

ENV_ID = "cosim/Warehouse-v0"
"""The Gymnasium id of :class:`WarehouseEnv`."""


def register_envs() -> None:
    """Register ``cosim/Warehouse-v0`` with Gymnasium (once; done on import)."""
    if ENV_ID not in gymnasium.registry:
        gymnasium.register(ENV_ID, entry_point="cosim.envs.gym_env:WarehouseEnv")


def parallel_env(**kwargs: Any) -> WarehouseParallelEnv:
    """A :class:`WarehouseParallelEnv` (PettingZoo's ``parallel_env`` convention)."""
    return WarehouseParallelEnv(**kwargs)


def env(**kwargs: Any) -> WarehouseAECEnv:
    """A :class:`WarehouseAECEnv` (PettingZoo's ``env`` convention)."""
    return WarehouseAECEnv(**kwargs)


register_envs()

__all__ = [
    "ENV_ID",
    "Agents",
    "Episode",
    "WarehouseAECEnv",
    "WarehouseEnv",
    "WarehouseParallelEnv",
    "agents_scenario",
    "env",
    "parallel_env",
    "register_envs",
]
