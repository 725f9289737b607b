"""cosim: deterministic discrete-event co-simulation of autonomous mobile robot fleets.

The Python API for notebooks and study scripts::

    import cosim
    scenario = cosim.load_scenario("warehouse-random", overrides={"robots.count": 8})
    result = cosim.run(scenario, seed=3)
    result.summary["real_time_factor"], result.tables["poses"].head()

The names of the package are imported from the modules that define them on first use
(PEP 562), so importing one part of cosim (``cosim.core.bus``, the command line) loads
neither pandas nor the runner.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from pathlib import Path

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
    from cosim.scenario.arguments import ArgumentError

_DEFINED_IN = {
    "ArgumentError": "cosim.scenario.arguments",
    "BridgeError": "cosim.core.errors",
    "ConfigError": "cosim.core.errors",
    "CosimError": "cosim.core.errors",
    "ExportError": "cosim.core.errors",
    "RegistryError": "cosim.core.errors",
    "ScenarioError": "cosim.core.errors",
    "RunResult": "cosim.runner.result",
    "run": "cosim.runner.execute",
    "Scenario": "cosim.scenario",
    "load_scenario": "cosim.scenario",
}
"""The module that defines each name of the package, imported when the name is first used."""


def __getattr__(name: str) -> Any:
    """A name of the package, imported from the module that defines it (PEP 562).

    Raises:
        AttributeError: the package has no such name.
    """
    module = _DEFINED_IN.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value  # later uses find it without coming here
    return value


def __dir__() -> list[str]:
    """The package's names, those not imported yet included."""
    return sorted({*globals(), *_DEFINED_IN})


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
        **options: passed to :func:`cosim.studies.run_study` (``progress``, ``report``,
            ``notify``, ``scheduler_timeout_s``).

    Raises:
        ArgumentError: (a ``ConfigError`` and a ``TypeError``) an argument of the wrong
            type, or a keyword the call does not take; one line naming it.
        ConfigError: an invalid study file, or an argument out of bounds (``workers=0``).
    """
    from cosim.scenario import arguments as check
    from cosim.studies import load_study, run_study

    call = "cosim.study"
    study_file = check.path_argument(call, "path", path, what="a study file")
    folder = check.path_argument(call, "out", out, what="a study folder")
    workers = check.count_argument(call, "workers", workers)
    if scheduler is not None:
        check.text_argument(call, "scheduler", scheduler)
    resume = check.flag_argument(call, "resume", resume)
    check.keywords_argument(call, options, STUDY_OPTIONS)
    for name, value in options.items():
        if name == "report":
            check.flag_argument(call, name, value)
        elif name == "progress" and value is not None and not callable(getattr(value, "begin", 0)):
            raise check.wrong_type(call, name, value, STUDY_OPTIONS[name] + ", or None")
        elif name == "scheduler_timeout_s":
            check.positive_argument(call, name, value, "seconds")
        else:
            check.callable_argument(call, name, value, STUDY_OPTIONS[name], arity=1)
    return run_study(
        load_study(study_file),
        folder,
        workers=workers,
        scheduler=scheduler,
        resume=resume,
        **options,
    )


STUDY_OPTIONS = {
    "progress": "a StudyProgress (cosim.studies.progress): its begin(total, done), then a "
    "call after every run",
    "report": "True or False: write the report of a study with a [report] section",
    "notify": "a function of one line: what resuming found",
    "scheduler_timeout_s": "how long to wait for the Dask scheduler (s)",
}
"""The keyword options :func:`study` passes on to :func:`cosim.studies.run_study`."""


__all__ = [
    "ArgumentError",
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
