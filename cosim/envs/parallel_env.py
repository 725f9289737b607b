"""A PettingZoo ``ParallelEnv``: one agent per robot, all deciding every period.

Agents are named after their robots (``robot_1``, ...). Each sees its own observation
(shape ``(size,)``), acts alone, and is rewarded for its own interval; every agent is
truncated when the episode reaches its duration. An agent left out of a step's actions
keeps its last action.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from pettingzoo import ParallelEnv

from cosim.envs.per_agent import PerAgent
from models.arrays import Float32Array


class WarehouseParallelEnv(PerAgent, ParallelEnv[str, Float32Array, Any]):
    """Every robot of a scenario an agent of its own, deciding at once (PettingZoo).

    Built as :class:`~cosim.envs.per_agent.PerAgent` (scenario, overrides, duration_s,
    render_mode).
    """

    metadata: dict[str, Any] = {  # noqa: RUF012 (PettingZoo's own field; render_fps per env)
        "name": "cosim_warehouse_v0",
        "render_modes": ["rgb_array"],
    }
    agents: list[str] = []  # noqa: RUF012 (PettingZoo's field: the live agents, set by reset)

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Float32Array], dict[str, dict[str, Any]]]:
        """Start an episode: the scenario's seed first, ``seed`` if given, else a drawn one."""
        self._start_episode(seed)
        self.agents = list(self.possible_agents)
        obs = self.core.observe()
        info = self.core.info()
        return (
            {a: obs[i].copy() for i, a in enumerate(self.agents)},
            {a: dict(info) for a in self.agents},
        )

    def step(
        self, actions: Mapping[str, Any]
    ) -> tuple[
        dict[str, Float32Array],
        dict[str, float],
        dict[str, bool],
        dict[str, bool],
        dict[str, dict[str, Any]],
    ]:
        """Apply every live agent's action, run one decision period, observe."""
        names = self.possible_agents
        acting = np.array([i for i, a in enumerate(names) if a in actions], dtype=np.int64)
        if len(acting):
            rows = np.stack([np.asarray(actions[names[i]]) for i in acting])
            self.core.act(acting, rows)
        self.core.advance_all()
        rewards = self.core.rewards(np.arange(len(names)))
        obs = self.core.observe()
        ended = self.core.ended
        info = self.core.info()
        live = list(self.agents)
        if ended:
            self.agents = []
        index = self.index
        return (
            {a: obs[index[a]].copy() for a in live},
            {a: float(rewards[index[a]]) for a in live},
            {a: False for a in live},
            {a: ended for a in live},
            {a: dict(info) for a in live},
        )
