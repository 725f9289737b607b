"""Keys renamed since older scenario files were written, and reading those files today.

A run folder's ``scenario.toml`` is the scenario as it was resolved then: a key renamed since
would make it unreadable (``unknown key 'yield_s'``), although drawing the run needs only its
tables and world. :data:`RENAMES` declares every renamed key with the commit that renamed it
and how an old value becomes the new one; :func:`migrate` applies them to a file's tables and
says each in one line.

A rename that keeps the meaning (``same_meaning``) also migrates where a scenario is run (the
new key runs what the old one ran). One whose model changed too migrates only where a run is
read (figures, bags, studies' reports): running such a file is refused with the new key to
set (:func:`renamed_hint`), since it would not run what it ran then.
"""

from __future__ import annotations

import copy
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from cosim.core.errors import ConfigError
from cosim.scenario.fields import show_value


def _gives_way(yield_s: Any) -> bool:
    """``humans.yield_s`` (s a walker stopped for a robot) as ``humans.avoid_robots``."""
    if isinstance(yield_s, bool) or not isinstance(yield_s, int | float):
        raise ValueError("expected a number of seconds")
    return bool(yield_s > 0)


@dataclass(frozen=True)
class Rename:
    """A scenario key renamed since files were written with it.

    Attributes:
        old: ``section.key`` as older files have it.
        new: ``section.key`` now.
        commit: the commit that renamed it (``git show`` it).
        convert: the new key's value from the old key's; raises ``ValueError`` (its message
            saying what was expected) for a value the old key never took.
        same_meaning: the new key with the converted value runs what the old key ran; false
            when the model behind it changed too.
        change: what changed, said after the rename in notes and errors.
    """

    old: str
    new: str
    commit: str
    convert: Callable[[Any], Any]
    same_meaning: bool
    change: str

    @property
    def sections(self) -> tuple[str, str]:
        """The old and the new key's section."""
        return self.old.partition(".")[0], self.new.partition(".")[0]


RENAMES: tuple[Rename, ...] = (
    Rename(
        old="humans.yield_s",
        new="humans.avoid_robots",
        commit="462a048",
        convert=_gives_way,
        same_meaning=False,
        change=(
            "people keep clear of robots through a speed model instead of stopping for one "
            "at most yield_s s; yield_s = 0 (never stopping) is avoid_robots = false"
        ),
    ),
)
"""Every scenario key renamed, oldest first (found with ``git log -S`` on the settings)."""


def _find(raw: Mapping[str, Any], dotted: str) -> tuple[bool, Any]:
    section, _, key = dotted.partition(".")
    table = raw.get(section)
    if isinstance(table, dict) and key in table:
        return True, table[key]
    return False, None


@dataclass(frozen=True)
class Migrated:
    """A scenario file's tables with renamed keys moved to their new names.

    Attributes:
        tables: the tables.
        notes: one line per key migrated.
        applied: the renames applied (each once).
    """

    tables: dict[str, Any]
    notes: tuple[str, ...]
    applied: tuple[Rename, ...]


def migrate(
    raw: Mapping[str, Any],
    origin: str,
    *,
    meaning_changes: bool = True,
    renames: tuple[Rename, ...] | None = None,
) -> Migrated:
    """A scenario file's tables with renamed keys under their new names, and a note each.

    Args:
        raw: the file's tables (not changed).
        origin: the file, for notes and errors.
        meaning_changes: migrate renames whose model changed too (reading a run); false
            leaves them in place (running a scenario: the loader refuses them with
            :func:`renamed_hint`).
        renames: the renames to apply (default :data:`RENAMES`).

    Returns:
        The tables, one line per key migrated (``note: origin: [humans] yield_s = 10.0
        read as humans.avoid_robots = true (renamed in 462a048: ...)``) and the renames
        applied.

    Raises:
        ConfigError: an old key holds a value it never took (naming the file, the key, the
            value and what was expected).
    """
    tables = copy.deepcopy(dict(raw))
    notes, applied = [], []
    for rename in RENAMES if renames is None else renames:
        if not (rename.same_meaning or meaning_changes):
            continue
        found, value = _find(tables, rename.old)
        if not found:
            continue
        old_section, new_section = rename.sections
        old_key = rename.old.partition(".")[2]
        new_key = rename.new.partition(".")[2]
        shown = f"note: {origin}: [{old_section}] {old_key} = {show_value(value)}"
        del tables[old_section][old_key]
        if _find(tables, rename.new)[0]:
            notes.append(f"{shown} ignored (renamed {rename.new} in {rename.commit}, set too)")
            continue
        try:
            new_value = rename.convert(value)
        except ValueError as error:
            raise ConfigError(
                f"{origin}: [{old_section}] {old_key} = {show_value(value)}: {error} (the key "
                f"was renamed {rename.new} in {rename.commit})"
            ) from None
        target = tables.setdefault(new_section, {})
        if isinstance(target, dict):  # else the loader refuses the section, naming it
            target[new_key] = new_value
            applied.append(rename)
            notes.append(
                f"{shown} read as {rename.new} = {show_value(new_value)} (renamed in "
                f"{rename.commit}: {rename.change})"
            )
    return Migrated(tables, tuple(notes), tuple(applied))


def migrate_dotted(
    values: Mapping[str, Any], *, renames: tuple[Rename, ...] | None = None
) -> dict[str, Any]:
    """``section.key`` -> value (a study's overrides, a run's row) with renames applied.

    Only renames of the same meaning apply: a study that set the old key ran what the new
    key runs. Where both keys are given, or the old value is one it never took, the
    values stay as they are (the comparison that follows then finds them different).
    """
    migrated = dict(values)
    for rename in RENAMES if renames is None else renames:
        if rename.same_meaning and rename.old in migrated and rename.new not in migrated:
            try:
                migrated[rename.new] = rename.convert(migrated.pop(rename.old))
            except ValueError:
                continue
    return migrated


def leftover(raw: Mapping[str, Any], *, renames: tuple[Rename, ...] | None = None) -> Rename | None:
    """The first rename whose old key ``raw`` still has (one :func:`migrate` left), or None."""
    for rename in RENAMES if renames is None else renames:
        if _find(raw, rename.old)[0]:
            return rename
    return None


def renamed_hint(rename: Rename) -> str:
    """``: renamed section.new in COMMIT (what changed); set section.new instead``."""
    return f": renamed {rename.new} in {rename.commit} ({rename.change}); set {rename.new} instead"


__all__ = ["RENAMES", "Migrated", "Rename", "leftover", "migrate", "migrate_dotted", "renamed_hint"]
