"""The resolved scenario: a frozen settings section per name, read by type or by name."""

from __future__ import annotations

import pickle
from dataclasses import dataclass

import pytest

import cosim
from adapters.navigation.settings import NavigationConfig
from cosim.core.errors import ConfigError, RegistryError
from cosim.scenario.fields import param
from cosim.scenario.model import (
    CORE_SECTIONS,
    SECTIONS,
    Scenario,
    default_scenario,
    section_classes,
    section_registry,
)
from cosim.scenario.sections import RobotsConfig, ScenarioSection, WorldConfig


@dataclass(frozen=True)
class ProbeConfig:
    """Settings of an adapter given to a run in code (no package registers them)."""

    gain: float = param(2.0, "a gain")


def test_a_scenario_always_has_the_core_sections_with_their_defaults():
    scenario = Scenario({})
    assert list(scenario.sections) == list(CORE_SECTIONS)
    assert scenario.robots == RobotsConfig() and scenario.world == WorldConfig()
    assert scenario.seed == 1 and scenario.name == "unnamed"


def test_a_section_is_read_by_its_type_and_by_its_name():
    scenario = cosim.load_scenario("warehouse-random")
    assert scenario.section(RobotsConfig) is scenario.robots
    assert scenario.section(NavigationConfig) is scenario.navigation
    assert [name for name, _ in scenario] == list(scenario.sections)


def test_an_unregistered_section_type_reads_as_its_defaults():
    assert Scenario({}).section(ProbeConfig) == ProbeConfig()


def test_a_registered_section_missing_from_the_scenario_is_an_error_naming_it():
    with pytest.raises(RegistryError) as refused:
        Scenario({}, "s.toml").section(NavigationConfig)
    message = str(refused.value)
    assert message.startswith("s.toml: no section of type NavigationConfig in this scenario")
    assert "(its sections: scenario, world, robots, lidar, odometry, record)" in message


def test_an_unknown_section_name_is_an_attribute_error_listing_the_sections():
    with pytest.raises(AttributeError, match=r"no section 'navigaton' \(sections: scenario, "):
        _ = Scenario({}).navigaton


def test_copies_change_one_section_and_leave_the_original_as_it_was():
    scenario = cosim.load_scenario("warehouse-random")
    reseeded = scenario.with_seed(7)
    longer = scenario.with_duration(12.5)
    assert (reseeded.seed, scenario.seed) == (7, 1)
    assert longer.scenario.duration_s == 12.5 and scenario.scenario.duration_s != 12.5
    assert longer.robots is scenario.robots and longer.source == scenario.source
    moved = scenario.with_section("robots", RobotsConfig(count=9))
    assert moved.robots.count == 9 and moved.section(RobotsConfig).count == 9


@pytest.mark.parametrize("duration_s", [0.0, -1.0, 1e8, float("nan"), float("inf"), True, "5"])
def test_a_duration_out_of_the_key_s_bounds_is_refused_naming_them(duration_s):
    with pytest.raises(ConfigError) as refused:
        Scenario({}).with_duration(duration_s)  # type: ignore[arg-type]
    assert str(refused.value) == (
        f"duration_s = {duration_s!r}: expected a number >= 1e-06 and <= 1e+07 (s; the bounds "
        "of scenario.duration_s)"
    )


def test_scenarios_compare_by_their_sections_not_by_where_they_came_from():
    a = Scenario({"scenario": ScenarioSection(name="a")}, "a.toml")
    b = Scenario({"scenario": ScenarioSection(name="a")}, "b.toml")
    assert a == b and a != a.with_seed(2)


def test_a_scenario_pickles_for_the_study_workers_with_its_source():
    scenario = cosim.load_scenario("warehouse-random", {"robots.count": 5})
    copy = pickle.loads(pickle.dumps(scenario))
    assert copy == scenario and copy.source == scenario.source
    assert copy.section(RobotsConfig).count == 5


def test_the_registered_sections_come_in_their_declared_order_core_first_record_last():
    classes = section_classes()
    names = list(classes)
    assert names[: len(CORE_SECTIONS) - 1] == list(CORE_SECTIONS[:-1])
    assert names[-1] == "record"
    orders = [getattr(cls, "ORDER", 1000) for cls in classes.values()]
    assert orders == sorted(orders)
    assert set(CORE_SECTIONS) <= set(section_registry().names())


def test_the_default_scenario_has_every_registered_section_at_its_defaults():
    scenario = default_scenario()
    assert list(scenario.sections) == list(section_classes())
    for name, cls in section_classes().items():
        assert scenario.sections[name] == cls()


def test_a_section_must_be_a_dataclass_buildable_from_defaults_alone():
    check = SECTIONS.check
    assert check is not None
    assert check("probe", ProbeConfig) is None
    assert "is not a dataclass" in str(check("probe", dict))

    @dataclass(frozen=True)
    class NoDefault:
        gain: float

    problem = check("probe", NoDefault)
    assert problem is not None and problem.startswith("cannot be built from defaults alone (")
    assert problem.endswith("): give every key a default")
