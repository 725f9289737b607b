"""``cosim plugins``: every registered implementation, where it comes from, what it does.

The built-ins are listed beside any installed plugin package's, because they register the
same way: each kind of pluggable thing is a :class:`~cosim.core.registry.Group` registered
in ``cosim.registries``, its entries in the group's own entry points. A plugin that cannot
be loaded is listed with the reason; it stops no run that does not use it.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any

from cosim.core.registry import ADAPTERS, AdapterRegistry, Group, Plugin, Registry, installed_groups


def registry_of(group: Group) -> Registry[Any]:
    """The installed registry of ``group`` (adapters with their requirements resolved)."""
    return AdapterRegistry.from_entry_points() if group == ADAPTERS else group.installed()


def plugins(groups: Sequence[Group] | None = None) -> list[Plugin]:
    """Every entry of ``groups`` (default: all), loaded to read its summary, or with its error."""
    return [p for g in groups or installed_groups() for p in registry_of(g).describe()]


def plugin_lines(groups: Sequence[Group] | None = None) -> Iterator[str]:
    """``cosim plugins``' output: a block per registry, a line per entry."""
    groups = list(groups or installed_groups())
    found = plugins(groups)
    name_width = max((len(p.name) for p in found), default=4)
    package_width = max((len(p.package) for p in found), default=7)
    for group in groups:
        entries = [p for p in found if p.group == group]
        yield f"{group.plural} ({group.entry_points}): {len(entries)}"
        for p in entries:
            said = p.summary if p.error is None else f"BROKEN: {p.error}"
            yield f"  {p.name:<{name_width}}  {p.package:<{package_width}}  {said}"
        yield ""
