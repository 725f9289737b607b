import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from adapters.assignment.settings import AssignmentConfig
from adapters.tasks.contract import ClaimRules, claim_rules
from cosim.core.errors import ConfigError
from tests.conftest import cosim_main


def scenario(**overrides: object) -> cosim.Scenario:
    overrides = {"robots.driver": "tasks", **overrides}
    return cosim.load_scenario("warehouse-random", overrides=overrides)


def test_the_defaults_are_the_distributed_simplex_with_chosen_rates():
    cfg = scenario().section(AssignmentConfig)
    assert cfg == AssignmentConfig()
    assert (cfg.protocol, cfg.period_ms, cfg.round_phase) == (
        "distributed_simplex",
        100.0,
        "independent",
    )
    assert (cfg.preemption, cfg.diameter_bound, cfg.cost) == (False, 0, "euclidean")
    assert (cfg.claim_timeout_s, cfg.rebroadcast_s) == (5.0, 1.0)


@pytest.mark.parametrize(
    ("key", "value", "expected"),
    [
        ("period_ms", 0, "[assignment] period_ms = 0: expected a number >= 0.001"),
        ("diameter_bound", -1, "[assignment] diameter_bound = -1: expected an integer >= 0"),
        ("claim_timeout_s", 0, "[assignment] claim_timeout_s = 0: expected a number >= 1e-06"),
        ("rebroadcast_s", -1, "[assignment] rebroadcast_s = -1: expected a number >= 1e-06"),
        (
            "round_phase",
            "random",
            "[assignment] round_phase = 'random': expected one of 'independent', 'aligned'",
        ),
        (
            "cost",
            "manhattan",
            "[assignment] cost = 'manhattan': expected one of 'euclidean', 'path'",
        ),
        ("preemption", "yes", "[assignment] preemption = 'yes': expected true or false"),
    ],
)
def test_a_value_out_of_its_bounds_is_refused_naming_key_value_and_what_was_expected(
    key, value, expected
):
    with pytest.raises(ConfigError) as refused:
        scenario(**{f"assignment.{key}": value})
    assert str(refused.value).startswith(f"--set assignment.{key}: {expected}")


def test_an_unknown_protocol_is_refused_with_the_nearest_and_the_registered_ones():
    with pytest.raises(ConfigError) as refused:
        scenario(**{"assignment.protocol": "hungarain"})
    assert str(refused.value) == (
        "--set assignment.protocol: [assignment] protocol = 'hungarain': expected a registered "
        "assignment protocol; did you mean 'hungarian'? (registered: agent_bids, cbba, "
        "distributed_simplex, greedy, hungarian)"
    )


def test_an_unknown_key_names_the_nearest_one_or_the_valid_ones():
    nearest = r"unknown key 'timeout_s'; did you mean 'claim_timeout_s'"
    with pytest.raises(ConfigError, match=nearest):
        scenario(**{"assignment.timeout_s": 3})
    with pytest.raises(ConfigError, match=r"unknown key 'nope'; valid: protocol, period_ms, "):
        scenario(**{"assignment.nope": 3})


def test_cosim_check_refuses_a_bad_assignment_value_in_one_line():
    done = cosim_main("check", "warehouse-random", "--set", "assignment.claim_timeout_s=0")
    assert done.returncode == 2
    assert done.stderr.startswith(
        "cosim: error: --set assignment.claim_timeout_s: [assignment] claim_timeout_s = 0: "
    )
    assert done.stderr.count("\n") == 1


@pytest.mark.parametrize(
    ("protocol", "central"),
    [("distributed_simplex", False), ("cbba", False), ("greedy", False), ("hungarian", True)],
)
def test_the_task_source_keeps_its_book_by_the_sections_claim_rules(protocol, central):
    s = scenario(
        **{
            "assignment.protocol": protocol,
            "assignment.claim_timeout_s": 2.5,
            "assignment.rebroadcast_s": 0.5,
            "assignment.preemption": True,
        }
    )
    rules = ClaimRules(claim_timeout_s=2.5, rebroadcast_s=0.5, preemption=True, central=central)
    assert s.section(AssignmentConfig).claim_rules() == rules
    assert claim_rules(s.sections) == rules


KEYS = ["period_ms", "diameter_bound", "claim_timeout_s", "rebroadcast_s", "round_phase", "cost"]
VALUES = st.one_of(
    st.integers(-3, 10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.booleans(),
    st.none(),
)


@settings(max_examples=60, deadline=None)
@given(st.dictionaries(st.sampled_from(KEYS), VALUES, max_size=3))
def test_any_assignment_values_load_within_bounds_or_fail_with_one_config_error_line(values):
    try:
        cfg = scenario(**{f"assignment.{k}": v for k, v in values.items()}).section(
            AssignmentConfig
        )
    except ConfigError as error:
        assert "\n" not in str(error)
        assert any(f"assignment.{key}" in str(error) for key in values)
        return
    assert cfg.period_ms > 0 and cfg.claim_timeout_s > 0 and cfg.rebroadcast_s > 0
    assert cfg.diameter_bound >= 0 and isinstance(cfg.diameter_bound, int)
    assert cfg.round_phase in ("independent", "aligned") and cfg.cost in ("euclidean", "path")
