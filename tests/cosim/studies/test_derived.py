"""Derived metrics: computed from the runs' summary metrics (cosim.studies.derived)."""

import numpy as np
import pandas as pd
import pytest

from cosim.studies.derived import DERIVED_METRICS


def test_wall_us_per_robot_s_is_wall_time_over_robots_times_sim_time_in_microseconds():
    frame = pd.DataFrame(
        {"wall_time_s": [2.0, 0.5, 1.0], "robots": [50, 4, 0], "sim_time_s": [20.0, 10.0, 10.0]}
    )
    values = DERIVED_METRICS["wall_us_per_robot_s"].compute(frame)
    assert values[0] == pytest.approx(2000.0)  # 2 s / (50 x 20 robot-s)
    assert values[1] == pytest.approx(12500.0)
    assert np.isnan(values[2])  # no robot: undefined, not infinite


def test_a_derived_metric_names_the_summary_metrics_it_needs_and_cannot_be_replaced():
    metric = DERIVED_METRICS["wall_us_per_robot_s"]
    assert metric.inputs == ("wall_time_s", "robots", "sim_time_s")
    assert "1e6 x wall_time_s / (robots x sim_time_s)" in metric.formula
    with pytest.raises(TypeError):
        DERIVED_METRICS["wall_us_per_robot_s"] = metric  # type: ignore[index]


def test_goals_per_minute_counts_a_learning_agents_goals_or_else_the_navigations():
    frame = pd.DataFrame(
        {
            "sim_time_s": [60.0, 30.0, 60.0, 0.0],
            "arrivals": [5.0, float("nan"), 4.0, 1.0],
            "agent_arrivals": [float("nan"), 3.0, 7.0, 1.0],
        }
    )
    values = DERIVED_METRICS["goals_per_min"].compute(frame)
    assert values.iloc[0] == 5.0  # the navigation driver's
    assert values.iloc[1] == 6.0  # an agent's, in 30 s
    assert values.iloc[2] == 7.0  # both counted (the goal action): the agent's goals
    assert np.isnan(values.iloc[3])  # no time: undefined
    only_navigation = DERIVED_METRICS["goals_per_min"].compute(frame[["sim_time_s", "arrivals"]])
    assert only_navigation.iloc[2] == 4.0
