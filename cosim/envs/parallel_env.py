"""A PettingZoo ``ParallelEnv``: one agent per robot, all deciding every period.

Agents are named after their robots (``robot_1``, ...). Each sees its own observation
(shape ``(size,)``), acts alone, and is rewarded for its own interval; every agent is
truncated when the episode reaches its duration.
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import cache
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from pettingzoo import ParallelEnv

from cosim.envs.agents import SEED_LIMIT, Agents
from cosim.envs.rendering import frame
from cosim.runner.result import RunResult
from cosim.scenario.model import Scenario
from models.arrays import Float32Array, UInt8Array


class WarehouseParallelEnv(ParallelEnv[str, Float32Array, Any]):
    """Every robot of a scenario an agent of its own, deciding at once (PettingZoo).

    Args:
        scenario: a preset name, a scenario file, or a loaded scenario.
        overrides: ``{"section.key": value}`` on top of a preset or file.
        duration_s: an episode's simulated length (s); the scenario's if None.
        render_mode: None, or ``"rgb_array"`` (:meth:`render` draws the room from above).
    """

    metadata: dict[str, Any] = {  # noqa: RUF012 (PettingZoo's own field; render_fps per env)
        "name": "cosim_warehouse_v0",
        "render_modes": ["rgb_array"],
    }

    def __init__(
        self,
        scenario: str | Path | Scenario = "lab-room",
        overrides: Mapping[str, Any] | None = None,
        duration_s: float | None = None,
        render_mode: str | None = None,
    ) -> None:
        if render_mode not in (None, "rgb_array"):
            raise ValueError(f"render_mode={render_mode!r}: expected None or 'rgb_array'")
        self.render_mode = render_mode
        self.core = Agents(scenario, overrides, duration_s)
        self.metadata = {**self.metadata, "render_fps": self.core.settings.decision_hz}
        self.possible_agents = list(self.core.names)
        self.agents: list[str] = []
        self.observation_spaces = {a: self.core.observation_space for a in self.possible_agents}
        self.action_spaces = {a: self.core.action_space for a in self.possible_agents}
        self._all = np.arange(len(self.possible_agents))
        self._rng = np.random.default_rng()

    @cache  # noqa: B019 (one entry per agent, as PettingZoo's own envs)
    def observation_space(self, agent: str) -> gymnasium.spaces.Space[Any]:
        """An agent's observation space."""
        return self.observation_spaces[agent]

    @cache  # noqa: B019
    def action_space(self, agent: str) -> gymnasium.spaces.Space[Any]:
        """An agent's action space."""
        return self.action_spaces[agent]

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Float32Array], dict[str, dict[str, Any]]]:
        """Start an episode: the scenario's seed first, ``seed`` if given, else a drawn one."""
        if seed is not None:
            self._rng = np.random.default_rng(seed)
        elif not self.core.fresh:
            seed = int(self._rng.integers(SEED_LIMIT))
        self.core.reset(seed)
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
        rewards = self.core.rewards(self._all)
        obs = self.core.observe()
        ended = self.core.ended
        info = self.core.info()
        live = list(self.agents)
        if ended:
            self.agents = []
        return (
            {a: obs[names.index(a)].copy() for a in live},
            {a: float(rewards[names.index(a)]) for a in live},
            {a: False for a in live},
            {a: ended for a in live},
            {a: dict(info) for a in live},
        )

    def render(self) -> UInt8Array | None:
        """The room from above (``render_mode="rgb_array"``), else None."""
        if self.render_mode != "rgb_array":
            return None
        return frame(self.core.episode.view)

    def state(self) -> Float32Array:
        """Every agent's observation, stacked (agents, size): a centralized critic's input."""
        return self.core.observe().copy()

    def result(self) -> RunResult:
        """The episode's run: its summary and tables (ends it where it is if not ended)."""
        return self.core.finish()

    def close(self) -> None:
        """End the episode (its result stays available)."""
        self.core.finish()
