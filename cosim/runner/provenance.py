"""Whose code a run used: cosim, and every registered entry the run chose, by package version.

``summary.json`` lists them under ``"plugins"`` (:func:`run_plugins`): cosim itself, then
every adapter the run started, every settings section of its scenario, and every entry a
scenario key chose from a registry (``assignment.protocol``, ``navigation.controller``,
``network.loss_model``, ``robots.driver``, ... every key declared with
``param(..., registry=...)``), each with its package, version, group, name and target.
A key's entry counts even when its section is switched off: the resolved scenario names it,
and loading that file again needs it registered. The run folder's ``scenario.toml`` keeps
the packages and their versions (:func:`packages`) as its ``[provenance]`` table.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import fields, replace
from importlib.metadata import version
from typing import TYPE_CHECKING, Any

from cosim.core.entrypoints import COSIM
from cosim.core.plugins import PluginInfo, plugin_of
from cosim.core.registry import ADAPTERS, group_named
from cosim.scenario.model import Scenario, section_registry

if TYPE_CHECKING:
    from cosim.runner.assembly import Assembly


def run_plugins(scenario: Scenario, assembly: Assembly) -> list[dict[str, str]]:
    """Every package's code the run used, as ``summary.json``'s ``"plugins"``.

    Returns:
        cosim itself (``{"package": "cosim", "version": ..., "group": "", ...}``), then one
        entry per adapter started, section and registry choice (``package``, ``version``,
        ``group``, ``name``, ``target``; an entry given in code has package ``""``).
    """
    found: dict[tuple[str, str], PluginInfo] = {}
    for info in (
        *(_adapter(name, adapter) for name, adapter in assembly.adapters),
        *_sections(scenario),
        *_choices(scenario),
    ):
        found.setdefault((info.group, info.name), info)
    return [PluginInfo(COSIM, version(COSIM)).as_dict(), *(i.as_dict() for i in found.values())]


def packages(plugins: Iterable[Mapping[str, str]]) -> dict[str, str]:
    """Each package of ``plugins`` (``summary.json``'s) with its version, in order.

    Code given in a script or test (package ``""``) has no package to name.
    """
    return {p["package"]: p["version"] for p in plugins if p.get("package")}


def _adapter(name: str, adapter: Any) -> PluginInfo:
    kind = type(adapter)
    info = plugin_of(kind) or PluginInfo("", "", target=f"{kind.__module__}:{kind.__qualname__}")
    return replace(info, group=ADAPTERS.entry_points, name=name)


def _sections(scenario: Scenario) -> Iterable[PluginInfo]:
    registry = section_registry()
    return (registry.plugin(name) for name in scenario.sections if name in registry)


def _choices(scenario: Scenario) -> Iterable[PluginInfo]:
    """The entry each key declared with ``param(..., registry=...)`` names."""
    for section in scenario.sections.values():
        for key in fields(section):
            group = key.metadata.get("registry")
            if group is None:
                continue
            chosen = getattr(section, key.name)
            registry = group_named(group).installed()
            for name in chosen if isinstance(chosen, tuple) else (chosen,):
                if name != key.metadata.get("off") and name in registry:
                    yield registry.plugin(name)
