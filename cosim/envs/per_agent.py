"""What PettingZoo's parallel and AEC environments share: one agent per robot.

Agents are named after their robots (``robot_1``, ...); every agent has the same spaces; a
reset without a seed draws the next episode's seed from the last seed given.
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import cache
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np

from cosim.envs.agents import SEED_LIMIT, Agents
from cosim.envs.rendering import checked_render_mode, frame
from cosim.runner.result import RunResult
from cosim.scenario.model import Scenario
from models.arrays import Float32Array, UInt8Array


class PerAgent:
    """A mixin of the PettingZoo environments: the robots as agents of one :class:`Agents`.

    Args:
        scenario: a preset name, a scenario file, or a loaded scenario.
        overrides: ``{"section.key": value}`` on top of a preset or file.
        duration_s: an episode's simulated length (s); the scenario's if None.
        render_mode: None, or ``"rgb_array"`` (:meth:`render` draws the room from above).
    """

    metadata: dict[str, Any]

    def __init__(
        self,
        scenario: str | Path | Scenario = "lab-room",
        overrides: Mapping[str, Any] | None = None,
        duration_s: float | None = None,
        render_mode: str | None = None,
    ) -> None:
        self.render_mode = checked_render_mode(render_mode)
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

    def _start_episode(self, seed: int | None) -> None:
        """The scenario's seed first, ``seed`` if given, else one drawn from the last given."""
        if seed is not None:
            self._rng = np.random.default_rng(seed)
        elif not self.core.fresh:
            seed = int(self._rng.integers(SEED_LIMIT))
        self.core.reset(seed)

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
