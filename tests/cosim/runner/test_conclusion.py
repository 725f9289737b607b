import pytest

import cosim
from cosim.core.registry import AdapterRegistry
from cosim.runner.assembly import assemble
from cosim.runner.conclusion import close_adapters, conclude


def test_a_run_driven_by_hand_sums_up_as_a_whole_run_does():
    scenario = cosim.load_scenario("lab-room", {"scenario.duration_s": 1.0})
    assembly = assemble(scenario, registry=AdapterRegistry.from_entry_points())
    for _, adapter in assembly.adapters:
        adapter.start(assembly.run)
    events = assembly.run.kernel.run(400_000_000)
    assert close_adapters(assembly, None) is None
    result = conclude(scenario, assembly, reached_s=0.4, wall_s=0.1, events=events, failure=None)
    whole = cosim.run(scenario, duration_s=0.4)
    assert result.summary["sim_time_s"] == pytest.approx(0.4)
    assert result.summary["events"] == events
    assert result.tables["poses"].equals(whole.tables["poses"])
    assert set(result.summary) == set(whole.summary)
