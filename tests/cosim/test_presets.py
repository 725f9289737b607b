import pytest

import cosim
from cosim.core.errors import CosimError
from cosim.runner.result import RunResult
from cosim.scenario import preset_names

REAL_TIME = {"lab-real-in-virtual", "lab-mixed"}
"""Presets with a physical robot: their runs are paced by the wall clock."""


@pytest.mark.parametrize(
    "name",
    [pytest.param(n, marks=pytest.mark.slow) if n in REAL_TIME else n for n in preset_names()],
)
def test_every_preset_runs_two_seconds_without_robots_overlapping(name):
    result = _two_seconds(name)
    assert result.summary["robots"] == cosim.load_scenario(name).robots.count
    assert result.summary["min_clearance_m"] >= 0
    assert len(result.tables["poses"]) == 20 * result.summary["robots"]


def _two_seconds(name: str) -> RunResult:
    """A preset's first 2 s; a physical robot's run, which nobody tracks here, as kept."""
    scenario = cosim.load_scenario(name)
    if name not in REAL_TIME:
        return cosim.run(scenario, duration_s=2.0)
    # no motion capture answers on this machine: a run shorter than mocap.connect_timeout_s
    # fails at its end, saying so, and keeps what ran
    with pytest.raises(CosimError, match=r"within mocap\.connect_timeout_s") as unanswered:
        cosim.run(scenario, duration_s=2.0)
    assert unanswered.value.kept is not None
    return unanswered.value.kept


def test_the_paper_presets_have_the_papers_fleets_and_rooms():
    assert cosim.load_scenario("fleet50").robots.count == 50
    assert cosim.load_scenario("fleet50").world.size_m == (30.0, 30.0)
    assert cosim.load_scenario("warehouse-rows").world.layout == "all_rows"
    assert cosim.load_scenario("lab-room").world.size_m == (4.0, 8.0)


def test_fleet50_comes_with_the_fleet_manager_and_the_others_let_each_robot_plan():
    assert cosim.load_scenario("fleet50").navigation.traffic == "pibt"
    others = [name for name in preset_names() if name != "fleet50"]
    assert all(cosim.load_scenario(name).navigation.traffic == "none" for name in others)
