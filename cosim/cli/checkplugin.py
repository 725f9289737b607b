"""``cosim check-plugin NAME``: the checks cosim runs on its built-ins, run on one plugin.

One line per check (``ok``, ``warn``, ``FAIL`` or ``skip``, its name, what was found or
why), then a last line counting them. Exit status: 0 every check passed (a warning
breaks nothing: a summary key declared nowhere) or did not apply; 3 a check
failed (the plugin's code broke its contract or its group's rules, as ``cosim run`` says
of a plugin whose code failed; a ``--set`` value its scenario refuses fails the
``scenario`` check); 2 an unknown or ambiguous NAME, or a ``--set`` of no registered key.

The checks themselves are :mod:`cosim.testing.checks`; nothing of them is imported until
the command runs, so that ``cosim --help`` stays fast.
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any

from cosim.cli.exits import EXIT_OK as EXIT_ALL_PASSED
from cosim.cli.exits import EXIT_PLUGIN as EXIT_CHECK_FAILED

DESCRIPTION = (
    "Run on one registered entry (a plugin's, or a built-in) the checks cosim runs on its "
    "own: it loads; its registry's contract check passes and it declares its name; its "
    "settings section (the cosim.sections entry of the same name) builds from its "
    "defaults and documents every key with the unit in its name; and a short real run in "
    "a small warehouse-random set up for its kind (a protocol with tasks on a network that "
    "loses nothing, a controller with navigation, an adapter added to the scenario, ...) "
    "finishes, leaves a flat summary whose every key is declared with its unit (a "
    "warning otherwise), repeats exactly with the same seed and keeps its "
    "kind's rules (a protocol claims every task within 5 s without conflicts, a "
    "controller's robots stay finite and move, a network backend delivers everything)."
)
EPILOG = (
    "Exit status: 0 every check passed (or did not apply: skip), 3 a check failed, "
    "2 an unknown or ambiguous NAME or a --set of no registered key."
)


def add_arguments(parser: argparse.ArgumentParser, *, duration_s: Callable[[str], float]) -> None:
    """The command's description and arguments.

    Args:
        parser: the ``check-plugin`` subparser.
        duration_s: the type of ``--duration-s`` (the bounds of ``scenario.duration_s``).
    """
    parser.description = DESCRIPTION
    parser.epilog = EPILOG
    parser.add_argument(
        "name",
        metavar="NAME",
        help="a registered name (`cosim plugins` lists them), or GROUP:NAME when several "
        "registries hold it (drivers:navigation, cosim.sections:navigation)",
    )
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="SECTION.KEY=VALUE",
        help="a scenario key for its run, e.g. --set mocap.file=runs/a/bag for a source "
        "that replays a file (repeatable; values are TOML)",
    )
    parser.add_argument(
        "--duration-s",
        type=duration_s,
        help="simulated seconds of its run (default: its kind's, 5 to 20 s)",
    )


def check_plugin_command(args: argparse.Namespace) -> int:
    """Run every check on ``args.name``, print a line each; the exit status."""
    from cosim.scenario import parse_override
    from cosim.testing.checks import check_plugin, find_entry, known_keys, plugin_words

    overrides: dict[str, Any] = dict(parse_override(text) for text in args.overrides)
    known_keys(overrides)
    target = find_entry(args.name)
    print(f"checking {plugin_words(target)}", flush=True)
    outcomes = []
    for outcome in check_plugin(target, overrides=overrides, duration_s=args.duration_s):
        print(outcome.line(), flush=True)
        outcomes.append(outcome)
    failed = [o.check for o in outcomes if o.failed]
    skipped = sum(o.verdict.value == "skip" for o in outcomes)
    warned = sum(o.verdict.value == "warn" for o in outcomes)
    if failed:
        print(f"{target.name}: {len(failed)} of {len(outcomes)} checks failed: {', '.join(failed)}")
        return EXIT_CHECK_FAILED
    passed = len(outcomes) - skipped
    print(
        f"{target.name}: {passed} checks passed"
        + (f" ({warned} with a warning)" if warned else "")
        + (f", {skipped} skipped" if skipped else "")
    )
    return EXIT_ALL_PASSED
