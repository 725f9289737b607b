"""Intervals of a mean over few runs (cosim.studies.intervals) and the y axis they give."""

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.studies.analysis import aggregate, metric_figure
from cosim.studies.intervals import band_caption, bootstrap_interval, y_limits

VALUES = st.lists(
    st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_infinity=False),
    min_size=1,
    max_size=12,
)


@settings(max_examples=60, deadline=None)
@given(values=VALUES)
def test_a_bootstrap_interval_never_leaves_the_range_of_the_runs_and_holds_their_mean(values):
    low, high = bootstrap_interval(values)
    assert min(values) <= low <= high <= max(values)
    mean = float(np.mean(values))
    assert low <= mean + 1e-9 * max(1.0, abs(mean)) and mean - 1e-9 * max(1.0, abs(mean)) <= high


@settings(max_examples=30, deadline=None)
@given(values=st.lists(st.integers(min_value=0, max_value=30), min_size=2, max_size=3))
def test_counts_over_two_or_three_seeds_never_get_a_band_below_zero(values):
    results = pd.DataFrame(
        {"run_id": range(len(values)), "seed": range(len(values)), "conflicts": values}
    ).assign(status="ok")
    row = aggregate(results, [], ["conflicts"]).iloc[0]
    assert 0 <= min(values) <= row["conflicts_ci_low"] <= row["conflicts_ci_high"] <= max(values)


def test_the_same_runs_give_the_same_interval_every_time():
    values = list(np.random.default_rng(3).normal(size=12))
    assert bootstrap_interval(values) == bootstrap_interval(list(values))
    assert bootstrap_interval(values, seed=1) != bootstrap_interval(values)


def test_equal_values_one_value_and_no_value_give_no_width():
    assert bootstrap_interval([3.0, 3.0, 3.0]) == (3.0, 3.0)
    assert bootstrap_interval([7.0]) == (7.0, 7.0)
    assert all(np.isnan(bootstrap_interval([np.nan])))


def test_a_constant_metric_has_a_zero_width_band_and_an_axis_not_below_zero():
    results = pd.DataFrame(
        {
            "run_id": range(6),
            "seed": [1, 2, 3] * 2,
            "network.latency_ms": [0, 0, 0, 50, 50, 50],
            "collisions": 0,
            "status": "ok",
        }
    )
    row = aggregate(results, ["network.latency_ms"], ["collisions"]).iloc[0]
    assert row["collisions_ci_low"] == row["collisions_ci_high"] == 0.0
    ax = metric_figure(results, "network.latency_ms", "collisions").axes[0]
    assert ax.get_ylim() == (0.0, 1.0)
    results["collisions"] = 4
    ax = metric_figure(results, "network.latency_ms", "collisions").axes[0]
    assert ax.get_ylim() == (2.0, 6.0)


def test_y_limits_leave_a_varying_metric_to_autoscale():
    assert y_limits([0.0, 1.0]) is None
    assert y_limits([-2.0, -2.0]) == (-3.0, -1.0)


BAND = "band: 95 % bootstrap interval of the mean, "


@pytest.mark.parametrize(
    ("counts", "caption"),
    [
        ([5, 5], BAND + "n = 5 seeds per point; dots: each run"),
        ([3, 5], BAND + "n = 3-5 seeds per point; dots: each run"),
        ([20, 20], BAND + "n = 20 seeds per point"),
    ],
)
def test_the_caption_says_what_the_band_is_and_its_n(counts, caption):
    assert band_caption(counts) == caption
