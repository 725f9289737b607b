"""``cosim plugins``: every registered implementation, where it comes from, what it does.

The built-ins are listed beside any installed plugin package's, because they register the
same way (entry-point groups, :data:`cosim.core.registry.GROUPS`). A plugin that cannot be
loaded is listed with the reason; it stops no run that does not use it.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any

from adapters.assignment.contract import protocol_registry
from adapters.navigation.contract import controller_registry, planner_registry, traffic_registry
from cosim.core.registry import GROUPS, KIND_WORDS, AdapterRegistry, Plugin, Registry
from cosim.runner.assembly import driver_registry
from cosim.scenario.model import section_registry

KINDS = ("adapter", "section", "driver", "protocol", "controller", "planner", "traffic")
"""The registries ``cosim plugins`` lists, in this order."""


def registry_of(kind: str) -> Registry[Any]:
    """The installed registry of ``kind``, with its contract check."""
    makers = {
        "adapter": AdapterRegistry.from_entry_points,
        "section": section_registry,
        "driver": driver_registry,
        "protocol": protocol_registry,
        "controller": controller_registry,
        "planner": planner_registry,
        "traffic": traffic_registry,
    }
    return makers[kind]()


def plugins(kinds: Sequence[str] = KINDS) -> list[Plugin]:
    """Every registered entry of ``kinds``, loaded (to read its summary) or with its error."""
    return [plugin for kind in kinds for plugin in registry_of(kind).describe()]


def plugin_lines(kinds: Sequence[str] = KINDS) -> Iterator[str]:
    """``cosim plugins``' output: a block per registry, a line per entry."""
    found = plugins(kinds)
    name_width = max((len(p.name) for p in found), default=4)
    package_width = max((len(p.package) for p in found), default=7)
    for kind in kinds:
        entries = [p for p in found if p.kind == kind]
        words = KIND_WORDS[kind]
        plural = words[:-1] + "ies" if words.endswith("y") else words + "s"
        yield f"{plural} ({GROUPS[kind]}): {len(entries)}"
        for p in entries:
            said = p.summary if p.error is None else f"BROKEN: {p.error}"
            yield f"  {p.name:<{name_width}}  {p.package:<{package_width}}  {said}"
        yield ""
