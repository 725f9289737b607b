"""The generated references cover everything a user can set, read or run."""

from __future__ import annotations

import re

import cosim
from cosim.cli.args import build_parser
from cosim.reference.commands_page import commands_markdown
from cosim.reference.keys_page import keys_markdown
from cosim.reference.registries_page import registries_markdown
from cosim.reference.tables_page import documented_tables, tables_markdown
from cosim.scenario import dump_scenario
from tests.conftest import cosim_main


def _resolved_keys(text: str) -> list[tuple[str, str]]:
    section, keys = "", []
    for line in text.splitlines():
        if match := re.fullmatch(r"\[(\w+)\]", line):
            section = match.group(1)
        elif match := re.match(r"(\w+) = ", line):
            keys.append((section, match.group(1)))
    return keys


def test_every_key_of_the_humans_scenario_is_in_the_key_reference():
    done = cosim_main("check", "warehouse-humans", "--print")
    assert done.returncode == 0, done.stderr
    keys = _resolved_keys(done.stdout)
    assert len(keys) > 100
    page = keys_markdown()
    sections = re.split(r"^## `\[", page, flags=re.M)
    documented = {}
    for block in sections[1:]:
        name = block.split("]", 1)[0]
        documented[name] = set(re.findall(r"^\| `(\w+)` \|", block, flags=re.M))
    for section, key in keys:
        assert key in documented.get(section, set()), f"[{section}] {key} is not documented"


def test_every_table_a_full_run_writes_is_declared_with_its_columns_and_documented():
    scenario = cosim.load_scenario(
        "warehouse-humans",
        {
            "scenario.duration_s": 4.0,
            "robots.driver": "tasks",
            "mapping.enabled": True,
            "mocap.source": "simulated",
            "mocap.robots": ["robot_1"],
            "mocap.dropout": 0.3,
            "humans.workers": 3,
        },
    )
    result = cosim.run(scenario)
    documented = {t.spec.name: t.spec for t in documented_tables()}
    for name, frame in result.tables.items():
        assert name in documented, f"table {name} has no TableSpec listed by its adapter"
        assert list(frame.columns) == list(documented[name].columns), name
    page = tables_markdown()
    for spec in documented.values():
        assert f"## `{spec.name}`" in page
        for column in spec.columns:
            assert f"| `{column}` |" in page


def test_the_command_reference_has_every_command_and_flag():
    page = commands_markdown()
    parser_help = build_parser().format_help()
    for command in ("run", "check", "study", "plugins", "map", "plot", "world", "standin"):
        assert f"## `cosim {command}`" in page and command in parser_help
    for flag in ("--set", "--live-port", "--scheduler", "--reference", "--gif"):
        assert flag in page


def test_the_registry_reference_lists_every_registry_and_built_in():
    page = registries_markdown()
    for group in ("cosim.adapters", "cosim.protocols", "cosim.controllers", "cosim.planners"):
        assert f"`{group}`" in page
    for name in ("distributed_simplex", "hungarian", "dwa", "astar", "pibt", "lidar"):
        assert f"| `{name}` | `cosim` |" in page


def test_the_resolved_scenario_lists_the_sections_in_reference_order():
    text = dump_scenario(cosim.load_scenario("warehouse-random"))
    order = re.findall(r"^\[(\w+)\]$", text, flags=re.M)
    assert order[:6] == ["scenario", "world", "robots", "lidar", "odometry", "network"]
    assert order[-1] == "record"
