"""Whose code it is: the package, version and entry point behind a module or an object.

A run calls code of several packages: cosim's own built-ins, and the plugins a user
installed (a package declaring entry points in a ``cosim.*`` group) or handed to
``cosim.run`` in code. When that code fails, or hands back a value cosim cannot take, the
error names the plugin (:class:`PluginError`), so a user's fault is never reported as a
bug of cosim, and a bug of cosim never as the user's.

:func:`plugin_of_module` answers from the installed packages' entry points alone (no
import): a module belongs to the package whose entry points name it, or a module above
it. Code given to a run directly (an adapter class for ``cosim.run(adapters=[...])``, an
entry a test registers with :meth:`~cosim.core.registry.Registry.with_entry`) is noted with
:func:`note_given`.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, replace
from functools import cache
from typing import Any

from cosim.core.entrypoints import COSIM as COSIM  # cosim's own distribution
from cosim.core.entrypoints import installed
from cosim.core.entrypoints import rescan as rescan_entry_points
from cosim.core.errors import CosimError

COSIM_PACKAGES = ("cosim", "models", "adapters", "studies")
"""The import packages of cosim's distribution."""
GROUP_PREFIX = "cosim."
"""Entry-point groups of cosim's registries start with this."""


@dataclass(frozen=True)
class PluginInfo:
    """A plugin, as errors, ``summary.json`` and ``cosim plugins`` name it.

    Attributes:
        package: the distribution (``labkit``); ``""`` for code given in a script or test.
        version: the distribution's version (``""`` for code given in a script or test).
        group: the entry-point group (``cosim.controllers``), ``""`` when not known.
        name: the registered name (``pure_pursuit``), ``""`` when not known.
        target: ``module:attribute`` of the entry, or the module.
    """

    package: str
    version: str
    group: str = ""
    name: str = ""
    target: str = ""

    @property
    def builtin(self) -> bool:
        """Whether it is cosim's own code."""
        return self.package == COSIM

    @property
    def kind(self) -> str:
        """What it is: the group's words (``local controller``), or ``plugin``."""
        return KINDS.get(self.group, self.group.removeprefix(GROUP_PREFIX) or "plugin")

    def describe(self) -> str:
        """``local controller 'pure_pursuit' (labkit.pursuit:PurePursuit, labkit 0.1.0)``."""
        where = self.target
        if self.package:
            owner = f"{self.package} {self.version}".strip()
            where = f"{where}, {owner}" if where else owner
        else:
            where = f"{where}, given in code" if where else "given in code"
        name = f" {self.name!r}" if self.name else ""
        return f"{self.kind}{name} ({where})"

    def as_dict(self) -> dict[str, str]:
        """The plugin as JSON (``summary.json``): package, version, group, name, target."""
        return {
            "package": self.package,
            "version": self.version,
            "group": self.group,
            "name": self.name,
            "target": self.target,
        }


KINDS: dict[str, str] = {}
"""Entry-point group -> how messages name one entry; each registry group adds itself."""


class PluginError(CosimError):
    """A plugin's code failed: it raised, hung, or handed back a value cosim refuses.

    The message is one line: the plugin, what went wrong, what cosim was doing and the
    simulated time. The runner keeps what ran and writes :attr:`details` (the traceback)
    into the run folder.

    Attributes:
        plugin: whose code it was (None: not known).
        problem: what went wrong (``returned a command of shape (3,); expected (2,)``).
        doing: what cosim was doing (``computing robot_2's command``), or ``""``.
        t_ns: the simulated time (ns), once the runner knows it.
        details: the traceback, or ``""``.
    """

    def __init__(
        self,
        plugin: PluginInfo | None,
        problem: str,
        *,
        doing: str = "",
        t_ns: int | None = None,
        details: str = "",
    ) -> None:
        self.plugin = plugin
        self.problem = problem
        self.doing = doing
        self.t_ns = t_ns
        self.details = details
        super().__init__(self._line())

    def _line(self) -> str:
        who = self.plugin.describe() if self.plugin is not None else "a plugin"
        line = f"{who} {self.problem}"
        if self.doing:
            line += f" while {self.doing}"
        if self.t_ns is not None:
            line += f" at t = {self.t_ns / 1e9:.9g} s simulated"
        return line

    def at(self, t_ns: int) -> PluginError:
        """The error with the simulated time set (when it has none yet)."""
        if self.t_ns is None:
            self.t_ns = t_ns
            self.args = (self._line(), *self.args[1:])
        return self

    def __reduce__(self) -> Any:  # pickled across a study's worker processes
        return (_rebuild, (self.plugin, self.problem, self.doing, self.t_ns, self.details))


def _rebuild(
    plugin: PluginInfo | None, problem: str, doing: str, t_ns: int | None, details: str
) -> PluginError:
    return PluginError(plugin, problem, doing=doing, t_ns=t_ns, details=details)


def refuse(owner: Any, problem: str, *, doing: str = "") -> PluginError:
    """The error for a value ``owner`` (a plugin's object or class) handed back.

    Example: ``raise refuse(controller, f"returned {cmd!r}; expected finite numbers")``.
    """
    return PluginError(plugin_of(owner), problem, doing=doing)


# -- whose module is it ------------------------------------------------------------------------
_GIVEN: dict[str, PluginInfo] = {}
"""Code given to a run directly (scripts, tests), by ``module:qualname``."""


def note_given(obj: Any, group: str = "", name: str = "") -> None:
    """Note that ``obj`` (a class or function given in code) is a plugin of ``group``.

    Its module then belongs to that plugin (unless an installed package claims it).
    """
    module = getattr(obj, "__module__", None)
    if not isinstance(module, str) or _installed_owner(module) is not None:
        return
    target = f"{module}:{getattr(obj, '__qualname__', type(obj).__qualname__)}"
    _GIVEN[target] = PluginInfo("", "", group, name, target)


def plugin_of_module(module: str) -> PluginInfo | None:
    """The plugin (or cosim) whose code ``module`` is; None for other libraries.

    The entry whose target is in ``module`` itself names it; otherwise the package whose
    entry points name ``module``'s top-level package (with ``target`` the module).
    """
    found = _installed_owner(module)
    if found is not None:
        return found
    given = [info for target, info in _GIVEN.items() if target.split(":", 1)[0] == module]
    if len(given) == 1:
        return given[0]
    return PluginInfo("", "", target=module) if given else None


def plugin_of(obj: Any) -> PluginInfo | None:
    """The plugin (or cosim) an object or class comes from; None when not known."""
    cls = obj if isinstance(obj, type) else type(obj)
    module = getattr(obj, "__module__", None) if callable(obj) else None
    module = module if isinstance(module, str) else cls.__module__
    qualname = getattr(obj, "__qualname__", None) if callable(obj) else None
    target = f"{module}:{qualname if isinstance(qualname, str) else cls.__qualname__}"
    exact = _entries_by_target(_all_entries()).get(target) or _GIVEN.get(target)
    if exact is not None:
        return exact
    found = plugin_of_module(module)
    if found is None:
        return None
    return replace(found, target=target)


def _installed_owner(module: str) -> PluginInfo | None:
    entries = _all_entries()
    by_module = _entries_by_module(entries)
    parts = module.split(".")
    top = parts[0]
    if top in COSIM_PACKAGES:  # cosim's code is cosim's, whatever another package names
        exact = [info for info in by_module.get(module, ()) if info.builtin]
        return exact[0] if len(exact) == 1 else PluginInfo(COSIM, _version(COSIM), target=module)
    for depth in range(len(parts), 0, -1):
        found = _claimants(by_module.get(".".join(parts[:depth]), ()), top)
        if found:
            if depth == len(parts) and len(found) == 1:
                return found[0]
            return PluginInfo(found[0].package, found[0].version, target=module)
    package = _packages_by_top(entries).get(top)
    if package is not None:
        return PluginInfo(package[0], package[1], target=module)
    return None


def _claimants(infos: Iterable[PluginInfo], top: str) -> list[PluginInfo]:
    """Of the entries naming a module under ``top``, those of the package that ships it.

    Two packages may name one module (a plugin registering another's class under a name of
    its own, or under the same name: a clash); the code is the package's named after the
    module's top-level package (``labkit`` for ``labkit.auction``; cosim for its own),
    else the first package's in registry order.
    """
    found = list(infos)
    if top in COSIM_PACKAGES:
        return [info for info in found if info.builtin]
    owners = [info for info in found if _normalized(info.package) == _normalized(top)]
    return owners or found


def _normalized(name: str) -> str:
    return re.sub(r"[-_.]+", "_", name).lower()


def installed_plugins() -> list[PluginInfo]:
    """Every entry of every ``cosim.*`` group installed packages declare (cosim's included).

    cosim's first, then other packages' by package name; a name two packages register in
    one group (a clash) is listed for both.
    """
    return list(_all_entries())


def rescan() -> None:
    """Read the installed packages' entry points again (a package installed meanwhile)."""
    rescan_entry_points()
    _all_entries.cache_clear()


@cache
def _entries_by_module(entries: tuple[PluginInfo, ...]) -> dict[str, list[PluginInfo]]:
    by_module: dict[str, list[PluginInfo]] = {}
    for info in entries:
        module = info.target.split(":", 1)[0]
        by_module.setdefault(module, []).append(info)
    return by_module


@cache
def _entries_by_target(entries: tuple[PluginInfo, ...]) -> dict[str, PluginInfo]:
    by_target: dict[str, list[PluginInfo]] = {}
    for info in entries:
        by_target.setdefault(info.target, []).append(info)
    found = {
        t: _claimants(infos, t.split(".", 1)[0].split(":", 1)[0]) for t, infos in by_target.items()
    }
    return {target: infos[0] for target, infos in found.items() if infos}


@cache
def _packages_by_top(entries: tuple[PluginInfo, ...]) -> dict[str, tuple[str, str]]:
    by_top: dict[str, list[PluginInfo]] = {}
    for info in entries:
        by_top.setdefault(info.target.split(".", 1)[0].split(":", 1)[0], []).append(info)
    found = {top: _claimants(infos, top) for top, infos in by_top.items()}
    return {top: (infos[0].package, infos[0].version) for top, infos in found.items() if infos}


@cache
def _all_entries() -> tuple[PluginInfo, ...]:
    """Every entry of a ``cosim.*`` group, in registry order (cosim's first)."""
    return tuple(
        PluginInfo(lazy.package, lazy.version, lazy.group, lazy.name, lazy.value)
        for lazy in installed()
        if lazy.group.startswith(GROUP_PREFIX)
    )


@cache
def _version(package: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(package)
    except PackageNotFoundError:
        return ""
