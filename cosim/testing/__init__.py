"""cosim's testing kit: run a scenario from a test, assert on its timing and outcome.

```python
from cosim.testing import assert_latency, assert_no_conflicts, run_scenario

result = run_scenario("warehouse-random", {"robots.count": 4}, seed=3, duration_s=30)
assert_latency(result, topic="/fleet/claims", p95_ms=20)
assert_no_conflicts(result)
```

With pytest, the ``cosim_run`` fixture (:mod:`cosim.testing.plugin`, registered through
the ``pytest11`` entry point) runs scenarios with their folders in the test's
``tmp_path``. ``cosim check-plugin NAME`` runs :mod:`cosim.testing.checks` on a plugin.

The names are imported from the modules that define them on first use (PEP 562), so the
pytest plugin costs a test session nothing until a test runs a scenario.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from cosim.testing.outcomes import assert_no_collisions, assert_no_conflicts, assert_same_run
    from cosim.testing.running import SMALL_WAREHOUSE, Plugins, given_plugins, run_scenario
    from cosim.testing.timing import (
        Latency,
        assert_epochs_decided_within,
        assert_latency,
        assert_order,
        assert_tasks_assigned_within,
    )

_DEFINED_IN = {
    "SMALL_WAREHOUSE": "cosim.testing.running",
    "Plugins": "cosim.testing.running",
    "given_plugins": "cosim.testing.running",
    "run_scenario": "cosim.testing.running",
    "Latency": "cosim.testing.timing",
    "assert_epochs_decided_within": "cosim.testing.timing",
    "assert_latency": "cosim.testing.timing",
    "assert_order": "cosim.testing.timing",
    "assert_tasks_assigned_within": "cosim.testing.timing",
    "assert_no_collisions": "cosim.testing.outcomes",
    "assert_no_conflicts": "cosim.testing.outcomes",
    "assert_same_run": "cosim.testing.outcomes",
}
"""The module that defines each name of the package."""


def __getattr__(name: str) -> Any:
    """A name of the kit, imported from the module that defines it (PEP 562).

    Raises:
        AttributeError: the kit has no such name.
    """
    module = _DEFINED_IN.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The kit's names, those not imported yet included."""
    return sorted({*globals(), *_DEFINED_IN})


__all__ = [
    "SMALL_WAREHOUSE",
    "Latency",
    "Plugins",
    "assert_epochs_decided_within",
    "assert_latency",
    "assert_no_collisions",
    "assert_no_conflicts",
    "assert_order",
    "assert_same_run",
    "assert_tasks_assigned_within",
    "given_plugins",
    "run_scenario",
]
