import pytest

import cosim
from adapters.drivers import stacks
from cosim.core.adapter import DRIVERS, Driver
from cosim.core.errors import ConfigError, RegistryError
from cosim.core.registry import AdapterRegistry, Registry
from cosim.runner.assembly import adapter_names, driver_registry
from tests.conftest import SMALL

BUILT_IN = {
    "navigation": stacks.NAVIGATION,
    "tasks": stacks.TASKS,
    "waypoints": stacks.WAYPOINTS,
    "wander": stacks.WANDER,
    "teleop": stacks.TELEOP,
    "agents": stacks.AGENTS,
}


def test_cosims_drivers_are_registered_as_a_plugins_are():
    assert driver_registry().load_all() == BUILT_IN
    assert all(isinstance(driver, Driver) for driver in BUILT_IN.values())


@pytest.mark.parametrize("name", list(BUILT_IN))
def test_every_driver_names_registered_adapters_and_says_what_the_robots_do(name):
    driver = BUILT_IN[name]
    ordered = AdapterRegistry.from_entry_points().resolve(driver.adapters)
    assert set(driver.adapters) <= set(ordered)
    assert driver.summary and "\n" not in driver.summary


def test_the_drivers_run_their_own_adapters():
    assert stacks.NAVIGATION.adapters == ("navigation", "goals")
    assert stacks.TASKS.adapters == ("navigation", "task_source", "dta")
    assert stacks.WAYPOINTS.adapters == ("waypoints",)
    assert stacks.WANDER.adapters == ("wander",)
    assert stacks.TELEOP.adapters == ("teleop",)
    assert stacks.AGENTS.adapters == ("agents",)


def test_only_drivers_that_avoid_nothing_run_without_a_lidar():
    blind = {name for name, driver in BUILT_IN.items() if not driver.needs_lidar}
    assert blind == {"waypoints", "teleop", "agents"}  # a policy decides what to avoid


@pytest.mark.parametrize("name", ["navigation", "tasks", "wander"])
def test_a_driver_that_avoids_what_the_lidar_sees_is_refused_without_beams(name):
    scenario = cosim.load_scenario(
        "warehouse-random", {**SMALL, "robots.driver": name, "lidar.beams": 0}
    )
    with pytest.raises(ConfigError, match=rf"driver = '{name}': expected lidar.beams > 0"):
        adapter_names(scenario)


@pytest.mark.parametrize("name", ["waypoints", "teleop", "agents"])
def test_a_driver_that_avoids_nothing_runs_without_a_lidar(name):
    scenario = cosim.load_scenario(
        "warehouse-random", {**SMALL, "robots.driver": name, "lidar.beams": 0}
    )
    names = adapter_names(scenario)
    assert "lidar" not in names
    assert set(BUILT_IN[name].adapters) <= set(names)


def test_an_entry_that_is_no_driver_is_refused_naming_what_it_is():
    with pytest.raises(RegistryError, match=r"robot driver 'odd' .*: is a tuple; expected a cosim"):
        Registry(DRIVERS, {"odd": ("waypoints",)}).get("odd")
