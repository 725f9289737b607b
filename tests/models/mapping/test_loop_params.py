"""The loop closer's parameters: the documented defaults, chi-square gates at their quantiles."""

import dataclasses

import pytest
from scipy.stats import chi2

from models.mapping.loop_params import LoopParams
from models.mapping.matcher import MatcherParams
from models.mapping.uncertainty import ResponseWindow


@pytest.mark.parametrize(
    ("name", "quantile"),
    [
        ("max_chi2", 0.999),
        ("max_innovation", 0.999),
        ("max_disagreement", 0.99),
        ("min_correction", 0.95),
    ],
)
def test_each_gate_is_the_documented_chi_square_quantile_with_three_degrees_of_freedom(
    name, quantile
):
    assert getattr(LoopParams(), name) == pytest.approx(chi2.ppf(quantile, 3), abs=0.005)


def test_the_loop_match_searches_a_wide_window_without_a_margin():
    matcher = LoopParams().matcher
    assert isinstance(matcher, MatcherParams)
    assert (matcher.window_m, matcher.window_rad, matcher.margin) == (1.5, 0.3, 0.0)
    assert matcher.min_score == 0.55 and matcher.max_points == 180
    # wider than a sequential match's default window
    assert matcher.window_m > MatcherParams().window_m


def test_a_closures_covariance_floors_are_5_cm_and_0_02_rad():
    params = LoopParams()
    assert isinstance(params.response, ResponseWindow)
    assert (params.response.floor_m, params.response.floor_rad) == (0.05, 0.02)
    assert (params.sequential_response.half_cells, params.sequential_response.rotation_steps) == (
        6,
        4,
    )


def test_odometry_is_trusted_to_10_percent_of_distance_and_5_percent_of_turn():
    a, b, c, e, f = LoopParams().odometry_sigma
    assert (a, c, e) == (0.1, 0.05, 0.01)
    assert b > 0 and f > 0  # a floor for standing still


def test_the_search_is_documented_in_metres_and_nodes():
    params = LoopParams()
    assert (params.search_radius_m, params.min_path_m) == (4.0, 10.0)
    assert (params.local_nodes, params.every_nodes, params.agreement_nodes) == (15, 2, 12)
    assert params.ambiguous_m < params.ambiguous_sigma_m
    assert 0 < params.max_cost_quantile < 1


def test_parameters_are_frozen_and_each_instance_has_its_own_matcher_settings():
    params = LoopParams(search_radius_m=2.0)
    with pytest.raises(dataclasses.FrozenInstanceError):
        params.min_path_m = 1.0  # type: ignore[misc]
    assert params.search_radius_m == 2.0 and params.matcher == LoopParams().matcher
    assert params == LoopParams(search_radius_m=2.0)
