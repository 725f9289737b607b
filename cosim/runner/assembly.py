"""Scenario assembly: which adapters a scenario needs, built in dependency order."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from cosim.core.adapter import DRIVERS, Adapter, Driver, RunContext
from cosim.core.bus import Bus
from cosim.core.errors import ConfigError
from cosim.core.kernel import Kernel
from cosim.core.recorder import Recorder
from cosim.core.registry import AdapterRegistry, Registry
from cosim.core.rng import RngStreams
from cosim.core.workers import Workers
from cosim.scenario.fields import model_problem
from cosim.scenario.model import Scenario
from models.errors import ModelError


def driver_registry() -> Registry[Driver]:
    """The robot drivers installed packages register (``cosim.drivers``)."""
    return DRIVERS.installed()


def adapter_names(scenario: Scenario, *, recording: bool = False) -> list[str]:
    """The adapters a scenario runs, before requirements are resolved.

    The world, fleet, network and collision checks always; the lidar with beams; what each
    section's settings ask for (a section may declare ``adapters()``: mapping when
    enabled, the mocap source, ...), in section order; the driver's adapters and the poses
    table; the extra adapters of ``[scenario] adapters``. ``recording`` adds the ROS
    interface (clock, frames, map, markers) that bags and the live view carry; it changes
    no table.

    Raises:
        ConfigError: for combinations that cannot work (a lidar-driven behaviour without
            a lidar).
        RegistryError: for a driver that cannot be loaded.
    """
    driver = driver_registry().get(scenario.robots.driver)
    if driver.needs_lidar and scenario.lidar.beams == 0:
        raise ConfigError(
            f"{scenario.source}: [robots] driver = {scenario.robots.driver!r}: expected "
            "lidar.beams > 0 (it avoids what the lidar sees)"
        )
    names = ["world", "fleet", "network", "collisions"]
    if scenario.lidar.beams > 0:
        names.append("lidar")
    for section in scenario.sections.values():
        asks = getattr(section, "adapters", None)
        if callable(asks):
            names += [name for name in asks() if name not in names]
    names += [*driver.adapters, "poses"]
    if recording:
        names.append("ros_interface")
    names += [name for name in scenario.scenario.adapters if name not in names]
    return names


def check_scenario(
    scenario: Scenario,
    *,
    registry: AdapterRegistry | None = None,
    recording: bool = False,
    extra: Sequence[str] = (),
) -> None:
    """Refuse combinations of sections that cannot work, before anything is built.

    Every adapter the scenario runs may declare ``check_scenario(scenario)`` (a static
    method raising :class:`~cosim.core.errors.ConfigError`); studies call this for each of their
    combinations before the first run, :func:`assemble` before building the world.
    """
    registry = registry or AdapterRegistry.from_entry_points()
    names = adapter_names(scenario, recording=recording)
    names += [name for name in extra if name not in names]
    for name in registry.resolve(names):
        check = getattr(registry.get(name), "check_scenario", None)
        if check is not None:
            check(scenario)


def needs_realtime(scenario: Scenario) -> bool:
    """Whether the scenario talks to the real world (physical robots, live mocap).

    A section says so by declaring ``needs_realtime()``.
    """
    for section in scenario.sections.values():
        says = getattr(section, "needs_realtime", None)
        if callable(says) and says():
            return True
    return False


@dataclass
class Assembly:
    """A run ready to start: its context and its adapters in start order."""

    run: RunContext
    adapters: list[tuple[str, Adapter]]


def assemble(
    scenario: Scenario,
    *,
    names: list[str] | None = None,
    registry: AdapterRegistry | None = None,
    realtime: bool = False,
    speed: float = 1.0,
    recording: bool = False,
    extra: Sequence[str] = (),
    threads: int = 1,
) -> Assembly:
    """Build the run context and construct the scenario's adapters.

    Args:
        scenario: the validated scenario.
        names: adapters to run instead of :func:`adapter_names` (requirements are added).
        registry: the adapter registry; defaults to the installed entry points.
        realtime: pace the kernel against the wall clock (forced, at speed 1, for
            scenarios that talk to the real world: :func:`needs_realtime`).
        speed: simulated seconds per wall-clock second when ``realtime``.
        recording: the run is recorded or viewed live (see :func:`adapter_names`).
        extra: more adapters to run, by name (after the scenario's).
        threads: the run's worker threads (:class:`cosim.core.workers.Workers`).
    """
    registry = registry or AdapterRegistry.from_entry_points()
    if names is None:
        check_scenario(scenario, registry=registry, recording=recording, extra=extra)
        names = adapter_names(scenario, recording=recording)
        names += [name for name in extra if name not in names]
    ordered = registry.resolve(names)
    if needs_realtime(scenario):
        realtime, speed = True, 1.0
    kernel = Kernel(realtime=realtime, speed=speed)
    recorder = Recorder(record_messages=scenario.record.messages)
    bus = Bus(kernel, tap=recorder)
    run = RunContext(
        scenario=scenario,
        kernel=kernel,
        bus=bus,
        rng=RngStreams(scenario.seed),
        recorder=recorder,
        workers=Workers(threads),
    )
    adapters: list[tuple[str, Adapter]] = []
    for name in ordered:
        try:
            adapters.append((name, registry.get(name)(run)))
        except ModelError as error:  # a model refusing its parameters: the user's input
            raise model_problem(scenario.source, error) from None
    run.run_checks()
    return Assembly(run, adapters)
