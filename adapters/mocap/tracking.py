"""Which robots are tracked, by what: the scenario's mocap and physical sections resolved.

One place decides it for every adapter that cares (the mocap source, the physical-robot
bridge, the robots' localization), so they cannot disagree.
"""

from __future__ import annotations

from adapters.mocap.settings import MocapConfig
from adapters.physical.settings import PhysicalConfig
from cosim.core.adapter import ScenarioView
from cosim.core.errors import ConfigError


def _check_names(scenario: ScenarioView, names: list[str], robots: list[str], key: str) -> None:
    for robot in robots:
        if robot not in names:
            raise ConfigError(
                f"{scenario.source}: [{key.split('.')[0]}] {key.split('.')[1]} names "
                f"{robot!r}: expected one of the robots {', '.join(names)}"
            )


def external_bodies(scenario: ScenarioView, names: list[str]) -> list[tuple[str, str]]:
    """(robot, body) of an external mocap source (``bag``, ``motioncapture``, ``ros2``, ``unity``).

    Defaults: the first robot with the bag's only pose topic; each physical robot by its
    own name (``motioncapture``) or on ``mocap.topic_pattern`` (``ros2``, ``unity``).

    Raises:
        ConfigError: for unknown robots, or a live source that tracks nobody.
    """
    cfg = scenario.section(MocapConfig)
    if not cfg.external:
        return []
    pairs = list(cfg.bodies)
    physical = list(scenario.section(PhysicalConfig).robots)
    if not pairs:
        if cfg.source == "bag":
            pairs = [(names[0], "")]
        elif not physical:
            raise ConfigError(
                f"{scenario.source}: [mocap] bodies = []: expected [[robot, body], ...] or "
                f"physical.robots for source = {cfg.source!r}"
            )
        elif cfg.source in ("ros2", "unity"):
            pairs = [(r, cfg.topic_pattern.replace("{robot}", r)) for r in physical]
        else:
            pairs = [(r, r) for r in physical]
    _check_names(scenario, names, [robot for robot, _ in pairs], "mocap.bodies")
    return pairs


def physical_robots(scenario: ScenarioView, names: list[str]) -> list[str]:
    """The physical robots, checked against the fleet and the pose they need.

    Raises:
        ConfigError: for an unknown robot, or a physical robot that would have no pose.
    """
    robots = list(scenario.section(PhysicalConfig).robots)
    _check_names(scenario, names, robots, "physical.robots")
    if scenario.section(PhysicalConfig).pose == "mocap" and robots:
        tracked = {robot for robot, _ in external_bodies(scenario, names)}
        live = scenario.section(MocapConfig).needs_realtime()
        missing = [robot for robot in robots if robot not in tracked or not live]
        if missing:
            raise ConfigError(
                f"{scenario.source}: [physical] robots names {missing[0]!r} with pose = "
                f"'mocap': expected it tracked by a live mocap source (mocap.source = 'ros2' "
                f"or 'motioncapture'), or physical.pose = 'odom'"
            )
    return robots


def simulated_robots(scenario: ScenarioView, names: list[str]) -> list[str]:
    """The robots a simulated mocap tracks (``mocap.robots``, or all).

    Raises:
        ConfigError: for a robot that is not in the fleet.
    """
    tracked = list(scenario.section(MocapConfig).robots) or list(names)
    _check_names(scenario, names, tracked, "mocap.robots")
    return tracked


def tracked_robots(scenario: ScenarioView, names: list[str]) -> list[str]:
    """The robots whose software localizes by measured poses on ``/<robot>/pose``."""
    cfg = scenario.section(MocapConfig)
    if cfg.source == "simulated":
        tracked = simulated_robots(scenario, names)
    else:
        tracked = [robot for robot, _ in external_bodies(scenario, names)]
    if scenario.section(PhysicalConfig).pose == "odom":
        tracked += [r for r in scenario.section(PhysicalConfig).robots if r not in tracked]
    return [name for name in names if name in tracked]
