"""The installed packages' entry points, read once, and names two packages both claim.

Every registry (:mod:`cosim.core.registry`) and every answer to "whose code is this"
(:mod:`cosim.core.plugins`) reads the same list: the entry points of the installed
distributions, cosim's first, then other packages' by package name. A distribution found
twice on the import path counts once (the one imported), as ``importlib.metadata`` does.

A name registered twice in one group (by two packages, or by a plugin and cosim) is a
:class:`Clash`: which of the two a scenario's ``"greedy"`` means cannot be told, so the
group refuses to load (:func:`entries`) until one is uninstalled or renamed, while
``cosim plugins`` lists both (:func:`clashes`, :func:`registered_once`).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache
from importlib.metadata import distributions
from typing import Any

from cosim.core.errors import RegistryError

COSIM = "cosim"
GROUPS = "cosim."
"""The entry-point groups cosim reads begin so (``cosim.protocols``, ``cosim.registries``)."""
"""cosim's own distribution: its entries are built-ins (listed first), its faults cosim's bugs."""


@dataclass(frozen=True)
class Lazy:
    """An entry point, imported on first use.

    Wrapped, because the entry points of ``importlib.metadata`` and of its backport
    ``importlib_metadata`` (which some packages install into the import system) are
    different classes with the same attributes.

    Attributes:
        point: the entry point (``load()``, ``name``, ``group``, ``value``, ``dist``).
    """

    point: Any
    known_package: str | None = None
    """The distribution's name, when read once for all its entry points."""
    known_version: str | None = None
    """Its version, likewise."""

    def load(self) -> Any:
        """Import the entry point's object."""
        return self.point.load()

    @property
    def name(self) -> str:
        """The registered name (``greedy``)."""
        return str(self.point.name)

    @property
    def group(self) -> str:
        """The entry-point group (``cosim.protocols``)."""
        return str(self.point.group)

    @property
    def value(self) -> str:
        """``module:attribute``."""
        return str(self.point.value)

    @property
    def package(self) -> str:
        """The distribution that declares the entry point."""
        if self.known_package is not None:
            return self.known_package
        dist = getattr(self.point, "dist", None)
        return str(dist.name) if dist is not None else "?"

    @property
    def version(self) -> str:
        """The version of the distribution that declares it (``""`` when not known)."""
        if self.known_version is not None:
            return self.known_version
        dist = getattr(self.point, "dist", None)
        return str(dist.version) if dist is not None else ""

    def owner(self) -> str:
        """``cosim`` for the built-ins, ``labkit 0.1.0`` for a plugin package's."""
        return self.package if self.package == COSIM else f"{self.package} {self.version}".strip()


@dataclass(frozen=True)
class Clash:
    """A name that more than one entry registers in one group.

    Attributes:
        group: the entry-point group (``cosim.protocols``).
        name: the name registered more than once (``greedy``).
        claims: every entry registering it, cosim's first, then by package name.
    """

    group: str
    name: str
    claims: tuple[Lazy, ...]

    def claimants(self) -> str:
        """``by cosim (a.b:Greedy) and by labkit 0.1.0 (labkit.greedy:Greedy)``."""
        said = [f"by {claim.owner()} ({claim.value})" for claim in self.claims]
        return f"{', '.join(said[:-1])} and {said[-1]}"

    def __str__(self) -> str:
        return (
            f"{self.group}: {self.name!r} is registered {self.claimants()}; "
            "uninstall one or rename it"
        )


@cache
def installed() -> tuple[Lazy, ...]:
    """Every entry point of a ``cosim.*`` group, cosim's first, then by package.

    A distribution's metadata is read once for all its entry points (reading it per entry
    point took about 0.1 s of every run).
    """
    found, seen = [], set()
    for dist in distributions():
        points = [point for point in dist.entry_points if point.group.startswith(GROUPS)]
        metadata = dist.metadata
        name = str(metadata["Name"])
        key = re.sub(r"[-_.]+", "-", name).lower()
        if key in seen:  # the same distribution twice on the path: the first is imported
            continue
        seen.add(key)
        version = str(metadata["Version"] or "")
        found += [Lazy(point, name, version) for point in points]
    ours = [p for p in found if p.package == COSIM]
    theirs = sorted((p for p in found if p.package != COSIM), key=lambda p: p.package.lower())
    return (*ours, *theirs)


def claims(group: str) -> dict[str, tuple[Lazy, ...]]:
    """Every name registered in ``group``, with every entry that registers it, in order."""
    return dict(_grouped().get(group, {}))


@cache
def _grouped() -> dict[str, dict[str, tuple[Lazy, ...]]]:
    found: dict[str, dict[str, tuple[Lazy, ...]]] = {}
    for lazy in installed():
        names = found.setdefault(lazy.group, {})
        names[lazy.name] = (*names.get(lazy.name, ()), lazy)
    return found


def rescan() -> None:
    """Read the installed distributions again (a package installed meanwhile)."""
    installed.cache_clear()
    _grouped.cache_clear()


def clashes(group: str) -> list[Clash]:
    """The names of ``group`` that more than one entry registers."""
    return [Clash(group, name, both) for name, both in claims(group).items() if len(both) > 1]


def registered_once(group: str) -> dict[str, Lazy]:
    """The entries of ``group`` whose name no other entry registers (for listings)."""
    return {name: found[0] for name, found in claims(group).items() if len(found) == 1}


def entries(group: str) -> dict[str, Lazy]:
    """The entries of ``group`` by name, cosim's first, then other packages' by package.

    Raises:
        RegistryError: a name of the group is registered more than once; the message
            names the group, the name and every package with its target.
    """
    found = clashes(group)
    if found:
        more = len(found) - 1
        also = f" ({more} more there: `cosim plugins` lists them)" if more else ""
        raise RegistryError(f"{found[0]}{also}")
    return registered_once(group)
