"""``[provenance]``: the packages, by version, that a run's resolved scenario was run with.

A run folder's ``scenario.toml`` begins with a ``[provenance]`` table, one
``package = "version"`` line per package whose code the run used (cosim's own first)::

    [provenance]
    cosim = "0.1.0"
    labkit = "0.1.0"

It is not a section: loading the file reads it (:func:`split_provenance`) and runs nothing
differently; a malformed one is refused in one line. When the installed versions differ, or
a package is gone, the command line says so in one note (:func:`provenance_note`): the
file still runs, but not necessarily as it ran then.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterator, Mapping
from importlib.metadata import PackageNotFoundError, version
from typing import Any

from cosim.core.errors import ConfigError
from cosim.scenario.fields import show_name, show_value

PROVENANCE = "provenance"
"""The table's name (no section may take it)."""
_PACKAGE = re.compile(r"[A-Za-z0-9](?:[A-Za-z0-9._-]*[A-Za-z0-9])?")
"""A distribution's name (PEP 508)."""
_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def split_provenance(
    raw: Mapping[str, Any], origin: str, origins: Mapping[tuple[str, str], str]
) -> tuple[dict[str, Any], dict[str, str]]:
    """The sections of a scenario file, and its ``[provenance]`` (package -> version).

    Args:
        raw: the file's tables.
        origin: the file (for messages).
        origins: where keys came from, by (section, key): an override's origin ends with
            its dotted key (``--set provenance.x``), and ``[provenance]`` is no setting.

    Raises:
        ConfigError: ``provenance`` is no table of ``package = "version"``, or is set by an
            override; one line naming the file, the key and what was expected.
    """
    sections = {name: table for name, table in raw.items() if name != PROVENANCE}
    table = raw.get(PROVENANCE, {})
    overridden = next(
        (o for (s, k), o in origins.items() if s == PROVENANCE and o.endswith(f" {s}.{k}")),
        None,
    )  # a file's key (from an extended file too) is named by the file alone
    if overridden is not None:
        raise ConfigError(
            f"{overridden}: [provenance] says which packages a run used; it is no setting "
            "(set a section's key instead)"
        )
    if not isinstance(table, dict):
        raise ConfigError(
            f"{origin}: provenance = {show_value(table)}: expected a [provenance] table of "
            'package = "version" lines'
        )
    for package, said in table.items():
        if not _PACKAGE.fullmatch(package):
            raise ConfigError(
                f"{origin}: [provenance] {show_name(package)}: expected a package name "
                "(letters, digits, '.', '_', '-')"
            )
        if not isinstance(said, str) or not said or not said.isprintable():
            raise ConfigError(
                f"{origin}: [provenance] {package} = {show_value(said)}: expected its version "
                'as a string ("0.1.0")'
            )
    return sections, dict(table)


def provenance_lines(packages: Mapping[str, str]) -> Iterator[str]:
    """The ``[provenance]`` table of ``packages`` (package -> version) as TOML lines."""
    yield "# the packages this run used, by version (`cosim run` notes any installed otherwise)"
    yield f"[{PROVENANCE}]"
    for package, said in packages.items():
        key = package if _BARE_KEY.fullmatch(package) else json.dumps(package)
        yield f"{key} = {json.dumps(said)}"


def provenance_note(source: str, resolved_with: Mapping[str, str]) -> str | None:
    """One line saying which packages are installed otherwise than ``resolved_with`` says.

    ``note: runs/a/scenario.toml was resolved with labkit 0.1.0; installed: labkit 0.2.0
    (results may differ from that run's)`` (``no labkit`` when it is gone); None when every
    version matches.
    """
    then, now = [], []
    for package, said in resolved_with.items():
        installed = _installed_version(package)
        if installed != said:
            then.append(f"{package} {said}")
            now.append(f"{package} {installed}" if installed else f"no {package}")
    if not then:
        return None
    return (
        f"note: {source} was resolved with {', '.join(then)}; installed: {', '.join(now)} "
        "(results may differ from that run's)"
    )


def missing_packages(resolved_with: Mapping[str, str]) -> list[str]:
    """``package version`` of each package ``resolved_with`` names that is not installed."""
    return [f"{p} {said}" for p, said in resolved_with.items() if not _installed_version(p)]


def _installed_version(package: str) -> str:
    try:
        return version(package)
    except PackageNotFoundError:
        return ""
