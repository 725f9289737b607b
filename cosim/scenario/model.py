"""The resolved scenario: one frozen settings dataclass per section, by section name.

Sections are registered in the ``cosim.sections`` entry-point group, cosim's own as a
plugin package's: the core sections (``scenario``, ``world``, ``robots``, ``lidar``,
``odometry``, ``record``) here in :mod:`cosim.scenario.sections`, every capability's with
its adapters (``[navigation]`` in ``adapters/navigation/settings.py``, ...). Code reads a
section by its type, ``scenario.section(NavigationConfig)``; ``scenario.navigation`` reads
it by name (untyped).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Collection, Iterator, Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any, TypeVar

from cosim.core.errors import ConfigError, RegistryError
from cosim.core.registry import Group, Registry
from cosim.scenario.arguments import seed_argument, text_argument, wrong_type
from cosim.scenario.fields import key_bounds
from cosim.scenario.provenance import PROVENANCE
from cosim.scenario.sections import (
    LidarConfig,
    OdometryConfig,
    RecordConfig,
    RobotsConfig,
    ScenarioSection,
    WorldConfig,
)

S = TypeVar("S")

CORE_SECTIONS = ("scenario", "world", "robots", "lidar", "odometry", "record")
"""Sections every scenario has, whatever is installed."""


def _section_contract(name: str, loaded: Any) -> str | None:
    """A section must be a dataclass type whose every field has a default, named freely."""
    import dataclasses

    if name == PROVENANCE:
        return (
            f"takes the name [{PROVENANCE}], which a run's scenario.toml keeps for the "
            "packages the run used; register the section under another name"
        )
    if not (isinstance(loaded, type) and dataclasses.is_dataclass(loaded)):
        return "is not a dataclass (declare the section's keys with param(default, doc))"
    try:
        loaded()
    except TypeError as error:
        return f"cannot be built from defaults alone ({error}): give every key a default"
    return None


SECTIONS = Group(
    "cosim.sections",
    "settings section",
    "settings sections",
    "a frozen dataclass of `param(default, doc, ...)` fields (`cosim.scenario.fields`)",
    "a `[section]` of the scenario file",
    named=False,
    check=_section_contract,
)
"""Settings sections: a scenario file's ``[section]`` tables, each a frozen dataclass."""


def section_registry() -> Registry[type[Any]]:
    """The settings sections installed packages register (``cosim.sections``)."""
    return SECTIONS.installed()


@dataclass(frozen=True)
class Scenario:
    """A validated scenario. Build it with :func:`cosim.load_scenario`.

    Attributes:
        sections: section name -> its settings, in file order (core sections first).
        source: the file or preset it was loaded from (for messages and provenance).
        resolved_with: the file's ``[provenance]``: package -> the version a run used (not
            a setting: see :mod:`cosim.scenario.provenance`).
        carried: sections no installed package registers, as the file gave them (section
            -> its TOML table): only a finished run's scenario read for its results has any
            (``load_scenario(..., reading=True)``); such a scenario cannot be run.
        notes: one line each for the user, said when the file was loaded: keys read under
            their new names (:mod:`cosim.scenario.migrations`), sections carried.
    """

    sections: Mapping[str, Any] = field(default_factory=dict)
    source: str = field(default="<defaults>", compare=False)
    resolved_with: Mapping[str, str] = field(default_factory=dict, compare=False)
    carried: Mapping[str, Any] = field(default_factory=dict)
    notes: tuple[str, ...] = field(default=(), compare=False)
    _by_type: Mapping[type[Any], Any] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )

    def __post_init__(self) -> None:
        sections = dict(self.sections)
        for name, kind in zip(
            CORE_SECTIONS,
            (ScenarioSection, WorldConfig, RobotsConfig, LidarConfig, OdometryConfig, RecordConfig),
            strict=True,
        ):
            sections.setdefault(name, kind())
        object.__setattr__(self, "sections", MappingProxyType(sections))
        object.__setattr__(self, "carried", MappingProxyType(dict(self.carried)))
        object.__setattr__(self, "_by_type", {type(s): s for s in sections.values()})

    def __reduce__(self) -> tuple[Any, ...]:
        # the mapping proxy does not pickle: studies send scenarios to worker processes
        return (
            Scenario,
            (
                dict(self.sections),
                self.source,
                dict(self.resolved_with),
                dict(self.carried),
                self.notes,
            ),
        )

    def section(self, kind: type[S]) -> S:
        """The section of type ``kind``.

        A section type that no installed package registers (the settings of an adapter given
        to :func:`cosim.run` in code) reads as its defaults.

        Raises:
            RegistryError: for a registered section missing from the scenario.
            ArgumentError: ``kind`` is no class (a section's name: read that as
                ``scenario.sections[name]``).
        """
        if not isinstance(kind, type):
            raise wrong_type(
                "Scenario.section",
                "kind",
                kind,
                "a settings class (NavigationConfig); by name: scenario.sections[name]",
            )
        found = self._by_type.get(kind)
        if found is None:
            return self._unregistered(kind)
        return found  # type: ignore[no-any-return]

    def _unregistered(self, kind: type[S]) -> S:
        """The defaults of a section no installed package registers (an adapter given in code).

        No scenario file could have set its keys (an unregistered section is refused when
        loading), so its defaults are its values. A registered section missing here (its
        package broke after the scenario was loaded) is an error.
        """
        registered = any(kind is cls for cls in section_classes().values())
        if registered or not dataclasses.is_dataclass(kind):
            raise RegistryError(
                f"{self.source}: no section of type {kind.__name__} in this scenario (its "
                f"sections: {', '.join(self.sections)}); register it in the cosim.sections "
                "entry-point group"
            )
        defaults = kind()
        self._by_type[kind] = defaults  # type: ignore[index]
        return defaults

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        sections = object.__getattribute__(self, "sections")
        try:
            return sections[name]
        except KeyError:
            raise AttributeError(
                f"the scenario has no section {name!r} (sections: {', '.join(sections)})"
            ) from None

    def __iter__(self) -> Iterator[tuple[str, Any]]:
        return iter(self.sections.items())

    @property
    def scenario(self) -> ScenarioSection:
        """``[scenario]``: name, duration, seed, extra adapters."""
        return self.sections["scenario"]  # type: ignore[no-any-return]

    @property
    def world(self) -> WorldConfig:
        """``[world]``: the warehouse hall."""
        return self.sections["world"]  # type: ignore[no-any-return]

    @property
    def robots(self) -> RobotsConfig:
        """``[robots]``: the fleet."""
        return self.sections["robots"]  # type: ignore[no-any-return]

    @property
    def lidar(self) -> LidarConfig:
        """``[lidar]``: every robot's planar lidar."""
        return self.sections["lidar"]  # type: ignore[no-any-return]

    @property
    def odometry(self) -> OdometryConfig:
        """``[odometry]``: every robot's wheel odometry."""
        return self.sections["odometry"]  # type: ignore[no-any-return]

    @property
    def record(self) -> RecordConfig:
        """``[record]``: what the run keeps."""
        return self.sections["record"]  # type: ignore[no-any-return]

    @property
    def seed(self) -> int:
        """The scenario seed."""
        return self.scenario.seed

    @property
    def name(self) -> str:
        """The scenario name."""
        return self.scenario.name

    def with_section(self, name: str, section: Any) -> Scenario:
        """Return a copy with section ``name`` replaced.

        Raises:
            ArgumentError: a ``name`` that is no string, or a ``section`` that is no
                settings dataclass instance.
        """
        text_argument("Scenario.with_section", "name", name)
        if not dataclasses.is_dataclass(section) or isinstance(section, type):
            raise wrong_type(
                "Scenario.with_section", "section", section, "a settings instance (a dataclass)"
            )
        return Scenario(
            {**self.sections, name: section},
            self.source,
            self.resolved_with,
            self.carried,
            self.notes,
        )

    def with_seed(self, seed: int) -> Scenario:
        """Return a copy with another seed.

        Raises:
            ArgumentError: a seed that is no int (a bool, a string); ConfigError: a
                negative one (:func:`cosim.scenario.arguments.seed_argument`).
        """
        checked = seed_argument("Scenario.with_seed", seed)
        return self.with_section("scenario", replace(self.scenario, seed=checked))

    def with_duration(self, duration_s: float) -> Scenario:
        """Return a copy with another duration (s), within the bounds of ``scenario.duration_s``.

        Raises:
            ConfigError: a duration that is not a finite number within those bounds.
        """
        bounds = key_bounds(ScenarioSection, "duration_s")
        number = isinstance(duration_s, int | float) and not isinstance(duration_s, bool)
        if not number or not math.isfinite(duration_s) or bounds.violation(duration_s):
            raise ConfigError(
                f"duration_s = {duration_s!r}: expected a number {bounds.describe()} (s; the "
                "bounds of scenario.duration_s)"
            )
        return self.with_section("scenario", replace(self.scenario, duration_s=duration_s))


LAST = 1000
"""Where a section that declares no ``ORDER`` comes (after cosim's own, by name)."""


def section_classes(needed: Collection[str] = ()) -> dict[str, type[Any]]:
    """Every registered section that loads, by name, in order (``ORDER``, then name).

    A plugin's section that cannot be imported is left out, so that it stops no run that
    does not use it; one in ``needed`` (the scenario names it) is an error.

    Raises:
        RegistryError: naming the section's package, for a section in ``needed``.
    """
    registry = section_registry()
    classes: dict[str, type[Any]] = {}
    for name in registry.names():
        try:
            classes[name] = registry.get(name)
        except RegistryError:
            if name in needed:
                raise
    return dict(
        sorted(classes.items(), key=lambda item: (getattr(item[1], "ORDER", LAST), item[0]))
    )


def default_scenario() -> Scenario:
    """Every registered section with its defaults (sections that cannot load left out)."""
    return Scenario({name: kind() for name, kind in section_classes().items()})


__all__ = ["CORE_SECTIONS", "Scenario", "default_scenario", "section_classes", "section_registry"]
