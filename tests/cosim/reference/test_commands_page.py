"""The command-line reference: every command's help, from the parser itself."""

from __future__ import annotations

import contextlib
import io
import re

import pytest

from cosim.cli.args import build_parser
from cosim.reference.commands_page import commands_markdown


def _help_of(*command: str) -> str:
    """What ``cosim COMMAND --help`` prints."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit):
        build_parser().parse_args([*command, "--help"])
    return out.getvalue().rstrip()


def test_the_command_reference_has_every_command_and_flag():
    page = commands_markdown()
    parser_help = build_parser().format_help()
    for command in ("run", "check", "study", "plugins", "map", "plot", "world", "standin"):
        assert f"## `cosim {command}`" in page and command in parser_help
    for flag in ("--set", "--live-port", "--scheduler", "--reference", "--gif"):
        assert flag in page


def test_the_page_opens_with_the_exit_statuses_and_the_parser_s_own_help():
    page = commands_markdown()
    assert page.startswith("# Command line\n")
    assert "## Exit status" in page
    for status in ("| 0 | done |", "| 1 | cosim's own", "| 2 | invalid input", "| 3 | a plugin"):
        assert status in page
    assert "| 4 | a study finished, but some of its runs failed" in page
    assert f"```text\n{build_parser().format_help().rstrip()}\n```" in page


def test_every_subcommand_and_nested_subcommand_has_a_section_with_what_its_help_prints():
    page = commands_markdown()
    headings = re.findall(r"^(#{2,3}) `cosim ([\w ]+)`$", page, flags=re.M)
    names = [name for _, name in headings]
    assert {"run", "check", "study", "plot", "bag", "bag info"} <= set(names)
    # a nested subcommand is a level deeper, right under its command
    assert headings[names.index("bag info")] == ("###", "bag info")
    assert names.index("bag info") == names.index("bag") + 1
    for level, name in headings:
        section = f"{level} `cosim {name}`\n\n```text\n{_help_of(*name.split())}\n```\n"
        assert section in page, name
