"""Registries of pluggable implementations, filled from entry-point groups.

Every choice a scenario makes between implementations is a registry, and cosim's own
implementations register exactly as a third party's do: in its ``pyproject.toml``::

    [project.entry-points."cosim.protocols"]
    my_auction = "my_package.auction:MyAuction"

Each kind of pluggable thing is a :class:`Group`, declared by the contract of the
capability it belongs to (the assignment protocols by ``adapters.assignment.contract``,
the local controllers by ``adapters.navigation.contract``, ...): the core knows no
capability. The groups themselves are registered in the ``cosim.registries`` entry-point
group, so that ``cosim plugins`` and the references find every one, a plugin package's
new kinds included. A registry reads the names of its group from the installed packages'
metadata and imports an entry only when it is asked for, so a broken plugin is named
when, and only when, a run uses it. An unknown name is refused with the registered names
and the nearest ones. A name two packages both register in one group (a plugin's
``greedy`` beside cosim's) stops the group from loading, naming both
(:class:`~cosim.core.entrypoints.Clash`): which one a scenario means cannot be told.
"""

from __future__ import annotations

import contextlib
import difflib
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, replace
from functools import cache
from typing import Any, Generic, TypeVar

from cosim.core.entrypoints import Clash, Lazy, claims, clashes, entries, registered_once
from cosim.core.errors import RegistryError
from cosim.core.plugins import KINDS, PluginInfo, note_given

T = TypeVar("T")

REGISTRIES = "cosim.registries"
"""The entry-point group of the groups: every kind of pluggable thing, by name."""

Check = Callable[[str, Any], str | None]
"""A contract check: (name, loaded object) -> what is wrong, or None."""


@dataclass(frozen=True)
class Group:
    """One kind of pluggable thing: where its entries are registered and what they are.

    Declared once, by the contract of the capability it belongs to, and registered in the
    ``cosim.registries`` entry-point group.

    Attributes:
        entry_points: the entry-point group its entries are registered in
            (``cosim.controllers``).
        words: how messages name one entry (``local controller``).
        plural: how the references name several (``local controllers``).
        contract: where its contract is declared, for the references.
        chosen_by: the scenario key that picks an entry, for the references.
        named: whether every entry declares its own ``name`` (checked against the entry
            point's).
        check: a contract check run once on every loaded entry.
    """

    entry_points: str
    words: str
    plural: str
    contract: str
    chosen_by: str
    named: bool = True
    check: Check | None = None

    def __post_init__(self) -> None:
        KINDS[self.entry_points] = self.words

    def installed(self) -> Registry[Any]:
        """The entries installed packages register in this group (names only, no import).

        Entries of cosim itself come first, in declaration order; then other packages' by
        package name.

        Raises:
            RegistryError: a name is registered twice in the group (by two packages, or by
                a plugin and cosim): which one a scenario means cannot be told.
        """
        return Registry(self, {**_entry_points(self.entry_points), **_given(self.entry_points)})

    def listed(self) -> Registry[Any]:
        """For listings (``cosim plugins``): the entries whose name no other registers.

        A name registered twice is left out here and said by :meth:`clashes`.
        """
        return Registry(self, {**registered_once(self.entry_points), **_given(self.entry_points)})

    def clashes(self) -> list[Clash]:
        """The names of this group that more than one installed package registers."""
        return clashes(self.entry_points)


def installed_groups() -> list[Group]:
    """Every group registered in ``cosim.registries`` (cosim's first), loaded.

    Raises:
        RegistryError: for a registered group that cannot be loaded or is no :class:`Group`,
            or a group's name registered twice.
    """
    return [group_named(name) for name in _entry_points(REGISTRIES)]


def registry_names() -> list[str]:
    """The entry-point groups of every registry (``cosim.registries``), none imported.

    A group two packages register is named too (:func:`group_named` refuses it).
    """
    return list(claims(REGISTRIES))


@cache
def group_named(entry_points: str) -> Group:
    """The group whose entries are registered in ``entry_points`` (``cosim.controllers``).

    Settings name the group of a key this way (``param(..., registry="cosim.controllers")``)
    so that a settings module need not import its capability's contract.

    Raises:
        RegistryError: for a group that is not registered in ``cosim.registries``, cannot
            be loaded, or is no :class:`Group` for that entry-point group.
    """
    clash = next((c for c in clashes(REGISTRIES) if c.name == entry_points), None)
    if clash is not None:
        raise RegistryError(str(clash))
    lazy = registered_once(REGISTRIES).get(entry_points)
    if lazy is None:
        raise RegistryError(
            f"no registry {entry_points!r}"
            + suggest_names(entry_points, registered_once(REGISTRIES))
        )
    where = f"registry {entry_points!r} ({lazy.value}, package {lazy.package})"
    try:
        group = lazy.load()
    except Exception as error:  # a broken plugin must name itself
        raise RegistryError(f"{where} cannot be loaded: {type(error).__name__}: {error}") from error
    if not isinstance(group, Group) or group.entry_points != entry_points:
        raise RegistryError(
            f"{where} is {group!r}; expected a cosim.core.registry.Group of {entry_points!r}"
        )
    return group


@dataclass(frozen=True)
class Plugin:
    """One registered entry, as ``cosim plugins`` lists it.

    Attributes:
        group: the group it is registered in.
        name: the registered name.
        package: the distribution that registers it (``cosim`` for the built-ins).
        target: ``module:attribute`` of the entry point.
        summary: the first line of its docstring.
        error: why it cannot be loaded, or None.
        version: the package's version (``""`` for an entry given in code).
    """

    group: Group
    name: str
    package: str
    target: str
    summary: str
    error: str | None = None
    version: str = ""


class Registry(Generic[T]):
    """The entries of one group, by registered name, imported on first use.

    Args:
        group: the group (its words, its contract check).
        entries: name -> entry point (imported when asked for) or the object itself.
    """

    def __init__(self, group: Group, entries: Mapping[str, Lazy | T]) -> None:
        self.group = group
        self._entries: dict[str, Lazy | T] = dict(entries)
        self._loaded: dict[str, T] = {}

    @property
    def words(self) -> str:
        """How messages name an entry of this group (``assignment protocol``)."""
        return self.group.words

    def names(self) -> list[str]:
        """Registered names, in registry order."""
        return list(self._entries)

    def __contains__(self, name: object) -> bool:
        return name in self._entries

    def with_entry(self, name: str, entry: T) -> Registry[T]:
        """A copy with ``entry`` registered as ``name`` (for tests and ``cosim.run``)."""
        note_given(entry, self.group.entry_points, name)
        copy = Registry(self.group, {**self._entries, name: entry})
        copy._loaded = {k: v for k, v in self._loaded.items() if k != name}
        return copy

    def package(self, name: str) -> str:
        """The distribution that registers ``name`` (``cosim`` for the built-ins)."""
        entry = self._entries.get(name)
        if isinstance(entry, Lazy):
            return entry.package
        return "(given in code)"

    def version(self, name: str) -> str:
        """The version of the distribution that registers ``name`` (``""``: given in code)."""
        entry = self._entries.get(name)
        return entry.version if isinstance(entry, Lazy) else ""

    def plugin(self, name: str) -> PluginInfo:
        """Whose entry ``name`` is: its package, version and target, without importing it.

        An entry given in code has no package (``""``), as :mod:`cosim.core.plugins` says.
        """
        entry = self._entries.get(name)
        if entry is None:
            raise self.unknown(name)
        package = self.package(name) if isinstance(entry, Lazy) else ""
        return PluginInfo(
            package, self.version(name), self.group.entry_points, name, self.target(name)
        )

    def target(self, name: str) -> str:
        """Where ``name`` comes from: ``module:attribute``."""
        entry = self._entries[name]
        if isinstance(entry, Lazy):
            return entry.value
        return f"{getattr(entry, '__module__', '?')}:{getattr(entry, '__qualname__', '?')}"

    def unknown(self, name: str) -> RegistryError:
        """The error for a name that is not registered: the registered names, the nearest."""
        return RegistryError(f"unknown {self.words} {name!r}" + suggest_names(name, self.names()))

    def get(self, name: str) -> T:
        """The entry registered as ``name``, imported and checked on first use.

        Raises:
            RegistryError: for an unknown name (with the nearest ones), or an entry that
                cannot be imported or breaks its kind's contract (naming the plugin).
        """
        found = self._loaded.get(name)
        if found is not None:
            return found
        entry = self._entries.get(name)
        if entry is None:
            raise self.unknown(name)
        where = f"{self.words} {name!r} ({self.target(name)}, package {self.package(name)})"
        loaded: Any = entry
        if isinstance(entry, Lazy):
            try:
                loaded = entry.load()
            except Exception as error:  # a broken plugin must name itself
                raise RegistryError(
                    f"{where} cannot be loaded: {type(error).__name__}: {error}"
                ) from error
        declared = getattr(loaded, "name", name) if self.group.named else name
        if declared != name:
            raise RegistryError(f"{where} declares name = {declared!r}; expected {name!r}")
        check = self.group.check
        problem = check(name, loaded) if check is not None else None
        if problem is not None:
            raise RegistryError(f"{where}: {problem}")
        self._loaded[name] = loaded
        return loaded  # type: ignore[no-any-return]

    def load_all(self) -> dict[str, T]:
        """Every entry that loads, by name; broken ones are left out (see :meth:`describe`)."""
        loaded: dict[str, T] = {}
        for name in self.names():
            try:
                loaded[name] = self.get(name)
            except RegistryError:
                continue
        return loaded

    def describe(self) -> list[Plugin]:
        """Every entry with its package and one-line summary; broken ones with their error."""
        plugins = []
        for name in self.names():
            row = Plugin(self.group, name, self.package(name), self.target(name), "")
            row = replace(row, version=self.version(name))
            try:
                loaded = self.get(name)
            except RegistryError as error:
                plugins.append(replace(row, error=str(error)))
                continue
            declared = getattr(loaded, "summary", None)
            doc = declared if isinstance(declared, str) else (loaded.__doc__ or "").strip()
            plugins.append(replace(row, summary=doc.splitlines()[0] if doc else ""))
        return plugins


def suggest_names(name: str, names: Iterable[str]) -> str:
    """``; did you mean 'x'? (registered: a, b, c)`` for an unknown ``name``."""
    options = list(names)
    close = difflib.get_close_matches(name, options, n=3, cutoff=0.5)
    hint = f"; did you mean {', '.join(repr(c) for c in close)}?" if close else ""
    return f"{hint} (registered: {', '.join(options) or 'none'})"


_GIVEN: dict[str, dict[str, Any]] = {}
"""Entries registered in code (:func:`registered`), by group, then name."""


def _given(group: str) -> dict[str, Any]:
    return _GIVEN.get(group, {})


@contextlib.contextmanager
def registered(entry_points: str, name: str, entry: Any) -> Iterator[None]:
    """While inside, ``entry`` is registered as ``name`` in ``entry_points``, given in code.

    As if an installed package declared it (a test's protocol, a script's adapter, a
    settings section): every registry of the group lists it, and its errors name it as
    code given in a script or test.

    ```python
    with registered("cosim.protocols", "my_auction", MyAuction):
        cosim.run(cosim.load_scenario("warehouse-rows", {"assignment.protocol": "my_auction"}))
    ```

    Raises:
        RegistryError: ``name`` is registered in the group already.
    """
    taken = {**_entry_points(entry_points), **_given(entry_points)}
    if name in taken:
        owner = taken[name]
        where = owner.package if isinstance(owner, Lazy) else "code given earlier"
        raise RegistryError(
            f"{name!r} is registered in {entry_points} already (by {where}); "
            "choose another name for the entry given in code"
        )
    note_given(entry, entry_points, name)
    _GIVEN.setdefault(entry_points, {})[name] = entry
    try:
        yield
    finally:
        _GIVEN[entry_points].pop(name, None)


def _entry_points(group: str) -> dict[str, Lazy]:
    """A group's entry points, cosim's first, then other packages' by package name.

    Raises:
        RegistryError: a name is registered twice in the group (see :class:`Clash`).
    """
    return entries(group)


class AdapterRegistry(Registry[Any]):
    """Adapter types by registered name, with their requirements resolved.

    Args:
        entries: name -> adapter type, or entry point.
    """

    def __init__(self, entries: Mapping[str, Any]) -> None:
        super().__init__(ADAPTERS, entries)

    @classmethod
    def from_entry_points(cls) -> AdapterRegistry:
        """Every adapter that installed packages declare in ``cosim.adapters`` (not imported)."""
        return cls({**_entry_points(ADAPTERS.entry_points), **_given(ADAPTERS.entry_points)})

    def with_adapter(self, adapter: Any) -> AdapterRegistry:
        """A copy of this registry with ``adapter`` added under its own ``name``."""
        note_given(adapter, self.group.entry_points, adapter.name)
        copy = AdapterRegistry({**self._entries, adapter.name: adapter})
        copy._loaded = {k: v for k, v in self._loaded.items() if k != adapter.name}
        return copy

    def resolve(self, names: Iterable[str]) -> list[str]:
        """Order ``names`` and their requirements so that requirements come first.

        Among independent adapters the given order is kept; the result is deterministic.

        Raises:
            RegistryError: for an unknown or broken adapter, or a requirement cycle.
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
                if required not in self._entries:
                    raise RegistryError(
                        f"adapter {name!r} ({self.target(name)}) requires "
                        f"{self.unknown(required)!s}"
                    )
                visit(required)
            visiting.pop()
            ordered.append(name)

        for name in names:
            visit(name)
        return ordered


def _adapter_contract(name: str, loaded: Any) -> str | None:
    """What an adapter type lacks: ``requires``, a constructor, ``start`` and ``finish``."""
    if not callable(loaded):
        return "is not a class (expected a class constructed with the run)"
    requires = getattr(loaded, "requires", None)
    if not isinstance(requires, tuple) or not all(isinstance(r, str) for r in requires):
        return f"requires = {requires!r}; expected a tuple of adapter names"
    for method in ("start", "finish"):
        if not callable(getattr(loaded, method, None)):
            return f"has no {method}(run) method (see cosim.core.adapter.Adapter)"
    return None


ADAPTERS = Group(
    "cosim.adapters",
    "adapter",
    "adapters",
    "`cosim.core.adapter` (`Adapter`, `AdapterType`, `RunContext`)",
    "`[scenario] adapters`, and what a scenario's settings ask for",
    check=_adapter_contract,
)
"""Adapters: what gives a model time, a rate and a place on the bus."""
