"""Who held which task when, from each task's life: claimed, released or given way, served."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.plotting.ownership import CLAIM_WINDOW_S, HOLD_COLUMNS, holder_at, task_holds
from tests.cosim.plotting.holdings import FLEET, events_table, navigation_table, tasks_table


def _tasks(**columns: list[object]) -> pd.DataFrame:
    """One task (id 3, station (4, 4) m, created at 0 s, claimed at 1 s) with ``columns`` set."""
    base: dict[str, list[object]] = {
        "task": [3.0], "x_m": [4.0], "y_m": [4.0], "t_created_s": [0.0], "t_assigned_s": [1.0],
        "robot": [""], "t_started_s": [np.nan], "t_completed_s": [np.nan],
    }  # fmt: skip
    return pd.DataFrame({**base, **columns})


def _goals(*sent: tuple[float, str]) -> pd.DataFrame:
    """Goals to task 3's station: (time s, robot) each."""
    return pd.DataFrame(
        {
            "t_s": [t for t, _ in sent],
            "robot": [r for _, r in sent],
            "event": ["goal"] * len(sent),
            "goal_x_m": [4.0] * len(sent),
            "goal_y_m": [4.0] * len(sent),
        }
    )


def _events(*given_up: tuple[float, str, str, str]) -> pd.DataFrame:
    """Events: (time s, robot, kind, detail) each."""
    return pd.DataFrame(given_up, columns=["t_s", "source", "kind", "detail"])


def test_a_released_task_passes_to_its_next_claimer_and_is_held_by_no_one_in_between() -> None:
    holds = task_holds(tasks_table(), navigation_table(), events_table(), robots=FLEET)
    assert holder_at(holds, 5.0) == {0.0: "robot_1", 1.0: "robot_1"}
    assert holder_at(holds, 11.0) == {1.0: "robot_1"}  # task 0 released, not yet claimed
    assert holder_at(holds, 13.0) == {0.0: "robot_2", 1.0: "robot_1"}
    assert holder_at(holds, 16.0) == {0.0: "robot_2"}  # task 1 released for good
    assert holder_at(holds, 25.0) == {}
    assert list(holds["end"]) == ["released", "completed", "released"]


def test_a_task_served_without_a_release_is_one_holding_from_claim_to_completion():
    holds = task_holds(
        _tasks(robot=["robot_1"], t_started_s=[5.0], t_completed_s=[7.0]), None, None, robots=FLEET
    )
    assert list(holds.columns) == list(HOLD_COLUMNS)
    assert holds.to_dict("records") == [
        {"task": 3.0, "robot": "robot_1", "t_from_s": 1.0, "t_to_s": 7.0, "end": "completed"}
    ]


def test_a_task_still_being_served_at_the_end_is_held_open_to_the_end_of_the_run():
    holds = task_holds(_tasks(robot=["robot_2"], t_started_s=[5.0]), None, None, robots=FLEET)
    (row,) = holds.to_dict("records")
    assert row["end"] == "open" and np.isnan(row["t_to_s"])
    assert holder_at(holds, 1e9) == {3.0: "robot_2"}
    assert holder_at(holds, 0.5) == {}  # not yet claimed


def test_a_task_never_claimed_has_no_holding():
    assert task_holds(
        _tasks(t_assigned_s=[np.nan]), _goals((2.0, "robot_1")), None, robots=FLEET
    ).empty


def test_a_claimed_task_no_one_served_is_held_by_the_robot_sent_to_it_near_the_claim():
    holds = task_holds(
        _tasks(), _goals((1.0 + CLAIM_WINDOW_S - 0.5, "robot_3")), None, robots=FLEET
    )
    assert holds[["robot", "t_from_s", "end"]].values.tolist() == [["robot_3", 1.0, "open"]]
    # a goal to the station long after serves another task at a shared station
    assert task_holds(
        _tasks(), _goals((1.0 + CLAIM_WINDOW_S + 0.5, "robot_3")), None, robots=FLEET
    ).empty
    assert task_holds(_tasks(), None, None, robots=FLEET).empty  # no navigation table: no one known


def test_giving_way_is_giving_up_and_other_events_are_not():
    events = _events(
        (3.0, "robot_9", "conflict", "task 3: gave way to robot_1"),
        (3.5, "robot_8", "arrive", "task 3: at the station"),
        (4.0, "robot_7", "release", "no task named"),
    )
    holds = task_holds(
        _tasks(robot=["robot_1"], t_started_s=[5.0], t_completed_s=[7.0]),
        None,
        events,
        robots=FLEET,
    )
    assert holds[["robot", "t_from_s", "t_to_s", "end"]].values.tolist() == [
        ["robot_9", 1.0, 3.0, "released"],
        ["robot_1", 3.0, 7.0, "completed"],
    ]


def test_the_task_sources_conflicts_settle_claims_and_are_no_robot_giving_its_task_up():
    # robot_2's claim is rejected (robot_1 holds the task), robot_2 gives way when it hears
    # robot_1's claim; later robot_3's cheaper claim replaces robot_1's, who gives way
    events = _events(
        (2.0, "task_source", "conflict", "task 3: robot_2 rejected"),
        (2.4, "robot_2", "conflict", "task 3 goes to robot_1"),
        (4.0, "task_source", "conflict", "task 3: robot_3 replaced"),
        (4.3, "robot_1", "conflict", "task 3 goes to robot_3"),
    )
    tasks = _tasks(robot=["robot_3"], t_started_s=[6.0], t_completed_s=[8.0])
    goals = _goals((1.0, "robot_1"), (1.9, "robot_2"), (3.9, "robot_3"))
    holds = task_holds(tasks, goals, events, robots=("robot_1", "robot_2", "robot_3"))
    # the holdings end where the robots gave way, and at the completion
    assert holds[["robot", "t_to_s", "end"]].values.tolist() == [
        ["robot_2", 2.4, "released"],
        ["robot_1", 4.3, "released"],
        ["robot_3", 8.0, "completed"],
    ]


def test_the_next_claim_after_a_release_is_the_robot_s_last_goal_to_the_station_before_it():
    events = _events((4.0, "robot_1", "release", "task 3: stuck"))
    goals = _goals((1.0, "robot_1"), (6.0, "robot_2"), (8.0, "robot_2"), (12.0, "robot_2"))
    tasks = _tasks(robot=["robot_2"], t_started_s=[10.0], t_completed_s=[11.0])
    holds = task_holds(tasks, goals, events, robots=FLEET)
    assert holds[["robot", "t_from_s", "t_to_s"]].values.tolist() == [
        ["robot_1", 1.0, 4.0],
        ["robot_2", 8.0, 11.0],  # the goal sent last before the service started
    ]


def test_a_holding_ends_at_its_release_exclusively():
    holds = task_holds(tasks_table(), navigation_table(), events_table(), robots=FLEET)
    assert holder_at(holds, 1.0) == {0.0: "robot_1"}  # from the claim on
    assert 0.0 not in holder_at(holds, 10.0)  # released at 10 s


@settings(max_examples=30, deadline=None)
@given(
    releases=st.lists(
        st.tuples(st.floats(1.0, 50.0), st.sampled_from(["robot_1", "robot_2", "robot_3"])),
        max_size=4,
    ),
    served=st.sampled_from(["", "robot_1", "robot_4"]),
    done=st.booleans(),
)
def test_holdings_of_a_task_follow_each_other_and_end_as_it_did(releases, served, done):
    events = _events(*[(t, r, "release", "task 3: stuck") for t, r in releases])
    tasks = _tasks(
        robot=[served],
        t_started_s=[60.0 if served else np.nan],
        t_completed_s=[70.0 if served and done else np.nan],
    )
    holds = task_holds(tasks, _goals((1.0, "robot_1")), events, robots=FLEET)
    ordered = sorted(releases)
    assert list(holds["end"][: len(ordered)]) == ["released"] * len(ordered)
    assert list(holds["t_to_s"][: len(ordered)]) == pytest.approx([t for t, _ in ordered])
    assert (holds["t_from_s"].diff().dropna() >= 0).all()
    if served:
        assert holds["robot"].iloc[-1] == served
        assert holds["end"].iloc[-1] == ("completed" if done else "open")
