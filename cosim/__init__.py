"""cosim: deterministic discrete-event co-simulation of autonomous mobile robot fleets.

The Python API for notebooks and study scripts::

    import cosim
    scenario = cosim.load_scenario("warehouse-random", overrides={"robots.count": 8})
    result = cosim.run(scenario, seed=3)
    result.summary["real_time_factor"], result.tables["poses"].head()
"""

from pathlib import Path
from typing import Any

import pandas as pd

from cosim.core.errors import (
    BridgeError,
    ConfigError,
    CosimError,
    ExportError,
    RegistryError,
    ScenarioError,
)
from cosim.runner.execute import run
from cosim.runner.result import RunResult
from cosim.scenario import Scenario, load_scenario


def study(
    path: str | Path,
    out: str | Path,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    **options: Any,
) -> pd.DataFrame:
    """Run a study file and return its results, one row per run.

    Args:
        path: the study TOML file.
        out: the study folder.
        workers: local processes (default: the machine's cores).
        scheduler: a Dask scheduler address to run on instead (``tcp://host:port``).
        resume: continue a study in ``out``.
        **options: passed to :func:`cosim.studies.run_study` (``progress``, ``report``).
    """
    from cosim.studies import load_study, run_study

    return run_study(
        load_study(path), out, workers=workers, scheduler=scheduler, resume=resume, **options
    )


__all__ = [
    "BridgeError",
    "ConfigError",
    "CosimError",
    "ExportError",
    "RegistryError",
    "RunResult",
    "Scenario",
    "ScenarioError",
    "load_scenario",
    "run",
    "study",
]
