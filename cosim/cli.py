"""The ``cosim`` command line.

Exit status: 0 done; 2 invalid input (one line on stderr naming the file, the key, the
value and what was expected); 1 internal failure (a bug: the traceback is printed).
"""

from __future__ import annotations

import argparse
import sys
import traceback
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NoReturn

from cosim.errors import ConfigError, CosimError
from cosim.progress import ProgressLine
from cosim.scenario import (
    Scenario,
    load_scenario,
    parse_override,
    preset_names,
    preset_summary,
)

HIGHLIGHTS = (
    ("arrivals", "goals reached"),
    ("deadlocks", "stuck reports"),
    ("collisions", "collisions"),
    ("min_clearance_m", "m smallest clearance"),
    ("messages_dropped", "messages dropped"),
    ("latency_ms_p50", "ms median latency"),
)
"""Summary metrics shown after a run, when the run has them."""

EXIT_OK = 0
EXIT_BUG = 1
EXIT_INPUT = 2


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_INPUT, f"{self.prog}: error: {message} (see `{self.prog} --help`)\n")


def _non_negative_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"{value} is negative; expected an integer >= 0")
    return value


def _positive_int(text: str) -> int:
    value = _non_negative_int(text)
    if value == 0:
        raise argparse.ArgumentTypeError("0 is not an integer >= 1")
    return value


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"{text} is not a finite number > 0")
    return value


def _scenario_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "scenario",
        metavar="SCENARIO",
        help="a scenario TOML file, or a preset name (list them with `cosim scenarios`)",
    )
    parser.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="SECTION.KEY=VALUE",
        help="override one scenario key, e.g. --set lidar.rate_hz=20 (repeatable; values are TOML)",
    )


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every subcommand."""
    parser = _Parser(
        prog="cosim",
        description=(
            "Deterministic discrete-event co-simulation of autonomous mobile robot fleets: "
            "kinematics, lidar and the network between robots, recorded as tables."
        ),
        epilog="Exit status: 0 done, 2 invalid input, 1 internal error.",
    )
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    commands.required = True

    run = commands.add_parser(
        "run",
        help="run a scenario and write its results folder",
        description=(
            "Run a scenario to its duration and write summary.json, scenario.toml (the fully "
            "resolved scenario) and tables/*.parquet into the output folder."
        ),
    )
    _scenario_argument(run)
    run.add_argument("--out", type=Path, help="results folder (default: runs/NAME-seedN)")
    run.add_argument("--seed", type=_non_negative_int, help="override scenario.seed")
    run.add_argument("--duration-s", type=_positive_float, help="override scenario.duration_s (s)")
    run.add_argument("--force", action="store_true", help="replace results in a non-empty --out")
    run.add_argument("--quiet", action="store_true", help="print nothing but errors")

    check = commands.add_parser(
        "check",
        help="validate a scenario without running it",
        description=(
            "Load and validate a scenario, build its world and adapters without running "
            "them, and print a one-line description."
        ),
    )
    _scenario_argument(check)
    check.add_argument("--print", action="store_true", help="print the fully resolved scenario")

    world = commands.add_parser(
        "world",
        help="write a scenario's world as a picture, a ROS map and a Gazebo world",
        description=(
            "Build the scenario's world (the same one `cosim run` builds for that seed) and "
            "write it as a PNG picture, a ROS map_server map (PGM + YAML, loadable by "
            "nav2_map_server) and/or a Gazebo SDF world. Without an output flag, print a "
            "description of the world."
        ),
    )
    _scenario_argument(world)
    world.add_argument("--seed", type=_non_negative_int, help="override scenario.seed")
    world.add_argument("--png", type=Path, metavar="F.png", help="write a picture of the world")
    world.add_argument("--map", type=Path, metavar="F.yaml", help="write a map_server map")
    world.add_argument("--sdf", type=Path, metavar="F.sdf", help="write a Gazebo SDF world")
    world.add_argument(
        "--resolution-m", type=_positive_float, default=0.05, help="map resolution (m/cell)"
    )

    study = commands.add_parser(
        "study",
        help="run a study: a scenario swept over overrides and seeds",
        description=(
            "Run every combination of a study file's [grid] (and [[cases]]) for every seed, on "
            "local processes or a Dask cluster, and write DIR/results.parquet (one row per run), "
            "DIR/runs/<run_id>/, and figures and report.md when the study has a [report]."
        ),
    )
    study.add_argument("study", metavar="STUDY.toml", type=Path, help="the study file")
    study.add_argument("--out", type=Path, help="study folder (default: runs/studies/NAME)")
    study.add_argument("--workers", type=_positive_int, help="local processes (default: cores)")
    study.add_argument(
        "--scheduler",
        metavar="tcp://HOST:PORT",
        help="run on this Dask scheduler instead of local processes",
    )
    study.add_argument(
        "--resume",
        action="store_true",
        help="continue a study in --out: skip finished runs, retry failed ones",
    )
    study.add_argument(
        "--quiet", action="store_true", help="no progress bar (the summary lines remain)"
    )

    commands.add_parser(
        "scenarios",
        help="list the presets, one line each",
        description="List the scenario presets shipped with cosim.",
    )
    return parser


def _load(args: argparse.Namespace) -> Scenario:
    overrides: dict[str, Any] = {}
    for text in args.overrides:
        key, value = parse_override(text)
        overrides[key] = value
    return load_scenario(args.scenario, overrides)


def _describe(scenario: Scenario) -> str:
    world = scenario.world
    return (
        f"{scenario.name} ({scenario.source}): {scenario.robots.count} robots, "
        f"{world.size_m[0]:g} m x {world.size_m[1]:g} m, layout {world.layout}, "
        f"{scenario.scenario.duration_s:g} s, seed {scenario.seed}"
    )


def _cmd_run(args: argparse.Namespace) -> int:
    from cosim.runner import run

    scenario = _load(args)
    if args.seed is not None:
        scenario = scenario.with_seed(args.seed)
    out = args.out or Path("runs") / f"{scenario.name}-seed{scenario.seed}"
    progress = None if args.quiet else ProgressLine(label=f"{scenario.name}: ")
    try:
        result = run(
            scenario, duration_s=args.duration_s, out=out, force=args.force, progress=progress
        )
    finally:
        if progress is not None:
            progress.close()
    if not args.quiet:
        s = result.summary
        print(
            f"{s['scenario']} seed {s['seed']}: {s['sim_time_s']:g} s simulated in "
            f"{s['wall_time_s']:.2f} s ({s['real_time_factor']:g}x real time), "
            f"{s['robots']} robots, {s['events']} events, {s['messages_sent']} messages"
        )
        highlights = [f"{s[key]} {label}" for key, label in HIGHLIGHTS if s.get(key) is not None]
        if highlights:
            print("  " + ", ".join(highlights))
        tables = ", ".join(sorted(result.tables))
        print(f"results: {out}/  (summary.json, scenario.toml, tables/: {tables})")
    return EXIT_OK


def _cmd_check(args: argparse.Namespace) -> int:
    from cosim.assembly import assemble
    from cosim.scenario import dump_scenario

    scenario = _load(args)
    assemble(scenario)  # builds the world and every adapter: impossible requests fail here
    print(f"ok: {_describe(scenario)}")
    if args.print:
        print(dump_scenario(scenario), end="")
    return EXIT_OK


def _cmd_world(args: argparse.Namespace) -> int:
    from cosim.worldfiles import scenario_warehouse, world_command

    scenario = _load(args)
    if args.seed is not None:
        scenario = scenario.with_seed(args.seed)
    if not (args.png or args.map or args.sdf):
        world = scenario_warehouse(scenario)
        print(
            f"{_describe(scenario)}: {len(world.shelves)} shelves, "
            f"{len(world.obstacles)} extra obstacles, dock depth {world.dock_depth_m:.2f} m "
            "(write files with --png, --map, --sdf)"
        )
        return EXIT_OK
    for path in world_command(
        scenario, png=args.png, map_yaml=args.map, sdf=args.sdf, resolution_m=args.resolution_m
    ):
        print(f"wrote {path}")
    return EXIT_OK


def _cmd_study(args: argparse.Namespace) -> int:
    from cosim.studies.runner import Progress, run_study
    from cosim.studies.spec import load_study

    spec = load_study(args.study)
    out = args.out or Path("runs") / "studies" / spec.name
    total = len(spec.runs())
    where = f"Dask at {args.scheduler}" if args.scheduler else f"{args.workers or 'all'} workers"
    print(
        f"{spec.name}: {total} runs ({len(spec.combinations())} combinations x "
        f"{len(spec.seeds)} seeds) on {where} -> {out}/"
    )
    results = run_study(
        spec,
        out,
        workers=args.workers,
        scheduler=args.scheduler,
        resume=args.resume,
        progress=None if args.quiet else Progress(),
    )
    failed = int((results["status"] != "ok").sum()) if len(results) else 0
    print(
        f"results: {out}/results.parquet ({len(results)} runs, {failed} failed)"
        + (f", report: {out}/report.md" if (out / "report.md").exists() else "")
    )
    return EXIT_OK


def _cmd_scenarios(_args: argparse.Namespace) -> int:
    names = preset_names()
    width = max(len(n) for n in names)
    for name in names:
        print(f"{name:<{width}}  {preset_summary(name)}")
    return EXIT_OK


COMMANDS = {
    "run": _cmd_run,
    "check": _cmd_check,
    "world": _cmd_world,
    "study": _cmd_study,
    "scenarios": _cmd_scenarios,
}


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return COMMANDS[args.command](args)
    except (CosimError, ConfigError) as error:
        print(f"cosim: error: {error}", file=sys.stderr)
        return EXIT_INPUT
    except KeyboardInterrupt:
        print("cosim: interrupted", file=sys.stderr)
        return 130
    except Exception:
        traceback.print_exc()
        print(
            "cosim: internal error (a bug; please report it with the traceback above)",
            file=sys.stderr,
        )
        return EXIT_BUG
