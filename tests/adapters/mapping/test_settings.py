import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from adapters.mapping.mapper import mapper_params
from adapters.mapping.settings import NO_SHARING, MappingConfig
from cosim.core.errors import ConfigError
from cosim.runner.assembly import adapter_names
from tests.conftest import SMALL, cosim_main


def scenario(**overrides: object) -> cosim.Scenario:
    return cosim.load_scenario("warehouse-random", overrides={**SMALL, **overrides})


def test_mapping_is_off_by_default_with_slam_toolboxs_defaults():
    cfg = scenario().section(MappingConfig)
    assert cfg == MappingConfig()
    assert (cfg.enabled, cfg.share) == (False, NO_SHARING)
    assert (cfg.resolution_m, cfg.min_travel_m, cfg.min_heading_rad, cfg.min_interval_s) == (
        0.05,
        0.5,
        0.5,
        0.5,
    )
    assert cfg.map_update_interval_s == 5.0 and cfg.scan_matching == "correlative"
    assert cfg.loop_closure is False
    assert cfg.refine == "walls"  # not slam_toolbox's: measured on the simulated warehouse


@pytest.mark.parametrize("refine", ["walls", "score"])
def test_each_refine_reaches_the_robots_matcher(refine):
    cfg = scenario(**{"mapping.enabled": True, "mapping.refine": refine}).section(MappingConfig)
    assert mapper_params(cfg, 0.1, 10.0).matcher.refine_against == refine


def test_robots_map_only_when_mapping_is_enabled():
    assert "mapping" not in adapter_names(scenario(**{"robots.driver": "navigation"}))
    on = scenario(**{"robots.driver": "navigation", "mapping.enabled": True})
    assert on.section(MappingConfig).adapters() == ("mapping",)
    assert "mapping" in adapter_names(on)


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        (
            {"mapping.resolution_m": 0.005},
            "--set mapping.resolution_m: [mapping] resolution_m = 0.005: expected a cell size "
            ">= 0.01 m",
        ),
        (
            {"mapping.resolution_m": 2},
            "--set mapping.resolution_m: [mapping] resolution_m = 2: expected a number > 0 and "
            "<= 1",
        ),
        (
            {"mapping.share": "scans"},
            "--set mapping.share: [mapping] share = 'scans': expected 'none' with enabled = "
            "false (robots that do not map have nothing to share); or set mapping.enabled = true",
        ),
        (
            {"mapping.enabled": True, "mapping.share": "scan"},
            "--set mapping.share: [mapping] share = 'scan': expected a registered map sharing "
            "mode; did you mean 'scans'? (registered: maps, none, scans)",
        ),
        (
            {"mapping.scan_matching": "icp"},
            "--set mapping.scan_matching: [mapping] scan_matching = 'icp': expected one of "
            "'correlative', 'none'",
        ),
        (
            {"mapping.search_window_rad": 2},
            "--set mapping.search_window_rad: [mapping] search_window_rad = 2: expected a number "
            "> 0 and <= 1.6",
        ),
        (
            {"mapping.refine": "icp"},
            "--set mapping.refine: [mapping] refine = 'icp': expected one of 'walls', 'score'",
        ),
        (
            {"mapping.match_margin": 1.5},
            "--set mapping.match_margin: [mapping] match_margin = 1.5: expected a number >= 0 "
            "and <= 1",
        ),
    ],
)
def test_settings_that_cannot_work_are_refused_naming_key_value_and_what_was_expected(
    overrides, message
):
    with pytest.raises(ConfigError) as refused:
        scenario(**overrides)
    assert str(refused.value) == message


def test_sharing_with_mapping_enabled_is_accepted():
    for share in ("none", "scans", "maps"):
        cfg = scenario(**{"mapping.enabled": True, "mapping.share": share}).section(MappingConfig)
        assert cfg.share == share


def test_cosim_check_refuses_sharing_without_mapping_in_one_line():
    done = cosim_main("check", "warehouse-random", "--set", "mapping.share=maps")
    assert done.returncode == 2
    assert done.stderr.startswith("cosim: error: --set mapping.share: [mapping] share = 'maps'")
    assert done.stderr.count("\n") == 1


KEYS = [
    "enabled",
    "resolution_m",
    "share",
    "scan_matching",
    "min_travel_m",
    "search_window_m",
    "match_margin",
    "loop_closure",
    "share_period_s",
    "refine",
]
VALUES = st.one_of(
    st.booleans(),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-2, 5),
    st.sampled_from(["none", "scans", "maps", "correlative", "x", "walls", "score"]),
)


@settings(max_examples=80, deadline=None)
@given(st.dictionaries(st.sampled_from(KEYS), VALUES, max_size=4))
def test_any_mapping_values_load_consistently_or_fail_with_one_config_error_line(values):
    try:
        cfg = scenario(**{f"mapping.{k}": v for k, v in values.items()}).section(MappingConfig)
    except ConfigError as error:
        assert "\n" not in str(error) and "[mapping]" in str(error)
        return
    assert 0.01 <= cfg.resolution_m <= 1
    assert cfg.enabled or cfg.share == NO_SHARING
    assert not (cfg.loop_closure and cfg.share == "maps")
    assert cfg.refine in ("walls", "score")
