"""Loading scenarios: TOML files or presets, ``--set`` overrides, and the resolved dump.

A file may extend a preset or another file (``extends = ...``): the chain is resolved by
:mod:`cosim.scenario.extends` before the sections are validated.
"""

from __future__ import annotations

import copy
import datetime
import math
import re
import tomllib
from collections.abc import Mapping
from dataclasses import fields, is_dataclass, replace
from importlib import resources
from pathlib import Path
from typing import Any

from cosim.core.errors import ConfigError, RegistryError
from cosim.scenario.arguments import (
    origins_argument,
    overrides_argument,
    path_argument,
    text_argument,
)
from cosim.scenario.extends import resolve as resolve_extends
from cosim.scenario.fields import build, show_name, show_value, suggest
from cosim.scenario.migrations import leftover, migrate, renamed_hint
from cosim.scenario.model import Scenario, section_classes, section_registry
from cosim.scenario.provenance import missing_packages, provenance_lines, split_provenance
from cosim.scenario.tomlfile import (
    MAX_DEPTH,
    deeper_than,
    parse_toml,
    read_toml_file,
    refuse_long_keys,
    too_deep,
)

PRESET_PACKAGE = "cosim.presets"
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")
_TOML_ESCAPE = re.compile(r'["\\\x00-\x08\x0a-\x1f\x7f]')
"""What a TOML basic string must escape: quote, backslash, control characters but tab."""


def _escaped(match: re.Match[str]) -> str:
    char = match.group()
    return "\\" + char if char in '"\\' else f"\\u{ord(char):04x}"


def preset_names() -> list[str]:
    """Names of the presets shipped with cosim, sorted."""
    folder = resources.files(PRESET_PACKAGE)
    return sorted(p.name[: -len(".toml")] for p in folder.iterdir() if p.name.endswith(".toml"))


def preset_text(name: str) -> str:
    """The TOML text of preset ``name``."""
    return (resources.files(PRESET_PACKAGE) / f"{name}.toml").read_text(encoding="utf-8")


def preset_summary(name: str) -> str:
    """The first comment line of a preset (its one-line description)."""
    for line in preset_text(name).splitlines():
        if line.startswith("#"):
            return line.lstrip("# ").strip()
    return ""


def _read_source(spec: str | Path) -> tuple[str, dict[str, Any]]:
    """Return (origin, raw TOML dict) for a path or a preset name."""
    text_spec = str(spec)
    path = Path(spec)
    looks_like_file = isinstance(spec, Path) or text_spec.endswith(".toml") or "/" in text_spec
    if not looks_like_file:
        names = preset_names()
        if text_spec not in names:
            # a name with a line break or nothing in it is shown quoted: the error is one line
            shown = text_spec if text_spec.isprintable() and text_spec.strip() else repr(text_spec)
            raise ConfigError(
                f"{shown}: not a scenario file nor a preset"
                + suggest(text_spec, names)
                + " (list them with `cosim scenarios`)"
            )
        origin = f"preset {text_spec}"
        text = preset_text(text_spec)
    else:
        if not path.is_file():
            shown = str(path) if str(path).isprintable() else repr(str(path))
            raise ConfigError(f"{shown}: scenario file not found")
        return str(path), read_toml_file(path, "scenario file")
    return origin, parse_toml(text, origin)


def parse_override(text: str) -> tuple[str, Any]:
    """Parse ``section.key=value`` from the command line; the value is read as TOML.

    A value that is not valid TOML (``all_rows``) is taken as a plain string; the
    schema then checks its type like any other value.

    Raises:
        ConfigError: if ``text`` has no ``=`` or no ``section.key`` before it, or its
            value nests deeper than a file may
            (:data:`~cosim.scenario.tomlfile.MAX_DEPTH`).
    """
    key, sep, raw = text.partition("=")
    key = key.strip()
    if not sep or key.count(".") != 1 or not all(key.split(".")):
        raise ConfigError(f"--set {text}: expected section.key=value, e.g. lidar.rate_hz=20")
    raw = raw.strip()
    origin = f"--set {key}"
    refuse_long_keys(raw, origin)
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    except RecursionError:  # arrays in arrays, a thousand deep
        raise ConfigError(too_deep(origin)) from None
    if deeper_than(value, MAX_DEPTH - 2):  # the value sits two levels down: [section] key
        raise ConfigError(too_deep(origin))
    return key, value


def load_scenario(
    spec: str | Path,
    overrides: Mapping[str, Any] | None = None,
    *,
    override_origin: str = "--set",
    override_origins: Mapping[str, str] | None = None,
    reading: bool = False,
) -> Scenario:
    """Load and validate a scenario from a TOML file or a preset name.

    A key renamed since the file was written (:data:`~cosim.scenario.migrations.RENAMES`)
    is read under its new name when the rename kept its meaning, with a note
    (:attr:`Scenario.notes`); one whose model changed too is refused, naming the key to set.

    Args:
        spec: a path to a TOML file (which may extend a preset or another file), or the
            name of a preset (``cosim scenarios``).
        overrides: ``{"section.key": value}`` applied on top of the file.
        override_origin: how messages name the origin of overrides.
        override_origins: how messages name the origin of some overrides, by key (a
            study's ``--set`` among its grid's keys); the others: ``override_origin``.
        reading: the scenario of a finished run, loaded to read its results (figures,
            reports): every renamed key is read under its new name, and sections and
            registered names that no installed package provides any more are carried
            (:attr:`Scenario.carried`), not refused; each said in :attr:`Scenario.notes`.
            Such a scenario cannot be run.

    Raises:
        ConfigError: for a missing file, malformed TOML, an unknown section or key, or a
            value of the wrong type or out of bounds; the message names all of them.
        ArgumentError: (a ``ConfigError`` and a ``TypeError``) for an argument of the
            wrong type: ``overrides`` that are no mapping, a ``spec`` that is no str or path.
    """
    call = "cosim.load_scenario"
    path = path_argument(call, "spec", spec, what="a preset name or a scenario file")
    spec = spec if isinstance(spec, str) else path  # a str may name a preset, a Path not
    overrides = overrides_argument(call, overrides)
    override_origin = text_argument(call, "override_origin", override_origin)
    override_origins = origins_argument(call, override_origins)
    origin, raw = _read_source(spec)
    layers = resolve_extends(origin, copy.deepcopy(raw), read=_read_source, presets=preset_names)
    raw, origins = layers.raw, dict(layers.keys)
    for dotted, value in (overrides or {}).items():
        section, _, key = dotted.partition(".")
        if not key or "." in key:
            raise ConfigError(f"{override_origin} {dotted}: expected section.key")
        table = raw.setdefault(section, {})
        if not isinstance(table, dict):
            where = layers.sections.get(section, origin)
            raise ConfigError(f"{where}: {section} must be a [section] table")
        table[key] = value
        named = (override_origins or {}).get(dotted, override_origin)
        origins[(section, key)] = f"{named} {dotted}"
    return _build(raw, origin, origins, layers.sections, reading=reading)


def section_types() -> dict[str, type[Any]]:
    """Section name -> settings dataclass, for every registered section that loads, in order."""
    return section_classes()


def _build(
    raw: dict[str, Any],
    origin: str,
    origins: dict[tuple[str, str], str],
    sections: Mapping[str, str] | None = None,
    *,
    reading: bool = False,
) -> Scenario:
    """Validate raw sections into a scenario.

    ``origins`` names where each (section, key) came from and ``sections`` where each
    section did (a file of an ``extends`` chain, ``--set``); ``origin`` where neither says.
    A ``[provenance]`` table is taken apart (:attr:`Scenario.resolved_with`), not a section.
    ``reading``: as :func:`load_scenario`'s.
    """
    raw, resolved_with = split_provenance(raw, origin, origins)
    migrated = migrate(raw, origin, meaning_changes=reading)
    raw, notes = migrated.tables, list(migrated.notes)
    for rename in migrated.applied:  # a key read under its new name came from the old's file
        old, new = rename.old.partition("."), rename.new.partition(".")
        if (old[0], old[2]) in origins:
            origins[(new[0], new[2])] = origins[(old[0], old[2])]
    sections = sections or {}
    _refuse_renamed(raw, origin, origins)
    registry = section_registry()
    carried: dict[str, Any] = {}
    for section in list(raw):
        if section in registry:
            continue
        if reading and isinstance(raw[section], dict):
            carried[section] = raw.pop(section)
            continue
        where = sections.get(section) or next(
            (o for (s, _), o in origins.items() if s == section), origin
        )
        raise ConfigError(
            f"{where}: unknown section [{show_name(section)}]"
            + _unknown_section_hint(section, registry.names(), resolved_with)
        )
    try:
        classes = section_classes(needed=raw.keys())
    except RegistryError as error:  # the file uses a plugin that cannot load: say which
        if not reading:
            raise ConfigError(f"{origin}: {error}") from None
        classes = section_classes()
        for section in [s for s in raw if s not in classes]:
            carried[section] = raw.pop(section)
    built: dict[str, Any] = {}
    unregistered: list[tuple[str, Any]] = []
    for section, cls in classes.items():
        table = raw.get(section, {})
        where = sections.get(section, origin)
        if not isinstance(table, dict):
            raise ConfigError(
                f"{where}: {section} = {show_value(table)}: expected a [{section}] table of keys"
            )
        key_origins = {key: origins.get((section, key), where) for key in table}
        table, key_origins = _apply_profile(cls, table, key_origins, section, where)
        found: list[tuple[str, Any]] = []
        built[section] = _resolve_paths(
            build(
                cls,
                table,
                section=section,
                origins=key_origins,
                default_origin=where,
                unregistered=found if reading else None,
            ),
            key_origins,
        )
        unregistered += [(f"{section}.{key}", value) for key, value in found]
    if carried or unregistered:
        notes.append(_carried_note(origin, carried, unregistered, resolved_with))
    return Scenario(
        built, source=origin, resolved_with=resolved_with, carried=carried, notes=tuple(notes)
    )


def check_runnable(scenario: Scenario) -> None:
    """Refuse to run a scenario read with sections no installed package registers.

    Raises:
        ConfigError: naming the sections and the packages to install.
    """
    if not scenario.carried:
        return
    missing = missing_packages(scenario.resolved_with)
    install = f"install {', '.join(missing)}" if missing else "install the plugin that registers it"
    names = ", ".join(f"[{show_name(name)}]" for name in scenario.carried)
    raise ConfigError(
        f"{scenario.source}: unknown section {names}: no installed package registers it; it "
        f"was read to draw a run, not to run one ({install} to run it)"
    )


def _refuse_renamed(
    raw: Mapping[str, Any], origin: str, origins: Mapping[tuple[str, str], str]
) -> None:
    """Refuse a key renamed with a change of model (left by the migration), naming the new."""
    rename = leftover(raw)
    if rename is not None:
        section, _, key = rename.old.partition(".")
        where = origins.get((section, key), origin)
        raise ConfigError(f"{where}: [{section}] unknown key {key!r}" + renamed_hint(rename))


def _unknown_section_hint(section: str, names: list[str], resolved_with: Mapping[str, str]) -> str:
    """What to do about a section no installed package registers."""
    missing = missing_packages(resolved_with)
    if missing:
        return (
            f": no installed package registers it; the file was resolved with "
            f"{', '.join(missing)}, not installed here: install it to run this scenario "
            "(`cosim plot` and studies' reports read a run's tables without it)"
        )
    return (
        suggest(section, names)
        + " (sections come from installed packages: `cosim plugins` lists them)"
    )


def _carried_note(
    origin: str,
    carried: Mapping[str, Any],
    unregistered: list[tuple[str, Any]],
    resolved_with: Mapping[str, str],
) -> str:
    """The one line saying what of a run's scenario no installed package reads."""
    parts = [f"[{show_name(name)}]" for name in carried]
    parts += [f"{key} = {show_value(value)}" for key, value in unregistered]
    missing = missing_packages(resolved_with)
    used = f" (the run used {', '.join(missing)})" if missing else ""
    return (
        f"note: {origin}: {', '.join(parts)} carried unread: no installed package provides "
        f"{'it' if len(parts) == 1 else 'them'}{used}; the run's tables are read without it"
    )


def _resolve_paths(section: Any, origins: Mapping[str, str]) -> Any:
    """Make the relative file names of a section absolute (see ``param(path=True)``)."""
    changes = {}
    for f in fields(section):
        value = getattr(section, f.name)
        if not f.metadata.get("path") or not value or Path(value).is_absolute():
            continue
        origin = Path(origins.get(f.name, ""))
        base = origin.parent if origin.suffix == ".toml" and origin.is_file() else Path.cwd()
        changes[f.name] = str((base / value).resolve())
    return replace(section, **changes) if changes else section


def _apply_profile(
    cls: type[Any],
    table: dict[str, Any],
    origins: dict[str, str],
    section: str,
    origin: str,
) -> tuple[dict[str, Any], dict[str, str]]:
    """Fill a section's keys from its profile (``PROFILES``); given keys win."""
    profiles = getattr(cls, "PROFILES", None)
    if profiles is None:
        return table, origins
    name = table.get("profile", cls().profile)
    if not isinstance(name, str) or name not in profiles:
        where = origins.get("profile", origin)
        raise ConfigError(
            f"{where}: [{section}] profile = {name!r}: expected one of "
            + ", ".join(repr(p) for p in profiles)
            + suggest(str(name), list(profiles))
        )
    merged = {**profiles[name], **table}
    merged_origins = {key: origins.get(key, f"{origin} (profile {name})") for key in merged}
    return merged, merged_origins


def toml_value(value: Any) -> str:
    """A value as TOML text (the resolved scenario's, and the key reference's defaults)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise ValueError(f"cannot write non-finite {value} to TOML")
        return repr(value)
    if isinstance(value, str):
        return '"' + _TOML_ESCAPE.sub(_escaped, value) + '"'
    if isinstance(value, list | tuple):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if is_dataclass(value) and not isinstance(value, type):
        inner = ", ".join(f"{f.name} = {toml_value(getattr(value, f.name))}" for f in fields(value))
        return "{" + inner + "}"
    if isinstance(value, Mapping):  # a carried section's inline table
        return "{" + ", ".join(f"{toml_key(k)} = {toml_value(v)}" for k, v in value.items()) + "}"
    raise TypeError(f"cannot write {type(value).__name__} to TOML")


def _carried_value(value: Any) -> str:
    """A carried section's value as TOML text, as the file gave it (``nan`` and ``inf`` too)."""
    if isinstance(value, float) and not math.isfinite(value):
        return "nan" if value != value else ("inf" if value > 0 else "-inf")
    if isinstance(value, datetime.date | datetime.time):  # a datetime is a date too
        return value.isoformat()
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_carried_value(v) for v in value) + "]"
    if isinstance(value, Mapping):
        return (
            "{" + ", ".join(f"{toml_key(k)} = {_carried_value(v)}" for k, v in value.items()) + "}"
        )
    return toml_value(value)


def toml_key(key: str) -> str:
    """A key as TOML text: bare when it can be, else quoted."""
    return key if key and _BARE_KEY.fullmatch(key) else toml_value(key)


def dump_scenario(scenario: Scenario, *, provenance: Mapping[str, str] | None = None) -> str:
    """The fully resolved scenario as TOML: every section, every key.

    Loading the text back gives an equal :class:`Scenario`.

    Args:
        scenario: the scenario.
        provenance: the packages a run of it used, by version (a run folder's
            ``scenario.toml``): written first, as a ``[provenance]`` table.
    """
    lines = [f"# resolved from {scenario.source}"]
    if provenance:
        lines += ["", *provenance_lines(provenance)]
    for name, section in scenario.sections.items():
        lines.append("")
        lines.append(f"[{name}]")
        for f in fields(section):
            lines.append(f"{f.name} = {toml_value(getattr(section, f.name))}")
    for name, table in scenario.carried.items():  # as given: no installed package reads them
        lines += ["", f"[{toml_key(name)}]"]
        lines += [f"{toml_key(k)} = {_carried_value(v)}" for k, v in table.items()]
    return "\n".join(lines) + "\n"


def scenario_from_text(text: str, origin: str) -> Scenario:
    """Load a scenario from TOML text (used for round trips and tests)."""
    return _build(parse_toml(text, origin), origin, {})
