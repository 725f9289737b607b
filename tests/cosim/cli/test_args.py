"""The command line's parser: built without any outside system's library."""

import subprocess
import sys

import pytest

from cosim.cli.args import build_parser
from tests.conftest import REPO

HEAVY = ("cyclonedds", "libsumo", "sumolib", "traci", "motioncapture", "pandas", "rosbags")
"""Libraries `cosim --help` must not import (DDS, SUMO, motion capture, tables, bags)."""


def test_building_the_parser_and_its_help_imports_no_outside_system():
    probe = (
        "import sys\n"
        "from cosim.cli.args import build_parser\n"
        "build_parser().format_help()\n"
        f"print(sorted({{m.split('.')[0] for m in sys.modules}} & set({HEAVY!r})))\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, cwd=REPO, check=True
    )
    assert done.stdout.strip() == "[]"


def test_every_command_has_its_help():
    parser = build_parser()
    commands = next(a for a in parser._actions if a.dest == "command")
    assert {"run", "check", "study", "map", "standin", "plugins"} <= set(commands.choices)
    for name, sub in commands.choices.items():
        assert sub.format_help().strip(), name


@pytest.mark.parametrize("kind", ["planner", "planners", "cosim.planners"])
def test_a_registry_is_named_by_group_short_name_or_singular(kind):
    assert build_parser().parse_args(["plugins", kind]).kinds == ["cosim.planners"]
