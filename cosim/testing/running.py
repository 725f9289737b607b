"""Running a scenario from a test: overrides, a seed, a duration, plugins given in code.

:func:`run_scenario` is what the ``cosim_run`` fixture calls; it needs no pytest::

    from cosim.testing import SMALL_WAREHOUSE, run_scenario

    result = run_scenario(
        "warehouse-random",
        {**SMALL_WAREHOUSE, "assignment.protocol": "my_auction"},
        duration_s=20,
        plugins={"cosim.protocols": {"my_auction": MyAuction}},
    )

Plugins given in code are registered (:func:`cosim.core.registry.registered`) only while
the scenario loads and runs, exactly as an installed package's entry points would be, so
a test needs no installed package and leaves no trace in the next one.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from types import MappingProxyType
from typing import Any

from cosim.core.adapter import AdapterType
from cosim.core.registry import group_named, registered
from cosim.runner.execute import run
from cosim.runner.result import RunResult
from cosim.scenario import Scenario, load_scenario

SMALL_WAREHOUSE: Mapping[str, Any] = MappingProxyType(
    {
        "world.size_m": [16.0, 16.0],
        "world.shelf_count": 6,
        "robots.count": 3,
        "tasks.initial": 3,
        "lidar.beams": 60,
    }
)
"""Overrides of ``warehouse-random`` for a quick test: a 16 m x 16 m hall with 6 shelves,
3 robots and 3 tasks open at the start, a 60-beam lidar (a run of 20 simulated seconds
takes well under a second once numba's kernels are compiled)."""

Plugins = Mapping[str, Mapping[str, Any]]
"""Entries given in code: entry-point group -> registered name -> the class (or object),
``{"cosim.protocols": {"my_auction": MyAuction}, "cosim.sections": {"my_auction":
AuctionSettings}}``."""


@contextlib.contextmanager
def given_plugins(plugins: Plugins | None) -> Iterator[None]:
    """While inside, every entry of ``plugins`` is registered in its group.

    Raises:
        RegistryError: a group that is not registered (naming the registered ones), or a
            name that a group holds already.
    """
    with contextlib.ExitStack() as stack:
        for group, entries in (plugins or {}).items():
            group_named(group)  # an unknown group is refused here, with the nearest names
            for name, entry in entries.items():
                stack.enter_context(registered(group, name, entry))
        yield


def load(
    scenario: str | Path | Scenario = "warehouse-random",
    overrides: Mapping[str, Any] | None = None,
) -> Scenario:
    """A scenario from a preset name or a TOML file, with ``{"section.key": value}`` overrides.

    A :class:`~cosim.scenario.Scenario` is taken as it is.

    Raises:
        ConfigError: an unknown preset, file, section or key, or a value out of bounds.
        TypeError: overrides given with a loaded :class:`Scenario` (load it with them).
    """
    if isinstance(scenario, Scenario):
        if overrides:
            raise TypeError(
                f"overrides {sorted(overrides)} given with a loaded Scenario; load it with "
                "them: cosim.load_scenario(name_or_file, overrides)"
            )
        return scenario
    return load_scenario(scenario, overrides or {})


def run_scenario(
    scenario: str | Path | Scenario = "warehouse-random",
    overrides: Mapping[str, Any] | None = None,
    *,
    seed: int | None = None,
    duration_s: float | None = None,
    plugins: Plugins | None = None,
    adapters: Sequence[str | AdapterType] = (),
    out: str | Path | None = None,
) -> RunResult:
    """Run a scenario and return its result: tables as pandas DataFrames, the summary.

    Args:
        scenario: a preset name (``cosim scenarios``), a TOML file, or a loaded scenario.
        overrides: ``{"section.key": value}`` on top of it (``{"robots.count": 4}``).
        seed: the run's seed (default: the scenario's).
        duration_s: simulated seconds to run (s; default: the scenario's).
        plugins: entries to register while it loads and runs (see :data:`Plugins`).
        adapters: more adapters to run: registered names, or adapter classes (used as if
            registered under their ``name``; their settings read as their defaults).
        out: write the run folder here (``summary.json``, ``tables/``, ``scenario.toml``).

    Returns:
        The run's :class:`~cosim.runner.result.RunResult` (``result.tables["events"]``,
        ``result.summary["collisions"]``, ``result.out``).
    """
    with given_plugins(plugins):
        loaded = load(scenario, overrides)
        return run(loaded, seed=seed, duration_s=duration_s, adapters=adapters, out=out)
