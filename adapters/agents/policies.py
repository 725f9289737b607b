"""cosim's own agent policies, registered in ``cosim.agent_policies`` as a plugin's are.

A policy decides for the agents in a plain run (``cosim run``, a study), so that a policy
learnt in :mod:`cosim.envs` is measured with the same tables, studies and figures as the
hand-written drivers it is compared with.
"""

from __future__ import annotations

import importlib
import zipfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from adapters.agents.contract import AgentParts, AgentView, BoxSpec
from adapters.agents.settings import AgentsConfig
from cosim.core.errors import ConfigError
from cosim.scenario.fields import Problem
from models.arrays import Float32Array


class RandomPolicy:
    """``random``: every action drawn uniformly from the action's space (a baseline).

    Draws come from the run's ``agents/policy`` stream: a seed gives the same run.
    """

    name: ClassVar[str] = "random"

    def __init__(self, view: AgentView, parts: AgentParts, observation_size: int) -> None:
        self.spec = parts.action.spec
        self.count = len(view)
        self.rng = view.run.rng.stream("agents/policy")

    def act(self, observations: Float32Array) -> np.ndarray:
        """Uniform draws, one row per agent."""
        if isinstance(self.spec, BoxSpec):
            low, high = np.array(self.spec.low), np.array(self.spec.high)
            return self.rng.uniform(low, high, size=(self.count, len(low)))
        return self.rng.integers(self.spec.n, size=self.count)


class Sb3Policy:
    """``sb3``: a model trained with Stable-Baselines3, loaded from ``agents.policy_file``.

    ``agents.sb3_algorithm`` names its class (``PPO``, ``A2C``, ``SAC``, ...). A model
    trained on ``cosim/Warehouse-v0`` observes every robot at once (``(robots, size)``,
    the fleet's size must match); one trained on a single agent's observation (``(size,)``)
    acts for each agent in turn. It acts deterministically, on one thread (a study runs
    several runs side by side). Needs ``pip install 'cosim[rl]'``.
    """

    name: ClassVar[str] = "sb3"
    keys: ClassVar[tuple[str, ...]] = ("policy_file", "sb3_algorithm")

    @classmethod
    def problems(cls, section: AgentsConfig) -> Iterator[Problem]:
        """A model file is named and exists (Stable-Baselines3 is looked for by the run)."""
        if not section.policy_file:
            yield Problem("policy_file", "", "a model saved by Stable-Baselines3 (model.save)")
        elif not Path(section.policy_file).is_file():
            yield Problem("policy_file", section.policy_file, "an existing file")
        elif not zipfile.is_zipfile(section.policy_file):
            yield Problem(
                "policy_file",
                section.policy_file,
                "a model saved by Stable-Baselines3 (model.save writes a zip file)",
            )

    def __init__(self, view: AgentView, parts: AgentParts, observation_size: int) -> None:
        if importlib.util.find_spec("stable_baselines3") is None:
            raise ConfigError(
                f"{view.run.scenario.source}: [agents] policy = 'sb3': expected "
                "stable-baselines3 installed (pip install 'cosim[rl]'), not found"
            )
        import stable_baselines3
        import torch

        torch.set_num_threads(1)
        settings = view.settings
        algorithm = getattr(stable_baselines3, settings.sb3_algorithm, None)
        if algorithm is None or not hasattr(algorithm, "load"):
            raise ConfigError(
                f"{view.run.scenario.source}: [agents] sb3_algorithm = "
                f"{settings.sb3_algorithm!r}: expected a Stable-Baselines3 algorithm (PPO, A2C, "
                "SAC, TD3, DQN)"
            )
        try:
            self.model: Any = algorithm.load(settings.policy_file, device="cpu")
        except Exception as error:  # a zip that is no model of this algorithm: the file's fault
            raise ConfigError(
                f"{view.run.scenario.source}: [agents] policy_file = {settings.policy_file!r}: "
                f"expected a {settings.sb3_algorithm} model saved by Stable-Baselines3; loading "
                f"it raised {type(error).__name__}: {error}"
            ) from error
        shape = tuple(self.model.observation_space.shape)
        fleet, one = (len(view), observation_size), (observation_size,)
        if shape not in (fleet, one):
            raise ConfigError(
                f"{view.run.scenario.source}: [agents] policy_file = {settings.policy_file!r} "
                f"observes shape {shape}: expected {one} (one agent) or {fleet} (the fleet): "
                "the same [agents] observe and robots.count it was trained with"
            )

    def act(self, observations: Float32Array) -> np.ndarray:
        """The model's deterministic actions for every agent."""
        actions, _ = self.model.predict(observations, deterministic=True)
        return np.asarray(actions)
