"""The context adapters share: settings, hosts, services, checks; the driver group."""

import pytest

from cosim.core.adapter import DRIVERS, Adapter, Driver, RunContext
from cosim.core.bus import Bus
from cosim.core.errors import RegistryError
from cosim.core.hosts import Host, HostId, HostKind
from cosim.core.kernel import Kernel
from cosim.core.recorder import Recorder
from cosim.core.registry import AdapterRegistry
from cosim.core.rng import RngStreams
from cosim.scenario.sections import LidarConfig


@pytest.fixture
def run(small_scenario) -> RunContext:
    kernel = Kernel()
    recorder = Recorder()
    return RunContext(
        scenario=small_scenario,
        kernel=kernel,
        bus=Bus(kernel, tap=recorder),
        rng=RngStreams(small_scenario.seed),
        recorder=recorder,
    )


def test_settings_are_the_scenarios_section_of_that_type(run):
    lidar = run.settings(LidarConfig)
    assert isinstance(lidar, LidarConfig) and lidar.beams == 90  # the small scenario's


def test_hosts_are_kept_by_id_in_creation_order(run):
    base = run.add_host("base", HostKind.BASE)
    robot = run.add_host("robot_1", HostKind.ROBOT)
    assert (base, robot) == (HostId("base"), HostId("robot_1"))
    assert list(run.hosts.values()) == [Host(base, HostKind.BASE), Host(robot, HostKind.ROBOT)]


def test_a_host_may_be_added_twice_with_its_kind_but_not_as_another_kind(run):
    run.add_host("robot_1", HostKind.ROBOT)
    run.add_host("robot_1", HostKind.ROBOT)
    assert len(run.hosts) == 1
    with pytest.raises(ValueError, match=r"host 'robot_1' exists already as a robot host"):
        run.add_host("robot_1", HostKind.EXTERNAL)


class Map:
    """A service one adapter offers the others."""


def test_a_service_is_found_by_its_type_once_provided(run):
    assert not run.has_service(Map)
    shared = Map()
    run.provide(shared)
    assert run.has_service(Map) and run.service(Map) is shared


def test_a_second_service_of_one_type_is_refused(run):
    run.provide(Map())
    with pytest.raises(ValueError, match="a Map service is provided already"):
        run.provide(Map())


def test_a_missing_service_names_its_type_and_the_fix(run):
    with pytest.raises(RegistryError, match=r"no adapter provides a Map; add .* to `requires`"):
        run.service(Map)


def test_checks_run_in_registration_order_when_asked_and_a_failing_one_refuses(run):
    seen: list[str] = []
    run.check_when_assembled(lambda: seen.append("first"))
    run.check_when_assembled(lambda: seen.append("second"))
    assert seen == []
    run.run_checks()
    assert seen == ["first", "second"]

    def refuse() -> None:
        raise RegistryError("robot_9 is no host")

    run.check_when_assembled(refuse)
    with pytest.raises(RegistryError, match="robot_9 is no host"):
        run.run_checks()


class Started:
    def start(self, run: RunContext) -> None:
        pass

    def finish(self, run: RunContext) -> dict[str, int]:
        return {}


class NeverFinishes:
    def start(self, run: RunContext) -> None:
        pass


def test_an_adapter_is_anything_that_starts_and_finishes():
    assert isinstance(Started(), Adapter)
    assert not isinstance(NeverFinishes(), Adapter)


def test_the_driver_group_accepts_the_built_in_drivers_each_naming_registered_adapters():
    drivers = DRIVERS.installed().load_all()
    assert {"navigation", "tasks", "waypoints", "wander", "teleop"} <= set(drivers)
    adapters = set(AdapterRegistry.from_entry_points().names())
    for name, driver in drivers.items():
        assert isinstance(driver, Driver) and driver.summary, name
        assert set(driver.adapters) <= adapters, name


def test_the_driver_group_refuses_an_entry_that_is_no_driver_saying_what_it_should_be():
    registry = DRIVERS.installed().with_entry("broken", ("wander",))
    with pytest.raises(
        RegistryError,
        match=r"robot driver 'broken' .*: is a tuple; expected a cosim.core.adapter.Driver",
    ):
        registry.get("broken")
    assert "broken" not in registry.load_all()


def test_a_driver_needs_the_lidar_unless_it_says_otherwise():
    assert Driver(("wander",), "roams").needs_lidar
    drivers = DRIVERS.installed().load_all()
    assert not drivers["waypoints"].needs_lidar and not drivers["teleop"].needs_lidar
