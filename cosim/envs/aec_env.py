"""A PettingZoo ``AECEnv``: agents decide one at a time, when their moment comes.

An agent's moment is its next period (``agents.decision_hz``; spread over the period
with ``agents.stagger``) or, sooner, an event it wakes on (``agents.wake_on``: its goal
reached, a pose heard over the network, a contact), as sumo-rl's users ask of traffic
lights. ``agent_selection`` is always the agent whose moment is the earliest; the kernel
runs between two moments and stops after the instant of a waking event. Each agent is
rewarded for its own interval between two decisions.
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import cache
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from pettingzoo import AECEnv

from cosim.envs.agents import SEED_LIMIT, Agents
from cosim.envs.rendering import frame
from cosim.runner.result import RunResult
from cosim.scenario.model import Scenario
from models.arrays import Float32Array, UInt8Array


class WarehouseAECEnv(AECEnv[str, Float32Array, Any]):
    """Every robot an agent deciding at its own instants (PettingZoo's AEC API).

    Args:
        scenario: a preset name, a scenario file, or a loaded scenario.
        overrides: ``{"section.key": value}`` on top of a preset or file.
        duration_s: an episode's simulated length (s); the scenario's if None.
        render_mode: None, or ``"rgb_array"`` (:meth:`render` draws the room from above).
    """

    metadata: dict[str, Any] = {  # noqa: RUF012 (PettingZoo's own field; render_fps per env)
        "name": "cosim_warehouse_aec_v0",
        "render_modes": ["rgb_array"],
    }

    def __init__(
        self,
        scenario: str | Path | Scenario = "lab-room",
        overrides: Mapping[str, Any] | None = None,
        duration_s: float | None = None,
        render_mode: str | None = None,
    ) -> None:
        super().__init__()
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode={render_mode!r}: expected None or 'rgb_array'")
        self.render_mode = render_mode
        self.core = Agents(scenario, overrides, duration_s)
        self.metadata = {**self.metadata, "render_fps": self.core.settings.decision_hz}
        self.possible_agents = list(self.core.names)
        self.index = {a: i for i, a in enumerate(self.possible_agents)}
        self.observation_spaces = {a: self.core.observation_space for a in self.possible_agents}
        self.action_spaces = {a: self.core.action_space for a in self.possible_agents}
        self._rng = np.random.default_rng()

    @cache  # noqa: B019 (one entry per agent, as PettingZoo's own envs)
    def observation_space(self, agent: str) -> gymnasium.spaces.Space[Any]:
        """An agent's observation space."""
        return self.observation_spaces[agent]

    @cache  # noqa: B019
    def action_space(self, agent: str) -> gymnasium.spaces.Space[Any]:
        """An agent's action space."""
        return self.action_spaces[agent]

    def reset(self, seed: int | None = None, options: dict[str, Any] | None = None) -> None:
        """Start an episode: the scenario's seed first, ``seed`` if given, else a drawn one."""
        if seed is not None:
            self._rng = np.random.default_rng(seed)
        elif not self.core.fresh:
            seed = int(self._rng.integers(SEED_LIMIT))
        self.core.reset(seed)
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

    def render(self) -> UInt8Array | None:
        """The room from above (``render_mode="rgb_array"``), else None."""
        if self.render_mode != "rgb_array":
            return None
        return frame(self.core.episode.view)

    def state(self) -> Float32Array:
        """Every agent's observation, stacked (agents, size)."""
        return self.core.observe().copy()

    def result(self) -> RunResult:
        """The episode's run: its summary and tables (ends it where it is if not ended)."""
        return self.core.finish()

    def close(self) -> None:
        """End the episode (its result stays available)."""
        self.core.finish()
