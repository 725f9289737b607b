import pytest

import adapters.navigation.astar as astar
import adapters.navigation.planning as planning
import cosim
from models.navigation.landmarks import Landmarks

FLEET = {
    "navigation.traffic": "none",  # every robot plans (fleet50's fleet manager plans none)
    "robots.count": 6,
    "scenario.duration_s": 6.0,
    "record.bag": "none",
    "record.messages": False,
}


def _spy(monkeypatch: pytest.MonkeyPatch, min_cells: int) -> list[tuple[str, Landmarks | None]]:
    """Lower or raise the size threshold; record the landmarks every search is given."""
    monkeypatch.setattr(planning, "ALT_MIN_CELLS", min_cells)  # the yardstick's searches
    monkeypatch.setattr(astar, "ALT_MIN_CELLS", min_cells)  # the A* planner's
    calls: list[tuple[str, Landmarks | None]] = []
    plan, yardstick = astar.plan, planning.shortest_path_length_m

    def spy_plan(*args, **kwargs):
        calls.append(("plan", kwargs.get("landmarks")))
        return plan(*args, **kwargs)

    def spy_yardstick(*args, **kwargs):
        calls.append(("yardstick", kwargs.get("landmarks")))
        return yardstick(*args, **kwargs)

    monkeypatch.setattr(astar, "plan", spy_plan)
    monkeypatch.setattr(planning, "shortest_path_length_m", spy_yardstick)
    return calls


def _first_plans(result: cosim.RunResult) -> tuple[list[str], list[float]]:
    """The robots planning at t = 0 and the lengths of their paths (m)."""
    nav = result.tables["navigation"]
    first = nav[(nav["event"] == "plan") & (nav["t_s"] == 0.0)].sort_values("robot")
    return list(first["robot"]), list(first["path_length_m"])


@pytest.mark.slow
def test_above_the_size_threshold_every_robot_plans_with_the_same_landmarks(monkeypatch):
    calls = _spy(monkeypatch, 0)
    fleet = {**FLEET, "scenario.duration_s": 20.0}
    fast = cosim.run(cosim.load_scenario("fleet50", fleet))
    plans = [marks for kind, marks in calls if kind == "plan"]
    yardsticks = [marks for kind, marks in calls if kind == "yardstick"]
    # robots that start exactly where they stand measure a goal's yardstick on arrival
    assert len(yardsticks) == fast.summary["arrivals"] >= 1 and len(plans) >= 6
    assert all(m is not None and m.cost_weight == 1.0 for m in plans)
    assert all(m is not None and m.cost_weight == 0.0 for m in yardsticks)
    assert len({id(m) for m in plans}) == 1 and len({id(m) for m in yardsticks}) == 1  # shared
    # the same goals, planned to paths of the same cost (equal-cost paths may differ)
    calls.clear()
    monkeypatch.setattr(planning, "ALT_MIN_CELLS", 10**12)
    monkeypatch.setattr(astar, "ALT_MIN_CELLS", 10**12)
    plain = cosim.run(cosim.load_scenario("fleet50", fleet))
    assert all(marks is None for _, marks in calls)
    assert fast.summary["goals_sent"] == plain.summary["goals_sent"]
    assert fast.summary["goals_unreachable"] == plain.summary["goals_unreachable"]
    robots, with_marks = _first_plans(fast)
    assert (robots, len(robots)) == (_first_plans(plain)[0], 6)
    assert with_marks == pytest.approx(_first_plans(plain)[1], rel=0.03)


def test_on_fleet50s_floor_the_landmarks_are_not_built(monkeypatch):
    calls = _spy(monkeypatch, planning.ALT_MIN_CELLS)
    result = cosim.run(cosim.load_scenario("fleet50", {**FLEET, "scenario.duration_s": 1.0}))
    assert result.summary["goals"] == 6
    assert calls and all(marks is None for _, marks in calls)


def test_robots_that_map_plan_on_their_own_maps_without_landmarks(monkeypatch):
    calls = _spy(monkeypatch, 0)
    scenario = cosim.load_scenario(
        "warehouse-mapping", {"scenario.duration_s": 8.0, "record.bag": "none"}
    )
    cosim.run(scenario)
    plans = [marks for kind, marks in calls if kind == "plan"]
    yardsticks = [marks for kind, marks in calls if kind == "yardstick"]
    assert plans and all(marks is None for marks in plans)
    # the yardstick is measured on the building's true map: the landmarks hold there
    assert yardsticks and all(m is not None and m.cost_weight == 0.0 for m in yardsticks)
