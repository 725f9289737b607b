"""``cosim/Warehouse-v0``: a Gymnasium environment over any scenario, every robot at once.

One decision every ``1 / agents.decision_hz`` s of simulated time for the whole fleet: the
observation stacks every robot's (shape ``(robots, size)``), the action every robot's
(``(robots, 2)`` velocities, or ``MultiDiscrete`` place choices), the reward is the sum of
the robots'. With ``robots.count = 1`` it is a single robot's task.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np

from cosim.envs.agents import SEED_LIMIT, Agents
from cosim.envs.rendering import checked_render_mode, frame
from cosim.runner.result import RunResult
from cosim.scenario.model import Scenario
from models.arrays import Float32Array, UInt8Array


class WarehouseEnv(gymnasium.Env[Float32Array, np.ndarray]):
    """Every robot of a scenario driven by one policy (Gymnasium's ``Env``).

    Args:
        scenario: a preset name (``lab-room``), a scenario file, or a loaded scenario.
        overrides: ``{"section.key": value}`` on top of a preset or file (``[agents]`` keys
            choose what the robots see, do and are rewarded for).
        duration_s: an episode's simulated length (s); the scenario's if None.
        render_mode: None, or ``"rgb_array"``: :meth:`render` draws the room from above
            (:mod:`cosim.envs.rendering`); the run's tables and figures are in
            :meth:`result` either way.
    """

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"]}  # noqa: RUF012 (Gymnasium's own)

    def __init__(
        self,
        scenario: str | Path | Scenario = "lab-room",
        overrides: Mapping[str, Any] | None = None,
        duration_s: float | None = None,
        render_mode: str | None = None,
    ) -> None:
        self.render_mode = checked_render_mode(render_mode)
        self.agents = Agents(scenario, overrides, duration_s)
        self.metadata = {**self.metadata, "render_fps": self.agents.settings.decision_hz}
        n = len(self.agents)
        one_obs, one_action = self.agents.observation_space, self.agents.action_space
        self.observation_space = gymnasium.spaces.Box(
            np.tile(one_obs.low, (n, 1)), np.tile(one_obs.high, (n, 1)), dtype=np.float32
        )
        if isinstance(one_action, gymnasium.spaces.Discrete):
            self.action_space: gymnasium.spaces.Space[Any] = gymnasium.spaces.MultiDiscrete(
                [int(one_action.n)] * n
            )
        else:
            assert isinstance(one_action, gymnasium.spaces.Box)
            self.action_space = gymnasium.spaces.Box(
                np.tile(one_action.low, (n, 1)), np.tile(one_action.high, (n, 1)), dtype=np.float32
            )
        self._all = np.arange(n)

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Float32Array, dict[str, Any]]:
        """Start an episode: the scenario's seed first, ``seed`` if given, else a drawn one."""
        super().reset(seed=seed)
        if seed is None and not self.agents.fresh:
            seed = int(self.np_random.integers(SEED_LIMIT))
        self.agents.reset(seed)
        return self.agents.observe().copy(), self.agents.info()

    def step(self, action: np.ndarray) -> tuple[Float32Array, float, bool, bool, dict[str, Any]]:
        """Apply every robot's action, run one decision period, observe."""
        self.agents.act(self._all, np.asarray(action))
        self.agents.advance_all()
        rewards = self.agents.rewards(self._all)
        info = self.agents.info()
        info["rewards"] = rewards
        return self.agents.observe().copy(), float(rewards.sum()), False, self.agents.ended, info

    def render(self) -> UInt8Array | None:
        """The room from above (``render_mode="rgb_array"``), else None."""
        if self.render_mode != "rgb_array":
            return None
        return frame(self.agents.episode.view)

    def result(self) -> RunResult:
        """The episode's run: its summary and tables (``result().tables["poses"]``).

        Called once the episode is truncated, it is the whole episode; called before, the
        episode ends where it is (reset to start another).
        """
        return self.agents.finish()

    def close(self) -> None:
        """End the episode (its result stays available)."""
        self.agents.finish()
