"""Sections a study's resolved scenario gained or lost since its folder was started.

Installing a package that registers a settings section adds that section, with its
defaults, to every resolved scenario, so the scenario a study would run is no longer the
one its finished runs ran. Whether resuming may go on depends on what the section does:

- a section no run of the study sets (every key at the value it has when no file names
  it), and that by its defaults starts nothing (its ``adapters()`` asks for none, it needs
  no real time and no DDS, and it declares no other method the run may ask of every
  section) cannot have changed a finished run, and does not change the runs to come: the
  study resumes, and says so;
- otherwise (the study sets a key of it, or its defaults start an adapter) the runs to come
  would differ from the finished ones: resuming is refused, naming the section, its package
  and why.

A section that is gone (its package uninstalled or broken) is refused, naming its package:
the finished runs had it. The sections a study's folder was started with are in
``plan.json`` (``fingerprint.sections``: section -> package and version); for a folder
started before that was kept, they are read from a finished run's ``scenario.toml``.
"""

from __future__ import annotations

import tomllib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, fields
from typing import Any

from cosim.core.errors import ConfigError, RegistryError
from cosim.scenario.loader import dump_scenario, scenario_from_text
from cosim.scenario.model import Scenario, section_registry
from cosim.scenario.provenance import PROVENANCE

HOOKS_VOUCHED = ("problems", "adapters", "needs_realtime", "uses_dds")
"""Methods of a section whose effect at its defaults is known: checks, and three that the run
asks of every section (an empty ``adapters()``, False from the other two start nothing)."""


@dataclass(frozen=True)
class Gained:
    """What the resolved scenario gained since a folder was started, and whether it matters.

    Attributes:
        sections: the new sections, in scenario order.
        owners: each one's package and version (``labkit 0.2.0``).
        why: why one of them changes the runs (``[labkit] gain = 3.0 in run 0000_s1``), or
            "" when none does.
    """

    sections: tuple[str, ...]
    owners: Mapping[str, str]
    why: str = ""

    def named(self) -> str:
        """``[labkit] (package labkit 0.2.0)``, for each new section."""
        return ", ".join(f"[{name}] (package {self.owners[name]})" for name in self.sections)


def owner(name: str) -> str:
    """The package and version that register section ``name``, as messages say it."""
    registry = section_registry()
    try:
        info = registry.plugin(name)
    except RegistryError:
        return "not installed"
    return f"{info.package} {info.version}".strip() or "given in code"


def section_owners(scenario: Scenario) -> dict[str, str]:
    """Every section of ``scenario`` with its package and version (``plan.json`` keeps them)."""
    return {name: owner(name) for name in scenario.sections}


def toml_sections(text: str) -> list[str] | None:
    """The sections of a run's ``scenario.toml`` (not ``[provenance]``), or None if garbled."""
    try:
        loaded = tomllib.loads(text)
    except (tomllib.TOMLDecodeError, RecursionError):
        return None
    return [
        name for name, table in loaded.items() if isinstance(table, dict) and name != PROVENANCE
    ]


def dump_of(scenario: Scenario, keep: Iterable[str]) -> str:
    """The resolved scenario's text with only the sections in ``keep`` (as it was then)."""
    kept = set(keep)
    sections = {name: s for name, s in scenario.sections.items() if name in kept}
    return dump_scenario(Scenario(sections, scenario.source, scenario.resolved_with))


def _unset(name: str) -> Any:
    """Section ``name`` as a scenario that does not name it has it (profiles applied)."""
    return scenario_from_text("", "<defaults>").sections.get(name)


def changes_runs(scenario: Scenario, name: str) -> str:
    """Why section ``name`` of ``scenario`` changes a run (a key set, an adapter), or ""."""
    section = scenario.sections[name]
    unset = _unset(name)
    for f in fields(section):
        value = getattr(section, f.name)
        if unset is None or value != getattr(unset, f.name):
            return f"[{name}] {f.name} = {value!r}, not its default"
    asks = getattr(section, "adapters", None)
    if callable(asks) and tuple(asks()):
        return f"its defaults start adapter {', '.join(repr(a) for a in asks())} in every run"
    for hook in ("needs_realtime", "uses_dds"):
        says = getattr(section, hook, None)
        if callable(says) and says():
            return f"its {hook}() is true by default"
    for attribute in dir(type(section)):
        if attribute.startswith("_") or attribute in HOOKS_VOUCHED:
            continue
        if callable(getattr(type(section), attribute)):
            return f"it declares {attribute}(), which a run may ask of every section"
    return ""


def gained(
    scenarios: Iterable[tuple[str, Scenario]], then: Iterable[str], owners: Mapping[str, str]
) -> Gained:
    """The sections the scenarios have that ``then`` had not, and whether one changes a run.

    Args:
        scenarios: each combination's (or run's) label and resolved scenario.
        then: the sections the folder was started with.
        owners: each section's package now (:func:`section_owners`).
    """
    before = set(then)
    new: tuple[str, ...] = ()
    why = ""
    for label, scenario in scenarios:
        new = new or tuple(name for name in scenario.sections if name not in before)
        for name in new:
            if not why and (reason := changes_runs(scenario, name)):
                why = f"{reason} in {label}" if reason.startswith("[") else reason
    return Gained(new, {name: owners.get(name, owner(name)) for name in new}, why)


def gained_line(found: Gained, out: str, finished: int) -> str:
    """The note of a resume that goes on over sections that change nothing."""
    one = len(found.sections) == 1
    return (
        f"{out}: the resolved scenario gained {found.named()} since the folder was started "
        f"(a package installed since); no run of this study sets {'its' if one else 'their'} "
        f"keys and {'its' if one else 'their'} defaults start nothing, so the {finished} "
        "finished runs stand: resuming"
    )


def refuse_gained(found: Gained, path: str, out: str, finished: int) -> ConfigError:
    """The error of a resume over a new section that changes the runs."""
    packages = sorted({found.owners[name].split()[0] for name in found.sections})
    return ConfigError(
        f"{path}: the resolved scenario gained {found.named()} since {out} was started, and "
        f"it changes the runs ({found.why}); resuming would mix runs with and without it in "
        f"one table: uninstall {', '.join(packages)} to resume, or run this study with "
        f"another --out (the {finished} finished runs in {out} stay there)"
    )


def refuse_lost(
    lost: Iterable[str], owners: Mapping[str, Any], path: str, out: str, finished: int
) -> ConfigError:
    """The error of a resume over sections that are gone (their package uninstalled)."""
    names = sorted(lost)
    packages = sorted({str(owners.get(name, "its package")).split()[0] for name in names})
    listed = ", ".join(f"[{name}] (package {owners.get(name, 'unknown')})" for name in names)
    return ConfigError(
        f"{path}: {listed} is gone from the resolved scenario since {out} was started (its "
        f"package uninstalled, or failing to load: `cosim plugins` says); the finished runs "
        f"had it: install {', '.join(packages)} again to resume, or run this study with "
        f"another --out (the {finished} finished runs in {out} stay there)"
    )


__all__ = [
    "Gained",
    "changes_runs",
    "dump_of",
    "gained",
    "gained_line",
    "owner",
    "refuse_gained",
    "refuse_lost",
    "section_owners",
    "toml_sections",
]
