"""cosim's pytest plugin: the ``cosim_run`` fixture.

Installed with cosim, pytest loads it through the ``pytest11`` entry point
``cosim.testing.plugin``; in a checkout that is not installed, ask for it by the same
name: ``pytest -p cosim.testing.plugin`` (both at once load it once).

```python
from cosim.testing import assert_no_conflicts, assert_tasks_assigned_within


def test_my_auction_assigns_every_task_within_two_seconds(cosim_run):
    result = cosim_run(
        "warehouse-random",
        {"assignment.protocol": "my_auction"},
        duration_s=30,
        plugins={"cosim.protocols": {"my_auction": MyAuction}},
    )
    assert_tasks_assigned_within(result, 2.0)
    assert_no_conflicts(result)
```

Nothing of cosim's runner is imported until a test calls ``cosim_run``, so the plugin
costs a test session that does not use it nothing.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

if TYPE_CHECKING:
    from cosim.core.adapter import AdapterType
    from cosim.runner.result import RunResult
    from cosim.scenario import Scenario
    from cosim.testing.running import Plugins


class CosimRun:
    """Runs scenarios for one test, their folders under its ``tmp_path``.

    Args:
        tmp_path: the test's temporary folder.
    """

    def __init__(self, tmp_path: Path) -> None:
        self.tmp_path = tmp_path
        self.folders: list[Path] = []

    def __call__(
        self,
        scenario: str | Path | Scenario = "warehouse-random",
        overrides: Mapping[str, Any] | None = None,
        *,
        seed: int | None = None,
        duration_s: float | None = None,
        plugins: Plugins | None = None,
        adapters: Sequence[str | AdapterType] = (),
        out: bool = False,
    ) -> RunResult:
        """Run a scenario and return its result (tables as DataFrames, summary).

        Args:
            scenario: a preset name, a TOML file, or a loaded scenario.
            overrides: ``{"section.key": value}`` on top of it (``{"robots.count": 4}``).
            seed: the run's seed (default: the scenario's).
            duration_s: simulated seconds to run (s; default: the scenario's).
            plugins: entries to register while it runs, by group and name
                (``{"cosim.protocols": {"my_auction": MyAuction}}``).
            adapters: more adapters: registered names, or adapter classes.
            out: write the run folder (``tmp_path/run-1``, ``run-2``, ...;
                ``result.out``).
        """
        from cosim.testing.running import run_scenario

        folder = None
        if out:
            folder = self.tmp_path / f"run-{len(self.folders) + 1}"
            self.folders.append(folder)
        return run_scenario(
            scenario,
            overrides,
            seed=seed,
            duration_s=duration_s,
            plugins=plugins,
            adapters=adapters,
            out=folder,
        )


@pytest.fixture
def cosim_run(tmp_path: Path) -> CosimRun:
    """Run a scenario and get its :class:`~cosim.runner.result.RunResult`.

    ``cosim_run(scenario, overrides, seed=, duration_s=, plugins=, adapters=, out=)``.
    Plugins given in code are registered only while their run loads and runs; with
    ``out=True`` the run folder goes under the test's ``tmp_path``.
    """
    return CosimRun(tmp_path)
