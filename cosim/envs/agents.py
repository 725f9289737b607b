"""What every environment of :mod:`cosim.envs` shares: episodes, spaces, decisions.

:class:`Agents` builds an episode per ``reset``, declares the spaces of one agent from
the chosen observation parts and action kind, and steps agents at their decision
instants. The Gymnasium, PettingZoo parallel and AEC environments are views of it.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np

from adapters.agents.contract import BoxSpec, ChoiceSpec
from adapters.agents.settings import AgentsConfig
from cosim.core.timebase import NS_PER_S, period_ns
from cosim.envs.episode import Episode, agents_scenario
from cosim.runner.result import RunResult
from cosim.scenario.arguments import ArgumentError
from cosim.scenario.model import Scenario
from models.arrays import Float32Array, FloatArray, IntArray

SEED_LIMIT = 2**31
"""Seeds drawn for episodes after the first are below this."""


def action_space(spec: BoxSpec | ChoiceSpec) -> gymnasium.spaces.Space[Any]:
    """One agent's action space for an action kind's spec."""
    if isinstance(spec, ChoiceSpec):
        return gymnasium.spaces.Discrete(spec.n)
    return gymnasium.spaces.Box(
        np.array(spec.low, dtype=np.float32), np.array(spec.high, dtype=np.float32)
    )


class Agents:
    """Learning agents over one scenario: one episode at a time.

    Args:
        scenario: a preset name, a scenario file, or a loaded scenario.
        overrides: ``{"section.key": value}`` on top of a preset or file.
        duration_s: an episode's simulated length (s); the scenario's ``duration_s`` if
            None.

    Raises:
        ConfigError: a bad scenario, key or value (before anything runs).
    """

    def __init__(
        self,
        scenario: str | Path | Scenario = "lab-room",
        overrides: Mapping[str, Any] | None = None,
        duration_s: float | None = None,
    ) -> None:
        base = agents_scenario(scenario, overrides)
        if duration_s is not None:
            base = base.with_duration(duration_s)
        self.base = base
        self.settings = base.section(AgentsConfig)
        self.period_ns = period_ns(self.settings.decision_hz)
        self.episode = Episode(base)
        self.fresh = True
        """Whether the episode has not been stepped (reset need not rebuild it)."""
        self.last: RunResult | None = None
        view, parts = self.episode.view, self.episode.parts
        self.names = list(view.names)
        low = [part.low for part in parts.observations]
        high = [part.high for part in parts.observations]
        self.observation_space = gymnasium.spaces.Box(
            np.concatenate(low).astype(np.float32), np.concatenate(high).astype(np.float32)
        )
        self.action_space = action_space(parts.action.spec)
        self.obs = np.zeros((len(self.names), len(self.observation_space.low)), dtype=np.float32)
        self.due_ns = self._first_decisions()

    def __len__(self) -> int:
        return len(self.names)

    @property
    def now_ns(self) -> int:
        """The episode's simulated time (ns)."""
        return self.episode.now_ns

    @property
    def ended(self) -> bool:
        """Whether the episode reached its end."""
        return self.episode.ended

    def _first_decisions(self) -> IntArray:
        n = len(self.names)
        if not self.settings.stagger:
            return np.zeros(n, dtype=np.int64)
        return (np.arange(n, dtype=np.int64) * self.period_ns) // n

    def reset(self, seed: int | None) -> None:
        """Start a new episode (the scenario's seed, or ``seed``); the last one is closed."""
        if seed is not None and not (isinstance(seed, int) and not isinstance(seed, bool)):
            raise ArgumentError(f"reset(seed={seed!r}): expected an int >= 0 or None")
        scenario = self.base if seed is None else self.base.with_seed(seed)
        if self.fresh and not self.episode.closed and scenario.seed == self.episode.scenario.seed:
            return  # the episode built for this seed has not moved yet: it is the new one
        self.finish()
        self.episode = Episode(scenario)
        self.fresh = True
        self.due_ns = self._first_decisions()

    def finish(self) -> RunResult:
        """Close the episode where it is; its result (tables, summary) is :attr:`last`."""
        self.last = self.episode.close()
        return self.last

    def observe(self) -> Float32Array:
        """Every agent's observation now, (agents, size) float32 (a buffer reused)."""
        self.episode.observe(self.obs)
        return self.obs

    def act(self, agents: IntArray, actions: np.ndarray) -> None:
        """Apply the actions of ``agents`` now; each decides next a period later."""
        self.fresh = False
        now = self.now_ns
        self.episode.act(agents, actions)
        self.episode.view.decided_ns[agents] = now
        self.due_ns[agents] = now + self.period_ns

    def rewards(self, agents: IntArray) -> FloatArray:
        """Each agent's reward since its previous one."""
        return self.episode.rewards(agents)

    def advance_all(self) -> None:
        """Run one decision period: every agent decides again at its end."""
        self.due_ns[:] = self.now_ns + self.period_ns
        self.episode.advance(int(self.due_ns[0]))

    def next_deciding(self) -> int | None:
        """Run until an agent is due, by its period or an event it wakes on; its index.

        None when the episode ends first.
        """
        view = self.episode.view
        while True:
            now = self.now_ns
            due = (self.due_ns <= now) | (view.woken_ns > view.decided_ns)
            if due.any() and not self.ended:
                return int(np.flatnonzero(due)[0])
            if self.ended:
                return None

            def woken() -> bool:
                return bool((view.woken_ns > view.decided_ns).any())

            self.episode.advance(int(self.due_ns.min()), woken)

    def info(self) -> dict[str, Any]:
        """What every step tells besides the observation: the time (s)."""
        return {"t_s": self.now_ns / NS_PER_S}
