"""``cosim plugins``: every registered implementation, where it comes from, what it does.

The built-ins are listed beside any installed plugin package's, because they register the
same way: each kind of pluggable thing is a :class:`~cosim.core.registry.Group` registered
in ``cosim.registries``, its entries in the group's own entry points. A plugin that cannot
be loaded is listed with the reason; it stops no run that does not use it. A name that two
packages register in one group is listed once, marked ``CLASH``, with both packages: it
stops every run that uses the group, so ``cosim plugins`` then exits 2.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator, Sequence

from cosim.cli.exits import EXIT_INPUT
from cosim.core.entrypoints import Clash, clashes, registered_once
from cosim.core.registry import REGISTRIES, Group, Plugin, group_named

CLASH = "CLASH"
"""How ``cosim plugins`` marks a name registered twice in one group."""


def listed_groups() -> list[Group]:
    """Every registry whose name one package registers (a clashing one is said apart)."""
    return [group_named(name) for name in registered_once(REGISTRIES)]


def plugins(groups: Sequence[Group] | None = None) -> list[Plugin]:
    """Every entry of ``groups`` (default: all), loaded to read its summary, or with its error.

    A name registered twice in a group is left out (see :func:`group_clashes`).
    """
    return [p for g in groups or listed_groups() for p in g.listed().describe()]


def group_clashes(groups: Sequence[Group] | None = None) -> list[Clash]:
    """The names registered twice in ``groups`` (default: every group and the registries)."""
    found = [] if groups else clashes(REGISTRIES)
    return found + [c for g in groups or listed_groups() for c in g.clashes()]


def plugin_lines(groups: Sequence[Group] | None = None) -> Iterator[str]:
    """``cosim plugins``' output: a block per registry, a line per entry, one per clash."""
    every = not groups
    groups = list(groups or listed_groups())
    found = plugins(groups)
    clashing = group_clashes(groups)
    name_width = max((len(p.name) for p in found), default=4)
    package_width = max((len(f"{p.package} {p.version}") for p in found), default=7)
    if every and clashes(REGISTRIES):
        yield f"registries ({REGISTRIES}): {len(clashes(REGISTRIES))} clashing"
        yield from (_clash_line(c, name_width) for c in clashes(REGISTRIES))
        yield ""
    for group in groups:
        entries = [p for p in found if p.group == group]
        twice = [c for c in clashing if c.group == group.entry_points]
        yield f"{group.plural} ({group.entry_points}): {len(entries) + len(twice)}"
        for p in entries:
            said = p.summary if p.error is None else f"BROKEN: {p.error}"
            package = f"{p.package} {p.version}".strip()
            yield f"  {p.name:<{name_width}}  {package:<{package_width}}  {said}"
        yield from (_clash_line(c, name_width) for c in twice)
        yield ""


def list_plugins(groups: Sequence[Group] | None = None) -> int:
    """Print ``cosim plugins``' lines; the exit status: 2 when a name is registered twice."""
    for line in plugin_lines(groups):
        print(line)
    found = group_clashes(groups)
    if not found:
        return 0
    names = ", ".join(f"{c.group} {c.name!r}" for c in found)
    print(
        f"cosim: error: registered twice ({CLASH} above): {names}; a run that uses such a "
        "registry is refused until one package is uninstalled or renames its entry",
        file=sys.stderr,
    )
    return EXIT_INPUT


def _clash_line(clash: Clash, width: int) -> str:
    said = f"registered {clash.claimants()}; uninstall one or rename it"
    return f"  {clash.name:<{width}}  {CLASH}: {said}"
