"""A scenario that extends another: ``extends = "warehouse-rows"`` at a file's top level.

The file then holds only the keys that differ. ``extends`` names a preset, or another
scenario file by its path relative to the extending file (a path ends in ``.toml`` or holds
a ``/``); that one may extend another in turn. Every key a file sets overrides the one it
extends: tables (a ``[section]``, an inline table) merge key by key, anything else (a list, a
number) replaces. The chain is resolved before the scenario is validated, and each key
remembers the file that set it, so an error names the file that holds the bad key (the
extending file or the extended one). The resolved scenario has no ``extends``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cosim.core.errors import ConfigError
from cosim.scenario.fields import show_value, suggest

EXTENDS = "extends"
"""The top-level key naming the scenario a file extends."""

Reader = Callable[[str | Path], tuple[str, dict[str, Any]]]
"""Reads a preset (by name) or a scenario file (by path): its origin and raw TOML."""


@dataclass(frozen=True)
class Layers:
    """A scenario's raw sections with its ``extends`` chain resolved.

    Attributes:
        raw: section name -> its table (or whatever value the outermost file gave it).
        keys: (section, key) -> the file or preset that set the key.
        sections: section name -> the outermost file or preset that names the section.
    """

    raw: dict[str, Any]
    keys: dict[tuple[str, str], str]
    sections: dict[str, str]


@dataclass(frozen=True)
class _Source:
    """One link of the chain: where it came from, its folder (None: a preset), its identity."""

    origin: str
    folder: Path | None
    identity: str


def resolve(
    origin: str, raw: dict[str, Any], *, read: Reader, presets: Callable[[], list[str]]
) -> Layers:
    """Follow ``extends`` from the scenario ``origin`` (its raw TOML ``raw``) and merge.

    Args:
        origin: the file (as given) or ``"preset NAME"`` that ``raw`` was read from.
        raw: its TOML, as read.
        read: reads an extended preset or file (a TOML error in it names it).
        presets: the preset names.

    Raises:
        ConfigError: one line naming the file that holds ``extends`` and its value, for a
            value that is not a string, a preset or file that does not exist, a folder,
            or a chain that comes back to a file it passed.
    """
    source = _source(origin, presets)
    layers: list[tuple[str, dict[str, Any]]] = []
    seen = [source]
    while True:
        table = dict(raw)
        value = table.pop(EXTENDS, None)
        layers.append((source.origin, table))
        if value is None:
            break
        source = _extended(source, value, presets)
        if any(s.identity == source.identity for s in seen):
            chain = " extends ".join(s.origin for s in [*seen, source])
            raise ConfigError(
                f"{seen[-1].origin}: {EXTENDS} = {show_value(value)}: a cycle ({chain}); "
                "expected a chain that ends in a scenario extending nothing"
            )
        seen.append(source)
        _, raw = read(Path(source.origin) if source.folder is not None else value)
    return _merge(layers)


def _source(origin: str, presets: Callable[[], list[str]]) -> _Source:
    """The scenario ``origin`` names: a preset (``"preset NAME"``) or a file."""
    if origin.startswith("preset ") and origin.removeprefix("preset ") in presets():
        return _Source(origin, None, origin)
    path = Path(origin)
    return _Source(origin, path.parent, str(path.resolve()))


def _extended(extending: _Source, value: Any, presets: Callable[[], list[str]]) -> _Source:
    """The preset or file that ``extends = value`` names in ``extending``."""
    where = f"{extending.origin}: {EXTENDS} = {show_value(value)}"
    if not isinstance(value, str) or not value:
        raise ConfigError(
            f"{where}: expected a preset name or the path of a scenario file, relative to "
            'this file (e.g. extends = "warehouse-rows")'
        )
    if not (value.endswith(".toml") or "/" in value):
        names = presets()
        if value not in names:
            raise ConfigError(
                f"{where}: not a preset" + suggest(value, names) + " (a scenario file's path "
                "ends in .toml; `cosim scenarios` lists the presets)"
            )
        return _Source(f"preset {value}", None, f"preset {value}")
    if extending.folder is None:
        raise ConfigError(f"{where}: a preset extends only presets; expected a preset name")
    path = extending.folder / value
    try:
        is_file, is_dir = path.is_file(), path.is_dir()
        identity = str(path.resolve())
    except (OSError, ValueError) as error:  # a name too long, a NUL byte
        reason = error.strerror if isinstance(error, OSError) and error.strerror else error
        raise ConfigError(f"{where}: cannot be read ({reason}); expected a scenario file") from None
    if is_dir:
        raise ConfigError(f"{where}: {path} is a folder; expected a scenario file")
    if not is_file:
        raise ConfigError(
            f"{where}: no scenario file {path} (a path is relative to the extending file)"
        )
    return _Source(str(path), path.parent, identity)


def _merge(layers: list[tuple[str, dict[str, Any]]]) -> Layers:
    """Merge the chain's tables, the innermost (extended by all) first, each over the last."""
    raw: dict[str, Any] = {}
    keys: dict[tuple[str, str], str] = {}
    sections: dict[str, str] = {}
    for origin, table in reversed(layers):
        for section, value in table.items():
            below = raw.get(section)
            if isinstance(value, dict) and section in raw and not isinstance(below, dict):
                # the extended file's non-table would vanish under this table: name it
                raise ConfigError(
                    f"{sections[section]}: {section} = {show_value(below)}: expected a "
                    f"[{section}] table of keys"
                )
            raw[section] = merged(below, value) if isinstance(value, dict) else value
            sections[section] = origin
            if isinstance(value, dict):
                keys.update(((section, key), origin) for key in value)
    # sections in the order of the outermost file, then those only the extended ones name
    order = [s for origin, table in layers for s in table]
    raw = {s: raw[s] for s in dict.fromkeys(order)}
    return Layers(raw, keys, sections)


def merged(below: Any, above: Mapping[str, Any]) -> dict[str, Any]:
    """``above`` over ``below``: tables merge key by key (recursively), anything else replaces.

    Neither argument is changed; a value of ``below`` that is not a table counts as absent.
    """
    out = dict(below) if isinstance(below, dict) else {}
    for key, value in above.items():
        out[key] = merged(out.get(key), value) if isinstance(value, dict) else value
    return out
