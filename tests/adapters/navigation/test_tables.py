"""Navigation records: tables/navigation rows, the events they raise, and the summary."""

from __future__ import annotations

import math

import pytest

from adapters.navigation.recovery import STUCK_KINDS
from adapters.navigation.tables import NAV_COLUMNS, NAVIGATION, NavRecords
from cosim.core.recorder import Recorder
from cosim.core.timebase import s_to_ns

ROBOTS = ["robot_1", "robot_2"]


def _records() -> tuple[Recorder, NavRecords]:
    recorder = Recorder()
    return recorder, NavRecords(recorder, ROBOTS, max_speed_mps=0.5)


def _rows(recorder: Recorder) -> list[dict[str, object]]:
    table = recorder.tables["navigation"].columns()
    return [{k: v[j] for k, v in table.items()} for j in range(len(table["event"]))]


def _events(recorder: Recorder) -> list[tuple[str, str, str]]:
    events = recorder.events.columns()
    return list(zip(events["source"], events["kind"], events["detail"], strict=True))


def test_the_table_declares_its_columns_with_units_and_plan_ms_as_volatile():
    assert NAVIGATION.name == "navigation"
    assert NAV_COLUMNS == (
        "t_s",
        "robot",
        "event",
        "goal_x_m",
        "goal_y_m",
        "path_length_m",
        "shortest_m",
        "lost_s",
        "plan_ms",
        "detail",
    )
    assert "(m)" in NAVIGATION.columns["goal_x_m"] and "map" in NAVIGATION.columns["goal_x_m"]
    assert "(ms; volatile)" in NAVIGATION.columns["plan_ms"]
    assert NAVIGATION.volatile == ("plan_ms",)  # wall-clock: left out of comparisons
    assert set(NAVIGATION.categorical) | set(NAVIGATION.volatile) <= set(NAVIGATION.columns)


def test_a_row_is_one_event_of_one_robot_in_seconds():
    recorder, records = _records()
    records.row(s_to_ns(1.5), 1, "plan", 3.0, 4.0, path_length_m=5.25, plan_ms=0.8)
    [row] = _rows(recorder)
    assert row == {
        "t_s": 1.5,
        "robot": "robot_2",
        "event": "plan",
        "goal_x_m": 3.0,
        "goal_y_m": 4.0,
        "path_length_m": 5.25,
        "shortest_m": row["shortest_m"],
        "lost_s": row["lost_s"],
        "plan_ms": 0.8,
        "detail": "",
    }
    assert records.counts == {"plan": 1}


def test_rows_without_a_plan_leave_its_columns_empty():
    recorder, records = _records()
    records.row(0, 0, "goal", 1.0, 2.0)
    [row] = _rows(recorder)
    assert all(math.isnan(row[k]) for k in ("path_length_m", "plan_ms", "shortest_m", "lost_s"))  # type: ignore[arg-type]


@pytest.mark.parametrize("event", ["stuck", "unreachable", "arrived", "off_map", "on_map"])
def test_events_a_user_looks_for_are_also_in_the_events_table(event):
    recorder, records = _records()
    records.row(s_to_ns(2.0), 0, event, 1.0, 2.5, detail="in_obstacle")
    assert _events(recorder) == [("robot_1", event, "goal (1.00, 2.50): in_obstacle")]


@pytest.mark.parametrize("event", ["goal", "plan", "replan", "recovery", "cancelled"])
def test_routine_events_stay_in_the_navigation_table(event):
    recorder, records = _records()
    records.row(0, 0, event, 1.0, 2.5)
    assert _events(recorder) == []


def test_an_arrival_records_the_time_to_goal_and_the_ratio_to_the_shortest_way():
    recorder, records = _records()
    records.start_goal(0, s_to_ns(10.0), driven_m=100.0, shortest_m=8.0)
    records.arrived(s_to_ns(22.5), 0, 5.0, 6.0, driven_m=110.0)
    assert records.times_s == [12.5]
    assert records.ratios == [pytest.approx(1.25)]
    assert _rows(recorder)[-1]["path_length_m"] == 10.0  # driven for this goal


def test_an_arrival_says_how_much_time_it_lost_against_its_shortest_way_at_full_speed():
    recorder, records = _records()  # 0.5 m/s
    records.start_goal(0, s_to_ns(10.0), driven_m=0.0, shortest_m=4.0)  # 8 s at full speed
    records.arrived(s_to_ns(30.0), 0, 5.0, 6.0, driven_m=6.0)  # took 20 s
    row = _rows(recorder)[-1]
    assert (row["shortest_m"], row["lost_s"]) == (4.0, 12.0)
    records.start_goal(1, s_to_ns(0.0), driven_m=0.0, shortest_m=4.0)
    records.arrived(s_to_ns(15.0), 1, 5.0, 6.0, driven_m=4.2)  # 15 s: under twice 8 s
    summary = records.summary(30.0)
    assert summary["time_lost_s"] == 19.0 and summary["time_lost_max_s"] == 12.0
    assert summary["arrivals_over_twice"] == 1  # the 20 s one


def test_time_stuck_adds_up_the_stalls_it_is_told_of():
    _, records = _records()
    records.stalled(31.5)
    records.stalled(40.0)
    assert records.summary(100.0)["stuck_s"] == 71.5


def test_goals_next_to_the_robot_say_nothing_about_path_quality():
    _, records = _records()
    records.start_goal(1, 0, driven_m=0.0, shortest_m=0.4)
    records.arrived(s_to_ns(1.0), 1, 0.0, 0.0, driven_m=0.9)
    assert records.times_s == [1.0] and records.ratios == []


def test_the_summary_counts_goals_arrivals_stalls_by_kind_and_averages():
    _, records = _records()
    assert records.summary(0.0) == {
        "goals": 0,
        "arrivals": 0,
        "mean_time_to_goal_s": None,
        "path_length_ratio": None,
        "deadlocks": 0,
        "stuck_s": 0.0,
        "time_lost_s": 0.0,
        "time_lost_max_s": None,
        "arrivals_over_twice": 0,
        **{f"stuck_{kind}": 0 for kind in STUCK_KINDS},
        "goals_unreachable": 0,
        "replans": 0,
        "recoveries": 0,
    }
    for i in (0, 1):
        records.row(0, i, "goal", 1.0, 1.0)
        records.start_goal(i, 0, 0.0, 2.0)
    records.arrived(s_to_ns(4.0), 0, 1.0, 1.0, 3.0)
    records.arrived(s_to_ns(6.0), 1, 1.0, 1.0, 2.0)
    records.row(0, 0, "stuck", 1.0, 1.0)
    records.stuck("halted")
    records.row(0, 0, "replan", 1.0, 1.0)
    records.row(0, 1, "unreachable", 1.0, 1.0)
    summary = records.summary(10.0)
    assert (summary["goals"], summary["arrivals"], summary["deadlocks"]) == (2, 2, 1)
    assert summary["mean_time_to_goal_s"] == 5.0
    assert summary["path_length_ratio"] == 1.25
    assert (summary["stuck_halted"], summary["stuck_slowed"]) == (1, 0)
    assert (summary["replans"], summary["goals_unreachable"], summary["recoveries"]) == (1, 1, 0)
