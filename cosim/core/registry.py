"""The adapter registry, filled from the ``cosim.adapters`` entry-point group.

A third party adds an adapter by installing a package that declares, in its
``pyproject.toml``::

    [project.entry-points."cosim.adapters"]
    my_sensor = "my_package.adapter:MySensorAdapter"

An unknown name is an error that suggests the nearest registered names.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Mapping
from importlib.metadata import entry_points

from cosim.core.adapter import AdapterType
from cosim.core.errors import RegistryError

GROUP = "cosim.adapters"


class AdapterRegistry:
    """Adapter types by registered name.

    Args:
        entries: name -> adapter type.
    """

    def __init__(self, entries: Mapping[str, AdapterType]) -> None:
        self._entries = dict(entries)

    @classmethod
    def from_entry_points(cls) -> AdapterRegistry:
        """Load every adapter declared in the ``cosim.adapters`` entry-point group.

        Raises:
            RegistryError: if an entry point cannot be imported or its class declares
                another name than the entry point.
        """
        entries: dict[str, AdapterType] = {}
        for point in sorted(entry_points(group=GROUP), key=lambda p: p.name):
            try:
                loaded = point.load()
            except Exception as error:  # a broken plugin must name itself
                raise RegistryError(
                    f"adapter {point.name!r} ({point.value}) cannot be loaded: {error}"
                ) from error
            declared = getattr(loaded, "name", None)
            if declared != point.name:
                raise RegistryError(
                    f"adapter entry point {point.name!r} ({point.value}) declares "
                    f"name = {declared!r}; expected {point.name!r}"
                )
            entries[point.name] = loaded
        return cls(entries)

    def with_adapter(self, adapter: AdapterType) -> AdapterRegistry:
        """A copy of this registry with ``adapter`` added under its own name."""
        return AdapterRegistry({**self._entries, adapter.name: adapter})

    def names(self) -> list[str]:
        """Registered names, sorted."""
        return sorted(self._entries)

    def get(self, name: str) -> AdapterType:
        """Return the adapter type registered as ``name``.

        Raises:
            RegistryError: for an unknown name, suggesting the nearest ones.
        """
        found = self._entries.get(name)
        if found is None:
            close = difflib.get_close_matches(name, self.names(), n=3, cutoff=0.5)
            hint = f"; did you mean {', '.join(repr(c) for c in close)}?" if close else ""
            raise RegistryError(
                f"unknown adapter {name!r}{hint} (registered: {', '.join(self.names())})"
            )
        return found

    def resolve(self, names: Iterable[str]) -> list[str]:
        """Order ``names`` and their requirements so that requirements come first.

        Among independent adapters the given order is kept; the result is deterministic.

        Raises:
            RegistryError: for an unknown name or a requirement cycle.
        """
        ordered: list[str] = []
        visiting: list[str] = []

        def visit(name: str) -> None:
            if name in ordered:
                return
            if name in visiting:
                cycle = " -> ".join([*visiting[visiting.index(name) :], name])
                raise RegistryError(f"adapter requirement cycle: {cycle}")
            visiting.append(name)
            for required in self.get(name).requires:
                visit(required)
            visiting.pop()
            ordered.append(name)

        for name in names:
            visit(name)
        return ordered
