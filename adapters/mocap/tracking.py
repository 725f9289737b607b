"""Which robots are tracked, by what: the scenario's mocap section resolved.

One place decides it for every adapter that cares (the mocap source, the physical-robot
bridge, the robots' localization), so they cannot disagree. Robots posed from outside
the simulation (a physical robot) are said so by their own section
(:class:`~adapters.mocap.contract.ExternalPoses`).
"""

from __future__ import annotations

from typing import Any

from adapters.mocap.contract import MOCAP_SOURCES, Tracked, external_poses
from adapters.mocap.settings import MocapConfig
from cosim.core.adapter import ScenarioView
from cosim.core.errors import ConfigError


def _check_names(scenario: ScenarioView, names: list[str], robots: list[str], key: str) -> None:
    for robot in robots:
        if robot not in names:
            raise ConfigError(
                f"{scenario.source}: [{key.split('.')[0]}] {key.split('.')[1]} names "
                f"{robot!r}: expected one of the robots {', '.join(names)}"
            )


def source_of(scenario: ScenarioView) -> Any:
    """The class of the scenario's pose source (a ``PoseSource``), or None for ``none``."""
    return scenario.section(MocapConfig).chosen()


def tracked_bodies(scenario: ScenarioView, names: list[str]) -> Tracked:
    """(robot, body) of every robot the scenario's mocap source tracks (none: ``[]``).

    Raises:
        ConfigError: for unknown robots, or an external source that tracks nobody.
    """
    cfg = scenario.section(MocapConfig)
    source = source_of(scenario)
    if source is None:
        return []
    pairs: Tracked = source.tracks(cfg, external_poses(scenario.sections), names)
    if not pairs:
        raise ConfigError(
            f"{scenario.source}: [mocap] bodies = []: expected [[robot, body], ...] or "
            f"physical.robots for source = {cfg.source!r}"
        )
    key = "mocap.bodies" if source.external else "mocap.robots"
    _check_names(scenario, names, [robot for robot, _ in pairs], key)
    return pairs


def tracked_robots(scenario: ScenarioView, names: list[str]) -> list[str]:
    """The robots whose software localizes by measured poses on ``/<robot>/pose``.

    Those the mocap source tracks, and those posed from outside by something else (a
    physical robot's own odometry), in fleet order.
    """
    tracked = [robot for robot, _ in tracked_bodies(scenario, names)]
    tracked += [r for r, by in external_poses(scenario.sections).items() if by != "mocap"]
    return [name for name in names if name in tracked]


def live_sources() -> list[str]:
    """The registered sources that send poses while the run goes (for messages)."""
    return [name for name, s in MOCAP_SOURCES.installed().load_all().items() if s.live]
