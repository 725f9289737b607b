"""cosim: deterministic discrete-event co-simulation of autonomous mobile robot fleets.

The Python API for notebooks and study scripts::

    import cosim
    scenario = cosim.load_scenario("warehouse-random", overrides={"robots.count": 8})
    result = cosim.run(scenario, seed=3)
    result.summary["real_time_factor"], result.tables["poses"].head()
"""

from cosim.errors import (
    BridgeError,
    ConfigError,
    CosimError,
    ExportError,
    RegistryError,
    ScenarioError,
)
from cosim.runner import RunResult, run
from cosim.scenario import Scenario, load_scenario

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
]
