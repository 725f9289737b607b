"""Scenario assembly: which adapters a scenario needs, built in dependency order."""

from __future__ import annotations

from dataclasses import dataclass

from cosim.core.adapter import Adapter, RunContext
from cosim.core.bus import Bus
from cosim.core.errors import ConfigError
from cosim.core.kernel import Kernel
from cosim.core.recorder import Recorder
from cosim.core.registry import AdapterRegistry
from cosim.core.rng import RngStreams
from cosim.scenario.fields import model_problem
from cosim.scenario.model import Scenario
from models.errors import ModelError

DRIVERS: dict[str, list[str]] = {
    "tasks": ["navigation", "task_source", "dta"],
    "navigation": ["navigation", "goals"],
    "waypoints": ["waypoints"],
    "wander": ["wander"],
}
"""The adapters that make up each ``robots.driver``."""


def adapter_names(scenario: Scenario, *, recording: bool = False) -> list[str]:
    """The adapters a scenario runs, before requirements are resolved.

    ``recording`` adds the ROS interface (clock, frames, map, markers) that bags and the
    live view carry; it changes no table.

    Raises:
        ConfigError: for combinations that cannot work (a lidar-driven behaviour without
            a lidar).
    """
    driver = scenario.robots.driver
    if driver in ("wander", "navigation", "tasks") and scenario.lidar.beams == 0:
        raise ConfigError(
            f"{scenario.source}: [robots] driver = {driver!r}: expected lidar.beams > 0 "
            "(it avoids what the lidar sees)"
        )
    names = ["world", "fleet", "network", "collisions"]
    if scenario.lidar.beams > 0:
        names.append("lidar")
    if scenario.mapping.enabled:
        names.append("mapping")
    if scenario.mocap.source != "none":
        names.append("mocap")
    if scenario.physical.robots:
        names.append("physical")
    if scenario.humans.enabled:
        names.append("humans")
    names += DRIVERS[driver] + ["poses"]
    if recording:
        names.append("ros_interface")
    names += [name for name in scenario.scenario.adapters if name not in names]
    return names


def check_scenario(
    scenario: Scenario, *, registry: AdapterRegistry | None = None, recording: bool = False
) -> None:
    """Refuse combinations of sections that cannot work, before anything is built.

    Every adapter the scenario runs may declare ``check_scenario(scenario)`` (a static
    method raising :class:`~cosim.core.errors.ConfigError`); studies call this for each of their
    combinations before the first run, :func:`assemble` before building the world.
    """
    registry = registry or AdapterRegistry.from_entry_points()
    for name in registry.resolve(adapter_names(scenario, recording=recording)):
        check = getattr(registry.get(name), "check_scenario", None)
        if check is not None:
            check(scenario)


def needs_realtime(scenario: Scenario) -> bool:
    """Whether the scenario talks to the real world (physical robots, live mocap)."""
    return bool(scenario.physical.robots) or scenario.mocap.source in ("motioncapture", "ros2")


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
    """
    registry = registry or AdapterRegistry.from_entry_points()
    if names is None:
        check_scenario(scenario, registry=registry, recording=recording)
        names = adapter_names(scenario, recording=recording)
    ordered = registry.resolve(names)
    if needs_realtime(scenario):
        realtime, speed = True, 1.0
    kernel = Kernel(realtime=realtime, speed=speed)
    recorder = Recorder(record_messages=scenario.record.messages)
    bus = Bus(kernel, tap=recorder)
    run = RunContext(
        scenario=scenario, kernel=kernel, bus=bus, rng=RngStreams(scenario.seed), recorder=recorder
    )
    adapters: list[tuple[str, Adapter]] = []
    for name in ordered:
        try:
            adapters.append((name, registry.get(name)(run)))
        except ModelError as error:  # a model refusing its parameters: the user's input
            raise model_problem(scenario.source, error) from None
    run.run_checks()
    return Assembly(run, adapters)
