"""The command-line reference: every command's help, from the parser itself."""

from __future__ import annotations

import argparse

from cosim.cli.args import build_parser


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
        "`cosim COMMAND ...`; every command answers `--help`. Exit status: 0 done; 2 "
        "invalid input (one line on standard error naming the file, the key, the value and "
        "what was expected, no traceback); 1 an internal failure (a bug). This page is "
        "generated from the command line's own parser (`cosim/reference/commands_page.py`).",
        "",
        "```text",
        parser.format_help().rstrip(),
        "```",
        "",
    ]
    for name, sub in _subparsers(parser).items():
        lines += [f"## `cosim {name}`", "", "```text", sub.format_help().rstrip(), "```", ""]
        for inner_name, inner in _subparsers(sub).items():
            lines += [
                f"### `cosim {name} {inner_name}`",
                "",
                "```text",
                inner.format_help().rstrip(),
                "```",
                "",
            ]
    return "\n".join(lines) + "\n"
