"""One test over every registered adapter: it starts, runs, and repeats exactly."""

import json

import pandas as pd
import pytest

import cosim
from cosim.core.adapter import Adapter
from cosim.core.registry import AdapterRegistry
from cosim.runner.execute import execute
from cosim.testing.outcomes import VOLATILE as TESTING_VOLATILE

REGISTRY = AdapterRegistry.from_entry_points()
SMALL = {
    "scenario.duration_s": 5.0,
    "world.size_m": [12.0, 12.0],
    "world.shelf_count": 4,
    "robots.count": 3,
    "lidar.beams": 60,
}

NEEDS = {
    "mocap": {"mocap.source": "simulated", "mocap.dropout": 0.2},
    # a physical robot that never answers: its twin stands still; the run is real time
    "physical": {
        "physical.robots": ["robot_1"],
        "physical.pose": "odom",
        "physical.dds_domain": 171,
    },
    "humans": {"humans.workers": 3},
}
"""Scenario keys an adapter needs to have something to do."""
VOLATILE = TESTING_VOLATILE
"""Wall-clock and machine figures (cosim.testing's own list: SUMO's coupling, lateness,
threads and their busy times)."""


def test_the_registry_holds_the_core_adapters():
    assert {"world", "fleet", "lidar", "waypoints", "poses"} <= set(REGISTRY.names())


REAL_TIME = {"physical"}
"""Adapters whose runs are paced by the wall clock (slow: a run of 5 s takes 5 s, twice)."""


@pytest.mark.parametrize(
    "name",
    [pytest.param(n, marks=pytest.mark.slow) if n in REAL_TIME else n for n in REGISTRY.names()],
)
def test_every_registered_adapter_starts_runs_and_repeats_exactly_with_the_same_seed(name):
    scenario = cosim.load_scenario("warehouse-random", overrides={**SMALL, **NEEDS.get(name, {})})
    first = execute(scenario, names=[name], registry=REGISTRY)
    second = execute(scenario, names=[name], registry=REGISTRY)
    assert first.tables.keys() == second.tables.keys()
    second_tables = second.deterministic_tables()
    for table, frame in first.deterministic_tables().items():
        pd.testing.assert_frame_equal(frame, second_tables[table])
    assert {k: v for k, v in first.summary.items() if k not in VOLATILE} == {
        k: v for k, v in second.summary.items() if k not in VOLATILE
    }
    json.dumps(first.summary)  # flat and serializable


@pytest.mark.parametrize("name", REGISTRY.names())
def test_every_registered_adapter_follows_the_adapter_protocol(name):
    scenario = cosim.load_scenario("warehouse-random", overrides={**SMALL, **NEEDS.get(name, {})})
    from cosim.runner.assembly import assemble

    assembly = assemble(scenario, names=[name], registry=REGISTRY)
    built = dict(assembly.adapters)
    assert isinstance(built[name], Adapter)
    adapter_type = REGISTRY.get(name)
    assert adapter_type.name == name
    assert all(required in REGISTRY.names() for required in adapter_type.requires)
