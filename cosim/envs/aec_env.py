"""A PettingZoo ``AECEnv``: agents decide one at a time, when their moment comes.

An agent's moment is its next period (``agents.decision_hz``; spread over the period
with ``agents.stagger``) or, sooner, an event it wakes on (``agents.wake_on``: its goal
reached, a pose heard over the network, a contact), as sumo-rl's users ask of traffic
lights. ``agent_selection`` is always the agent whose moment is the earliest; the kernel
runs between two moments and stops after the instant of a waking event. Each agent is
rewarded for its own interval between two decisions.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pettingzoo import AECEnv

from cosim.envs.per_agent import PerAgent
from models.arrays import Float32Array


class WarehouseAECEnv(PerAgent, AECEnv[str, Float32Array, Any]):
    """Every robot an agent deciding at its own instants (PettingZoo's AEC API).

    Built as :class:`~cosim.envs.per_agent.PerAgent` (scenario, overrides, duration_s,
    render_mode).
    """

    metadata: dict[str, Any] = {  # noqa: RUF012 (PettingZoo's own field; render_fps per env)
        "name": "cosim_warehouse_aec_v0",
        "render_modes": ["rgb_array"],
    }

    def reset(self, seed: int | None = None, options: dict[str, Any] | None = None) -> None:
        """Start an episode: the scenario's seed first, ``seed`` if given, else a drawn one."""
        self._start_episode(seed)
        self.agents = list(self.possible_agents)
        self.rewards = {a: 0.0 for a in self.agents}
        self._cumulative_rewards = {a: 0.0 for a in self.agents}
        self.terminations = {a: False for a in self.agents}
        self.truncations = {a: False for a in self.agents}
        self.infos = {a: self.core.info() for a in self.agents}
        first = self.core.next_deciding()
        self.agent_selection = self.possible_agents[first if first is not None else 0]

    def observe(self, agent: str) -> Float32Array:
        """What ``agent`` sees now."""
        row: Float32Array = self.core.observe()[self.index[agent]].copy()
        return row

    def step(self, action: Any) -> None:
        """Apply the selected agent's action; run to the next agent's moment."""
        agent = self.agent_selection
        if self.terminations[agent] or self.truncations[agent]:
            self._was_dead_step(action)
            return
        self._cumulative_rewards[agent] = 0.0
        i = self.index[agent]
        self.core.act(np.array([i]), np.asarray(action)[None])
        self._clear_rewards()
        following = self.core.next_deciding()
        info = self.core.info()
        for live in self.agents:
            self.infos[live] = dict(info)
        if following is None:  # the episode ended: every agent is truncated
            gains = self.core.rewards(np.array([self.index[a] for a in self.agents]))
            for live, gain in zip(self.agents, gains, strict=True):
                self.rewards[live] = float(gain)
                self.truncations[live] = True
            self._accumulate_rewards()
            self._deads_step_first()
            return
        nxt = self.possible_agents[following]
        self.rewards[nxt] = float(self.core.rewards(np.array([following]))[0])
        self.agent_selection = nxt
        self._accumulate_rewards()
