"""The plugin reference: every registry, its entry-point group and what is registered there."""

from __future__ import annotations

import re

from cosim.cli.plugins import plugins
from cosim.core.registry import Plugin, installed_groups
from cosim.reference import registries_page
from cosim.reference.registries_page import registries_markdown
from tests.cosim.reference.rendered import rows


def test_the_registry_reference_lists_every_registry_and_built_in():
    page = registries_markdown()
    for group in ("cosim.adapters", "cosim.protocols", "cosim.controllers", "cosim.planners"):
        assert f"`{group}`" in page
    for name in ("distributed_simplex", "hungarian", "dwa", "astar", "pibt", "lidar"):
        assert f"| `{name}` | `cosim` |" in page


def test_every_installed_registry_has_a_row_and_a_section_listing_every_entry():
    page = registries_markdown()
    groups = installed_groups()
    found = plugins(groups)
    for group in groups:
        assert (
            f"| {group.words} | `{group.entry_points}` | {group.chosen_by} | {group.contract} |"
            in page
        )
        heading = f"## {group.plural[0].upper()}{group.plural[1:]}\n"
        section = page.split(heading, 1)[1].split("\n## ", 1)[0]
        listed = re.findall(r"^\| `(\w+)` \| `([^`]+)` \|", section, flags=re.M)
        assert listed == [(p.name, p.package) for p in found if p.group == group], group


def test_each_entry_is_described_by_its_one_line_summary():
    page = registries_markdown()
    assert re.search(r"^\| `collisions` \| `cosim` \| Checks every proposed fleet step", page, re.M)
    assert re.search(r"^\| `none` \| `cosim` \| .+ \|$", page, re.M)  # a loss model


def test_a_plugin_that_cannot_be_loaded_is_listed_with_its_error(monkeypatch):
    group = next(g for g in installed_groups() if g.entry_points == "cosim.protocols")
    broken = Plugin(group, "auction", "labkit", "labkit.x:Auction", "", "No module named 'x' | y")
    monkeypatch.setattr(registries_page, "plugins", lambda groups: [broken])
    page = registries_markdown()
    assert "| `auction` | `labkit` | cannot be loaded: No module named 'x' \\| y |" in page
    assert ["auction", "labkit", "cannot be loaded: No module named 'x' | y"] in rows(page)


def test_a_summary_naming_a_topic_in_angle_brackets_shows_it():
    page = registries_markdown()
    teleop = [row for row in rows(page) if row[0] == "teleop" and "operator" in row[2]]
    assert teleop and "a Unity scene's /<robot>/cmd_vel" in teleop[-1][2]
