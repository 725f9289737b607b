"""One episode: a scenario's run, assembled once and advanced decision by decision.

The environments of :mod:`cosim.envs` hold one :class:`Episode` at a time. It runs the
same adapters ``cosim run`` would (the driver replaced by the ``agents`` adapter), so an
episode's tables are a run's tables: :meth:`Episode.result` gives them once it ended.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from adapters.agents.boundary import action_problem, observe_all, reward_totals
from adapters.agents.contract import AgentParts, AgentView
from adapters.agents.settings import AgentsConfig
from cosim.core.errors import BridgeError, ConfigError, CosimError, ExportError
from cosim.core.plugins import PluginError
from cosim.core.registry import AdapterRegistry
from cosim.core.timebase import NS_PER_S, s_to_ns
from cosim.runner.assembly import Assembly, assemble
from cosim.runner.conclusion import close_adapters, conclude
from cosim.runner.faults import Hung, fault_of, plugin_faults_named
from cosim.runner.result import RunResult
from cosim.scenario.arguments import ArgumentError
from cosim.scenario.loader import check_runnable, load_scenario
from cosim.scenario.model import Scenario
from models.arrays import Float32Array, FloatArray, IntArray

DRIVER = "agents"
"""The driver every robot of an environment's scenario runs."""


def agents_scenario(
    scenario: str | Path | Scenario, overrides: Mapping[str, Any] | None = None
) -> Scenario:
    """A scenario whose robots learning agents drive.

    Args:
        scenario: a preset name, a scenario file, or a loaded scenario.
        overrides: ``{"section.key": value}`` on top of a preset or file (``agents.action``,
            ``robots.count``, ...); a loaded scenario takes none (load it with them).

    Returns:
        The scenario with ``robots.driver = "agents"`` (``[agents]`` adds what its action
        kind needs: ``navigation`` for ``goal``).

    Raises:
        ConfigError: a bad file, key or value (named as ``cosim run`` names it).
        ArgumentError: overrides given with a loaded scenario.
    """
    if isinstance(scenario, Scenario):
        if overrides:
            raise ArgumentError(
                "cosim.envs: overrides go with a preset name or a scenario file, not with a "
                "loaded Scenario (load it with them: cosim.load_scenario(name, overrides))"
            )
        base = scenario
    else:
        base = load_scenario(scenario, dict(overrides or {}), override_origin="overrides")
    policy = base.section(AgentsConfig).policy
    if policy != "none":
        raise ConfigError(
            f"{base.source}: [agents] policy = {policy!r}: expected 'none' in an environment "
            "(the environment's caller decides; a policy decides in cosim run and studies)"
        )
    base = base.with_section("robots", replace(base.robots, driver=DRIVER))
    return base


class Episode:
    """A scenario's run, started and advanced by the caller.

    Args:
        scenario: a scenario whose driver is ``agents`` (:func:`agents_scenario`).
        registry: adapter registry; defaults to the installed entry points.

    Raises:
        ConfigError: what the scenario cannot run with (refused before anything runs).
        PluginError: a plugin's code failed while the run was built or started.
    """

    def __init__(self, scenario: Scenario, registry: AdapterRegistry | None = None) -> None:
        check_runnable(scenario)
        self.scenario = scenario
        with plugin_faults_named("building the run"):
            self.assembly: Assembly = assemble(
                scenario, registry=registry or AdapterRegistry.from_entry_points()
            )
        run = self.assembly.run
        self.view = run.service(AgentView)
        self.parts = run.service(AgentParts)
        self.end_ns = s_to_ns(scenario.scenario.duration_s)
        self.wall_s = 0.0
        self.events = 0
        self._result: RunResult | None = None
        self._closed = False
        doing = "starting the run"
        try:
            for name, adapter in self.assembly.adapters:
                doing = f"starting adapter {name!r}"
                adapter.start(run)
        except (Exception, Hung) as error:
            self._fail(fault_of(error, doing=doing, t_ns=run.kernel.now_ns))
        self._totals = self._reward_totals()

    @property
    def now_ns(self) -> int:
        """The episode's simulated time (ns)."""
        return self.assembly.run.kernel.now_ns

    @property
    def closed(self) -> bool:
        """Whether the run was closed (its result gathered, or failed)."""
        return self._closed

    @property
    def ended(self) -> bool:
        """Whether the run reached its duration (or was closed)."""
        return self._closed or self.now_ns >= self.end_ns

    def advance(self, until_ns: int, woken: Callable[[], bool] | None = None) -> None:
        """Run the kernel to ``until_ns`` (at most the run's end), or until ``woken()``.

        Raises:
            PluginError, InternalError, BridgeError: the run failed; it is closed and the
                error's ``kept`` holds what ran (tables, a summary saying it failed).
        """
        kernel = self.assembly.run.kernel
        until_ns = min(until_ns, self.end_ns)
        start = time.perf_counter()
        try:
            if woken is None:
                self.events += kernel.run(until_ns)
            else:
                self.events += kernel.advance(until_ns, woken)
        except (BridgeError, ExportError) as error:  # the world failed: kept as it is
            self._fail(error)
        except (Exception, Hung) as error:
            self._fail(fault_of(error, doing="running the simulation", t_ns=kernel.now_ns))
        finally:
            self.wall_s += time.perf_counter() - start

    def observe(self, out: Float32Array) -> None:
        """Write every agent's observation into ``out`` (agents, size), part after part.

        Raises:
            PluginError: a part raised, or wrote a value outside its declared bounds (or
                NaN); the run is closed, what ran kept.
        """
        try:
            observe_all(self.parts, self.view, out)
        except PluginError as error:
            self._fail(error)
        except (Exception, Hung) as error:
            self._fail(fault_of(error, doing="observing", t_ns=self.now_ns))

    def _reward_totals(self) -> FloatArray:
        """(terms, agents) running totals of the reward terms."""
        try:
            return reward_totals(self.parts, self.view)
        except PluginError as error:
            self._fail(error)
        except (Exception, Hung) as error:
            self._fail(fault_of(error, doing="rewarding", t_ns=self.now_ns))

    def act(self, agents: IntArray, actions: np.ndarray) -> None:
        """Apply the actions of ``agents`` (indices), one row each.

        Raises:
            ValueError: actions of the wrong shape, not finite, or no valid choice (the
                episode goes on: nothing was applied).
            PluginError: the action kind raised; the run is closed, what ran kept.
        """
        view, action = self.view, self.parts.action
        problem = action_problem(action.spec, actions, [view.names[int(i)] for i in agents])
        if problem is not None:
            raise ValueError(f"cosim.envs: {problem}")
        try:
            action.apply(view, agents, actions)
        except (Exception, Hung) as error:
            self._fail(fault_of(error, doing="acting", t_ns=self.now_ns))

    def rewards(self, agents: np.ndarray) -> FloatArray:
        """The weighted change of every term since each of ``agents`` last took its reward."""
        totals = self._reward_totals()
        gained = self.parts.weights @ (totals[:, agents] - self._totals[:, agents])
        self._totals[:, agents] = totals[:, agents]
        return np.asarray(gained, dtype=float)

    def close(self) -> RunResult:
        """End the run where it is: close the adapters and gather its summary and tables."""
        if self._result is not None:
            return self._result
        self._closed = True
        failure = close_adapters(self.assembly, None)
        reached_s = self.now_ns / NS_PER_S
        self._result = conclude(
            self.scenario,
            self.assembly,
            reached_s=reached_s,
            wall_s=self.wall_s,
            events=self.events,
            failure=failure,
        )
        if failure is not None:
            failure.kept = self._result
            raise failure
        return self._result

    def _fail(self, failure: CosimError) -> NoReturn:
        """Close a failed run, keep what ran in the error, and raise it."""
        self._closed = True
        failure = close_adapters(self.assembly, failure) or failure
        self._result = conclude(
            self.scenario,
            self.assembly,
            reached_s=self.now_ns / NS_PER_S,
            wall_s=self.wall_s,
            events=self.events,
            failure=failure,
        )
        failure.kept = self._result
        raise failure
