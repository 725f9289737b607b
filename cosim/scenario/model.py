"""The resolved scenario: one frozen dataclass per section."""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from typing import Any, TypeVar, get_type_hints

from cosim.core.errors import RegistryError
from cosim.scenario.humans import HumansConfig
from cosim.scenario.mapping import MappingConfig
from cosim.scenario.mixed import MocapConfig, PhysicalConfig
from cosim.scenario.network import NetworkConfig
from cosim.scenario.sections import (
    AssignmentConfig,
    LidarConfig,
    NavigationConfig,
    OdometryConfig,
    RecordConfig,
    RobotsConfig,
    ScenarioSection,
    TasksConfig,
    WorldConfig,
)

S = TypeVar("S")


@dataclass(frozen=True)
class Scenario:
    """A validated scenario. Build it with :func:`cosim.load_scenario`.

    Attributes:
        source: the file or preset it was loaded from (for messages and provenance).
    """

    scenario: ScenarioSection = field(default_factory=ScenarioSection)
    world: WorldConfig = field(default_factory=WorldConfig)
    robots: RobotsConfig = field(default_factory=RobotsConfig)
    lidar: LidarConfig = field(default_factory=LidarConfig)
    odometry: OdometryConfig = field(default_factory=OdometryConfig)
    network: NetworkConfig = field(default_factory=NetworkConfig)
    navigation: NavigationConfig = field(default_factory=NavigationConfig)
    tasks: TasksConfig = field(default_factory=TasksConfig)
    assignment: AssignmentConfig = field(default_factory=AssignmentConfig)
    mapping: MappingConfig = field(default_factory=MappingConfig)
    mocap: MocapConfig = field(default_factory=MocapConfig)
    physical: PhysicalConfig = field(default_factory=PhysicalConfig)
    humans: HumansConfig = field(default_factory=HumansConfig)
    record: RecordConfig = field(default_factory=RecordConfig)
    source: str = field(default="<defaults>", compare=False)

    def __post_init__(self) -> None:
        by_type = {type(getattr(self, f.name)): getattr(self, f.name) for f in fields(self)}
        object.__setattr__(self, "_by_type", by_type)

    def section(self, kind: type[S]) -> S:
        """The section of type ``kind``.

        Raises:
            RegistryError: if no section of the scenario has that type.
        """
        found = self._by_type.get(kind)  # type: ignore[attr-defined]
        if found is None:
            raise RegistryError(f"the scenario has no section of type {kind.__name__}")
        return found  # type: ignore[no-any-return]

    @property
    def seed(self) -> int:
        """The scenario seed."""
        return self.scenario.seed

    @property
    def name(self) -> str:
        """The scenario name."""
        return self.scenario.name

    def with_seed(self, seed: int) -> Scenario:
        """Return a copy with another seed."""
        return replace(self, scenario=replace(self.scenario, seed=seed))

    def with_duration(self, duration_s: float) -> Scenario:
        """Return a copy with another duration (s)."""
        return replace(self, scenario=replace(self.scenario, duration_s=duration_s))


def section_types() -> dict[str, type[Any]]:
    """Section name -> section dataclass, in file order."""
    hints = get_type_hints(Scenario)
    return {f.name: hints[f.name] for f in fields(Scenario) if f.name != "source"}
