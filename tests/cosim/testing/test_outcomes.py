"""The kit's outcome assertions: no collisions, no conflicts, the same run twice."""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest

from cosim.testing.outcomes import assert_no_collisions, assert_no_conflicts, assert_same_run
from cosim.testing.running import SMALL_WAREHOUSE, run_scenario
from tests.cosim.testing.conftest import made_run


def contacts(*rows: tuple[float, str, str, str, float]) -> pd.DataFrame:
    """A collisions table of (t_s, robot, other, kind, speed_mps) rows."""
    return pd.DataFrame(
        {
            "t_s": [r[0] for r in rows],
            "robot": pd.Categorical([r[1] for r in rows]),
            "other": pd.Categorical([r[2] for r in rows]),
            "kind": pd.Categorical([r[3] for r in rows]),
            "depth_m": [0.01] * len(rows),
            "speed_mps": [r[4] for r in rows],
        }
    )


def test_a_run_without_contacts_passes(simplex_run):
    assert simplex_run.tables["collisions"].empty
    assert_no_collisions(simplex_run)


def test_contacts_fail_in_time_order_naming_robot_what_it_hit_when_and_how_fast():
    run = made_run({"collisions": contacts(
        (4.25, "robot_2", "robot_1", "robot", 0.5),
        (1.5, "robot_1", "shelf_3", "shelf", 0.31),
    )})  # fmt: skip
    with pytest.raises(AssertionError) as failed:
        assert_no_collisions(run)
    assert str(failed.value) == (
        "2 collisions: robot_1 hit shelf_3 (shelf) at t = 1.5 s at 0.31 m/s; "
        "robot_2 hit robot_1 (robot) at t = 4.25 s at 0.5 m/s"
    )
    with pytest.raises(AssertionError, match=r"^1 collisions with a robot: robot_2 hit robot_1"):
        assert_no_collisions(run, kinds={"robot"})
    assert_no_collisions(run, kinds={"wall", "person"})


def test_collisions_cannot_pass_on_a_run_that_did_not_look_for_them():
    with pytest.raises(AssertionError, match=r'no tables/collisions \(written by the collisions '
                       r'adapter: scenario.adapters = \["collisions"\]\)'):  # fmt: skip
        assert_no_collisions(made_run({}))


def test_robots_agreeing_by_distributed_simplex_claim_no_task_twice(simplex_run):
    assert simplex_run.summary["conflicts"] == 0
    assert_no_conflicts(simplex_run)


def test_greedy_robots_claiming_one_task_fail_naming_the_task_and_the_claim_that_lost(
    greedy_run,
):
    with pytest.raises(AssertionError) as failed:
        assert_no_conflicts(greedy_run)
    said = str(failed.value)
    assert said.startswith(f"{greedy_run.summary['conflicts']} conflicts (a task claimed by two ")
    assert "task 1: robot_1 replaced at t = 0.052666367 s" in said


def test_conflicts_cannot_pass_on_a_run_without_tasks():
    with pytest.raises(AssertionError, match="the run has no task source"):
        assert_no_conflicts(made_run({}))


def test_two_runs_with_one_seed_are_the_same_and_another_seed_differs_naming_a_table():
    small = {**SMALL_WAREHOUSE, "robots.driver": "wander"}
    first, second = (run_scenario("warehouse-random", small, duration_s=3.0) for _ in range(2))
    assert_same_run(first, second)
    other = run_scenario("warehouse-random", small, duration_s=3.0, seed=2)
    with pytest.raises(AssertionError, match=r"^tables/\w+ differs: "):
        assert_same_run(first, other)


def test_a_summary_differing_in_one_key_is_named_and_wall_clock_figures_are_not():
    base = made_run({}, events=10, wall_time_s=0.5, mean=float("nan"))
    again = dataclasses.replace(base, summary={**base.summary, "wall_time_s": 0.9})
    assert_same_run(base, again)
    changed = dataclasses.replace(base, summary={**base.summary, "events": 11})
    with pytest.raises(AssertionError, match=r"^the summaries differ: events: 10 then 11$"):
        assert_same_run(base, changed)


def test_runs_with_different_tables_are_named():
    one = made_run({"poses": pd.DataFrame({"t_s": np.zeros(2)})})
    two = made_run({"poses": pd.DataFrame({"t_s": np.zeros(3)})})
    with pytest.raises(AssertionError, match=r"tables/poses: \(2, 1\) rows x columns, then"):
        assert_same_run(one, two)
    with pytest.raises(AssertionError, match=r"different tables: \['poses'\] and \[\]"):
        assert_same_run(one, made_run({}))
