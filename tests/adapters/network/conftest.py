"""A network context without a run: what the network's pluggable parts are built with."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import pytest

import cosim
from adapters.network.contract import NetworkContext
from adapters.network.settings import NetworkConfig
from cosim.core.adapter import RunContext
from cosim.core.bus import Bus
from cosim.core.kernel import Kernel
from cosim.core.recorder import Recorder
from cosim.core.rng import RngStreams
from tests.conftest import SMALL

ROBOTS = ["robot_1", "robot_2", "robot_3", "robot_4"]

MakeContext = Callable[..., NetworkContext]


def network_context(
    robots: list[str] | None = None, *, seed: int | None = None, **network: Any
) -> NetworkContext:
    """A context of ``[network]`` with ``network`` set (not checked as a scenario would be)."""
    scenario = cosim.load_scenario("warehouse-random", SMALL)
    if seed is not None:
        scenario = scenario.with_seed(seed)
    cfg = dataclasses.replace(scenario.section(NetworkConfig), **network)
    scenario = scenario.with_section("network", cfg)
    kernel = Kernel()
    run = RunContext(scenario, kernel, Bus(kernel), RngStreams(scenario.seed), Recorder())
    return NetworkContext(run, cfg, list(ROBOTS if robots is None else robots))


@pytest.fixture
def context() -> MakeContext:
    """``context(robots=None, *, seed=None, **network)``: see :func:`network_context`."""
    return network_context
