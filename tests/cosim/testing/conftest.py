"""Runs the kit's tests read: small task runs with a constant 5 ms network latency."""

from __future__ import annotations

from typing import Any

import pandas as pd
import pytest

from cosim.runner.result import RunResult
from cosim.scenario import Scenario
from cosim.testing.running import SMALL_WAREHOUSE, run_scenario

TASKS: dict[str, Any] = {
    **SMALL_WAREHOUSE,
    "robots.driver": "tasks",
    "network.latency_ms": 5.0,  # constant: every message between hosts takes exactly 5 ms
}


@pytest.fixture(scope="session")
def simplex_run() -> RunResult:
    """15 s of 3 robots assigning tasks by distributed simplex, 5 ms between hosts."""
    return run_scenario("warehouse-random", TASKS, duration_s=15.0)


@pytest.fixture(scope="session")
def greedy_run() -> RunResult:
    """The same with greedy robots: their first choices collide (conflicts)."""
    return run_scenario(
        "warehouse-random", {**TASKS, "assignment.protocol": "greedy"}, duration_s=15.0
    )


def made_run(tables: dict[str, pd.DataFrame], **summary: Any) -> RunResult:
    """A result made by hand: exactly these tables and summary entries."""
    return RunResult(Scenario(), {"sim_time_s": 20.0, **summary}, tables)
