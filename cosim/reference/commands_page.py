"""The command-line reference: every command's help, from the parser itself."""

from __future__ import annotations

import argparse

from cosim.cli.args import build_parser
from cosim.cli.exits import EXIT_STATUSES
from cosim.reference.escaping import cell, code, fenced


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:  # argparse keeps its subcommands there
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def commands_markdown() -> str:
    """The whole command-line reference page."""
    parser = build_parser()
    lines = [
        "# Command line",
        "",
        "`cosim COMMAND ...`; every command answers `--help`. This page is generated from "
        "the command line's own parser (`cosim/reference/commands_page.py`).",
        "",
        "## Exit status",
        "",
        "| status | meaning |",
        "|---|---|",
        *(f"| {status} | {cell(meaning)} |" for status, meaning in EXIT_STATUSES.items()),
        "",
        *fenced(parser.format_help().rstrip()),
        "",
    ]
    for name, sub in _subparsers(parser).items():
        lines += [f"## {code(f'cosim {name}')}", "", *fenced(sub.format_help().rstrip()), ""]
        for inner_name, inner in _subparsers(sub).items():
            lines += [
                f"### {code(f'cosim {name} {inner_name}')}",
                "",
                *fenced(inner.format_help().rstrip()),
                "",
            ]
    return "\n".join(lines) + "\n"
