"""``cosim check-plugin``: the checks the project runs on its built-ins, run on one entry.

In the spirit of Gymnasium's ``check_env``: an entry of any registry group (a protocol, a
controller, an adapter, a settings section, a loss model, ...) is put through, in order,

- ``loads``: its module imports and holds the entry;
- ``contract``: its group's contract check passes (what a run asks of it first), and it
  declares the name it is registered under;
- ``settings``: its settings section (the ``cosim.sections`` entry of the same name, or
  the entry itself for a section) builds from its defaults, has no problem with them, and
  every key has a one-line doc and carries the unit its doc states in its name;
- then a short real run in a small scenario chosen for its group, whose summary keys
  must be declared (a warning otherwise), and its group's behaviour rules
  (:mod:`cosim.testing.trials`).

A check that fails stops the ones that need it (no run of a class that does not load).
Each check yields an :class:`Outcome`, printed as one line: ``ok``, ``FAIL`` or ``skip``
(a check that cannot apply: a live motion-capture source needs its system to run).
"""

from __future__ import annotations

import dataclasses
import importlib
import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any

from cosim.core.errors import ConfigError, RegistryError
from cosim.core.plugins import plugin_of
from cosim.core.registry import (
    ADAPTERS,
    AdapterRegistry,
    Group,
    Registry,
    installed_groups,
    suggest_names,
)
from cosim.scenario.fields import UNITS, field_names, key_unit, suggest
from cosim.scenario.model import SECTIONS, section_classes, section_registry
from cosim.testing.trials import trial_checks
from cosim.testing.verdicts import Outcome, fail, ok, skip


@dataclass(frozen=True)
class Target:
    """The entry under check.

    Attributes:
        group: its registry group.
        name: its registered name.
        registry: the group's installed registry (with entries given in code).
    """

    group: Group
    name: str
    registry: Registry[Any]

    def describe(self) -> str:
        """``assignment protocol 'sequential_auction' (labkit.auction:..., package labkit)``."""
        package = self.registry.package(self.name)
        owner = package if package.startswith("(") else f"package {package}"
        return f"{self.group.words} {self.name!r} ({self.registry.target(self.name)}, {owner})"


def registry_of(group: Group) -> Registry[Any]:
    """The installed registry of ``group`` (adapters with their requirements resolved)."""
    return AdapterRegistry.from_entry_points() if group == ADAPTERS else group.installed()


def find_entry(text: str) -> Target:
    """The entry ``text`` names: ``NAME``, or ``GROUP:NAME`` when several groups hold NAME.

    A name held by one group and by ``cosim.sections`` is the plugin, not its settings
    section (which its ``settings`` check reads). ``GROUP`` is an entry-point group
    (``cosim.drivers``), its short name (``drivers``) or its singular (``driver``).

    Raises:
        RegistryError: no such group or name, or a name several groups hold (listing them).
    """
    groups = installed_groups()
    group_text, _, name = text.rpartition(":")
    if group_text:
        chosen = [g for g in groups if group_text in _group_names(g)]
        if not chosen:
            shorts = [g.entry_points.removeprefix("cosim.") for g in groups]
            raise RegistryError(
                f"{text!r}: no registry {group_text!r}" + suggest_names(group_text, shorts)
            )
        groups = chosen
    registries = [(g, registry_of(g)) for g in groups]
    holders = [(g, r) for g, r in registries if name in r]
    if not holders:
        everything = sorted({n for _, r in registries for n in r.names()})
        raise RegistryError(f"no plugin {name!r} in any registry" + suggest_names(name, everything))
    plugins = [(g, r) for g, r in holders if g != SECTIONS]
    if len(plugins) == 1:  # a section of a plugin's own name is its settings, checked with it
        holders = plugins
    if len(holders) > 1:
        where = ", ".join(g.entry_points for g, _ in holders)
        example = f"{holders[0][0].entry_points}:{name}"
        raise RegistryError(
            f"{name!r} is registered in {where}: name one as GROUP:NAME (e.g. {example})"
        )
    group, registry = holders[0]
    return Target(group, name, registry)


def _group_names(group: Group) -> tuple[str, str, str]:
    short = group.entry_points.removeprefix("cosim.")
    singular = short[:-3] + "y" if short.endswith("ies") else short.removesuffix("s")
    return group.entry_points, short, singular


# -- loads, contract ----------------------------------------------------------------------------
def check_loads(target: Target) -> Outcome:
    """Its module imports and holds the entry (entries given in code are loaded already)."""
    where = target.registry.target(target.name)
    if target.registry.package(target.name).startswith("("):
        return ok("loads", f"{where}, given in code")
    module, _, attribute = where.partition(":")
    try:
        found: Any = importlib.import_module(module)
        for part in attribute.split(".") if attribute else ():
            found = getattr(found, part)
    except Exception as error:  # a broken plugin is what this check is for
        return fail("loads", f"{where} cannot be imported: {type(error).__name__}: {error}")
    return ok("loads", where)


def check_contract(target: Target) -> Outcome:
    """The group's contract check, the declared name; an adapter's requirements resolve."""
    try:
        target.registry.get(target.name)
        if isinstance(target.registry, AdapterRegistry):
            target.registry.resolve([target.name])
    except RegistryError as error:
        return fail("contract", str(error))
    return ok("contract", f"follows {target.group.contract.replace('`', '')}")


# -- settings -----------------------------------------------------------------------------------
UNIT_SUFFIXES = {unit: suffix for suffix, unit in reversed(UNITS.items())}
"""Unit -> the key suffix that carries it (``m/s`` -> ``_mps``)."""
STATED_UNIT = re.compile(r"\(([^()]*)\)\s*$")
"""A unit stated at the end of a key's doc: ``speed on a straight path (m/s)``."""


def check_settings(target: Target) -> Outcome:
    """Its settings section builds from defaults, with no problem, every key documented."""
    sections = target.registry if target.group == SECTIONS else section_registry()
    if target.name not in sections:
        return skip("settings", f"no [{target.name}] section registered in cosim.sections")
    try:
        section = sections.get(target.name)
    except RegistryError as error:
        return fail("settings", str(error))
    problems = section_problems(section)
    if problems:
        return fail("settings", f"[{target.name}] " + "; ".join(problems))
    count = len(dataclasses.fields(section))
    return ok(
        "settings",
        f"[{target.name}] {count} key{'' if count == 1 else 's'}: builds from its defaults, "
        "every key documented, "
        "units in the names",
    )


def section_problems(section: type[Any]) -> list[str]:
    """What is wrong with a section class: keys without doc or unit, defaults it refuses."""
    found = []
    for field in dataclasses.fields(section):
        doc = field.metadata.get("doc")
        if not isinstance(doc, str) or not doc.strip() or "\n" in doc:
            found.append(
                f"key {field.name!r} has no one-line doc: declare it with param(default, doc)"
            )
            continue
        stated = _stated_unit(doc)
        if stated is None or not _is_number(field.default):
            continue
        carried = key_unit(field)
        if carried != stated:
            named = f"its name carries {carried}" if carried else "its name carries no unit"
            better = f"{_stem(field.name)}{UNIT_SUFFIXES[stated]}"
            found.append(f"key {field.name!r} is in {stated} (its doc says) but {named}: {better}")
    try:
        defaults = section()
        for problem in getattr(defaults, "problems", list)():
            found.append(
                f"its defaults are refused: {problem.key} = {problem.value!r}: {problem.expected}"
            )
    except Exception as error:  # the section's own check is the plugin's code
        found.append(f"checking its defaults raised {type(error).__name__}: {error}")
    return found


def _stated_unit(doc: str) -> str | None:
    match = STATED_UNIT.search(doc)
    if match is None:
        return None
    said = match.group(1).replace("^2", "²").strip()
    return said if said in UNIT_SUFFIXES else None


def _is_number(value: Any) -> bool:
    if isinstance(value, tuple):
        return bool(value) and all(_is_number(v) for v in value)
    return isinstance(value, int | float) and not isinstance(value, bool)


def _stem(key: str) -> str:
    suffix = next((s for s in UNITS if key.endswith(s)), "")
    return key[: len(key) - len(suffix)] if suffix else key


def known_keys(overrides: Mapping[str, Any]) -> None:
    """Refuse a ``section.key`` no registered section has (the user's typo, not the plugin's).

    Values are checked with the scenario of the run (the ``scenario`` check): whether a
    value fits may depend on the entry chosen.

    Raises:
        ConfigError: naming the key and the nearest ones.
    """
    classes = section_classes()
    for dotted in overrides:
        section, _, key = dotted.partition(".")
        if section not in classes:
            raise ConfigError(
                f"--set {dotted}: no section [{section}]" + suggest(section, list(classes))
            )
        keys = field_names(classes[section])
        if key not in keys:
            raise ConfigError(
                f"--set {dotted}: [{section}] has no key {key!r}" + suggest(key, keys)
            )


# -- all of them --------------------------------------------------------------------------------
def check_plugin(
    target: Target,
    *,
    overrides: Mapping[str, Any] | None = None,
    duration_s: float | None = None,
) -> Iterator[Outcome]:
    """Every check of ``target``, in order; a failure stops the checks that need it.

    Args:
        target: the entry (:func:`find_entry`).
        overrides: scenario keys for its run (``{"mocap.file": "run/bag"}``), on top of
            the group's small scenario.
        duration_s: simulated seconds of its run (default: the group's, see
            :mod:`cosim.testing.trials`).
    """
    loads = check_loads(target)
    yield loads
    if loads.failed:
        return
    contract = check_contract(target)
    yield contract
    if contract.failed:
        return
    yield check_settings(target)
    entry = target.registry.get(target.name)
    yield from trial_checks(target.group, target.name, entry, overrides or {}, duration_s)


def plugin_words(target: Target) -> str:
    """The entry as errors name it (its package and version, or given in code)."""
    try:
        info = plugin_of(target.registry.get(target.name))
    except RegistryError:
        info = None
    return info.describe() if info is not None else target.describe()
