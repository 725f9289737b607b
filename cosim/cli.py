"""The ``cosim`` command line.

Exit status: 0 done; 2 invalid input (one line on stderr naming the file, the key, the
value and what was expected); 1 internal failure (a bug: the traceback is printed).
"""

from __future__ import annotations

import argparse
import os
import sys
import traceback
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

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

if TYPE_CHECKING:
    from cosim.recording.session import RecordingSession
    from cosim.runner import RunResult

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


def _non_negative_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not value >= 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"{text} is not a finite number >= 0")
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


def _port(text: str) -> int:
    value = _non_negative_int(text)
    if value > 65535:
        raise argparse.ArgumentTypeError(f"{value} is not a TCP port (expected 0 to 65535)")
    return value


def _times(text: str) -> list[float]:
    values = []
    for part in text.split(","):
        try:
            value = float(part)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{part.strip()!r} in {text!r} is not a number; expected times in s, "
                "comma-separated (e.g. 10,20,30)"
            ) from None
        if not value >= 0 or value == float("inf"):
            raise argparse.ArgumentTypeError(f"{part.strip()} is not a finite time >= 0 (s)")
        values.append(value)
    return values


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
            "resolved scenario), tables/*.parquet and a ROS 2 bag (bag/, written while the "
            "run goes) into the output folder."
        ),
    )
    _scenario_argument(run)
    run.add_argument("--out", type=Path, help="results folder (default: runs/NAME-seedN)")
    run.add_argument("--seed", type=_non_negative_int, help="override scenario.seed")
    run.add_argument("--duration-s", type=_positive_float, help="override scenario.duration_s (s)")
    run.add_argument("--force", action="store_true", help="replace results in a non-empty --out")
    run.add_argument("--quiet", action="store_true", help="print nothing but errors")
    run.add_argument(
        "--bag",
        choices=("mcap", "sqlite3", "none"),
        help="ROS 2 bag in OUT/bag: mcap (default; Foxglove, ros2 bag), sqlite3 (.db3) or "
        "none (same as --set record.bag=...; topics from record.topics)",
    )
    run.add_argument(
        "--figures", action="store_true", help="draw the run's figures into OUT/figures at the end"
    )
    run.add_argument(
        "--gif", action="store_true", help="also write an animation OUT/figures/run.gif"
    )
    live = run.add_argument_group(
        "live view",
        "Serve the run over the Foxglove WebSocket protocol while it goes, paced against the "
        "wall clock: in Foxglove, Open connection > Foxglove WebSocket > ws://HOST:PORT.",
    )
    live.add_argument("--live", action="store_true", help="serve the run live to Foxglove")
    live.add_argument(
        "--live-port", type=_port, default=8765, help="TCP port of the live view (default 8765)"
    )
    live.add_argument(
        "--live-host",
        default="127.0.0.1",
        help="address to bind (default 127.0.0.1: this machine only; 0.0.0.0: every interface)",
    )
    live.add_argument(
        "--live-rate",
        type=_positive_float,
        default=1.0,
        help="simulated seconds per wall-clock second (default 1.0: real time)",
    )
    live.add_argument(
        "--live-wait",
        action="store_true",
        help="start the run only once a viewer has subscribed to a topic",
    )

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

    bag = commands.add_parser(
        "bag",
        help="look into ROS 2 bags (ours, or any rosbag2 recording)",
        description="Commands on ROS 2 bags: a rosbag2 folder, or a bare .mcap or .db3 file.",
    )
    bag_commands = bag.add_subparsers(dest="bag_command", metavar="COMMAND", parser_class=_Parser)
    bag_commands.required = True
    info = bag_commands.add_parser(
        "info",
        help="print a bag's topics, types, message counts and duration",
        description="Print a bag's storage, size, message count, time span, and per topic its "
        "type and message count.",
    )
    info.add_argument("bag", metavar="BAG", type=Path, help="a bag folder, or a .mcap/.db3 file")

    mapping = commands.add_parser(
        "map",
        help="map a recorded ROS 2 bag (LaserScan + Odometry) with cosim's mapping",
        description=(
            "Run the robots' mapping (scan-to-map matching correcting odometry) on a ROS 2 "
            "bag (MCAP or sqlite3, a rosbag2 folder or a bare file) and write map.pgm + "
            "map.yaml, map.png, trajectory.parquet/.csv (t_s, x_m, y_m, yaw_rad) and "
            "summary.json; with --reference, the trajectory error of odometry and of the "
            "estimate (RMS after rigid SE(2) alignment)."
        ),
    )
    mapping.add_argument("bag", metavar="BAG", type=Path, help="a bag folder or .mcap/.db3 file")
    mapping.add_argument("--out", type=Path, required=True, help="output folder")
    mapping.add_argument("--scan", default="/scan", help="sensor_msgs/LaserScan topic (/scan)")
    mapping.add_argument("--odom", default="/odom", help="nav_msgs/Odometry topic (/odom)")
    mapping.add_argument(
        "--reference",
        metavar="TOPIC",
        help="ground-truth poses (Odometry, PoseStamped or PoseWithCovarianceStamped) to "
        "measure the trajectory error against",
    )
    mapping.add_argument(
        "--resolution-m", type=_positive_float, default=0.05, help="map cell size (0.05 m)"
    )
    mapping.add_argument(
        "--min-travel-m",
        type=_non_negative_float,
        default=0.5,
        help="distance driven before a scan updates the map (slam_toolbox: 0.5 m)",
    )
    mapping.add_argument(
        "--scan-matching",
        choices=("correlative", "none"),
        default="correlative",
        help="correct odometry by scan matching, or none (odometry only, for comparison)",
    )
    mapping.add_argument(
        "--match-margin",
        type=_non_negative_float,
        default=0.0,
        help="score (0..1) by which a matched pose must beat the odometry's prediction "
        "(default 0: corrections of noisy real odometry matter; runs use 0.02)",
    )
    mapping.add_argument(
        "--no-loop-closure",
        action="store_true",
        help="do not close loops (scan-to-map matching only, as the robots in a run do)",
    )
    mapping.add_argument("--force", action="store_true", help="replace results in --out")
    mapping.add_argument("--quiet", action="store_true", help="no progress line")

    plot = commands.add_parser(
        "plot",
        help="draw a run's figures from its folder",
        description=(
            "Draw figures of a run from its folder alone (scenario.toml and tables/), so any "
            "earlier run can be plotted: the world with trajectories, snapshots with trails, "
            "a task timeline, the network over time, assignment convergence. PNGs go to "
            "RUN_DIR/figures/."
        ),
    )
    plot.add_argument("run_dir", metavar="RUN_DIR", type=Path, help="a run's folder")
    plot.add_argument(
        "--at",
        type=_times,
        metavar="T1,T2,...",
        help="snapshot times (s), comma-separated (default: evenly spaced over the run)",
    )
    plot.add_argument("--gif", action="store_true", help="also write an animation run.gif")
    plot.add_argument("--out", type=Path, help="folder for the figures (default RUN_DIR/figures)")

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
    from cosim.recording.live import LiveOptions
    from cosim.runner import run

    if args.bag is not None:
        args.overrides.append(f"record.bag={args.bag}")
    scenario = _load(args)
    if args.seed is not None:
        scenario = scenario.with_seed(args.seed)
    out = args.out or Path("runs") / f"{scenario.name}-seed{scenario.seed}"
    live = (
        LiveOptions(args.live_host, args.live_port, args.live_rate, args.live_wait)
        if args.live
        else None
    )
    progress = None if args.quiet else ProgressLine(label=f"{scenario.name}: ")
    try:
        result = run(
            scenario,
            duration_s=args.duration_s,
            out=out,
            force=args.force,
            progress=progress,
            live=live,
            on_ready=lambda session: _ready(session, quiet=args.quiet),
        )
    finally:
        if progress is not None:
            progress.close()
    figures = []
    if args.figures or args.gif:
        from cosim.plotting.command import plot_run

        figures = plot_run(out, gif=args.gif)
    if not args.quiet:
        _print_run(result, out, figures)
    return EXIT_OK


def _ready(session: RecordingSession, *, quiet: bool) -> None:
    """Say where the live view is; hold the run for a viewer when asked to."""
    live = session.live
    if live is None:
        return
    if not quiet:
        print(
            f"live view: {live.url}  (Foxglove: Open connection > Foxglove WebSocket; "
            f"{live.options.rate:g}x real time)",
            flush=True,
        )
    if live.options.wait:
        if not quiet:
            print("waiting for a viewer to subscribe (Ctrl-C to stop) ...", flush=True)
        while not live.subscribed.wait(timeout=0.5):
            pass


def _print_run(result: RunResult, out: Path, figures: list[Path]) -> None:
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
    if result.bag is not None:
        recorded = sum(result.recorded.values())
        size_mb = sum(p.stat().st_size for p in result.bag.iterdir() if p.is_file()) / 1e6
        print(
            f"bag: {result.bag}/  ({recorded} messages on {len(result.recorded)} topics, "
            f"{size_mb:.1f} MB; `cosim bag info {result.bag}`, or open it in Foxglove)"
        )
    if figures:
        print(f"figures: {', '.join(str(f) for f in figures)}")


def _cmd_check(args: argparse.Namespace) -> int:
    from cosim.assembly import assemble
    from cosim.recording.session import RecordingSession
    from cosim.scenario import dump_scenario

    scenario = _load(args)
    # builds the world and every adapter: impossible requests fail here, as do topic
    # patterns that match nothing the run would record
    recording = scenario.record.bag != "none"
    assembly = assemble(scenario, recording=recording)
    if recording:
        RecordingSession.topics_of(scenario, assembly.run.bus)
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


def _cmd_bag(args: argparse.Namespace) -> int:
    from cosim.recording.reading import bag_info, format_info

    print(format_info(bag_info(args.bag)))
    return EXIT_OK


def _cmd_map(args: argparse.Namespace) -> int:
    from cosim.bagmap import map_bag
    from models.mapping.matcher import MatcherParams
    from models.mapping.slam import UpdateGate

    progress = None if args.quiet else ProgressLine(label=f"{args.bag.name}: ")
    try:
        result = map_bag(
            args.bag,
            args.out,
            scan_topic=args.scan,
            odom_topic=args.odom,
            reference_topic=args.reference,
            resolution_m=args.resolution_m,
            gate=UpdateGate(min_travel_m=args.min_travel_m),
            matcher=MatcherParams(margin=args.match_margin),
            scan_matching=args.scan_matching != "none",
            loop_closure=not args.no_loop_closure,
            force=args.force,
            progress=progress,
        )
    finally:
        if progress is not None:
            progress.close()
    s = result.summary
    line = (
        f"{s['scans']} scans, {s['map_updates']} map updates ({s['matched']} matched, "
        f"{s['loop_closures']} loop closures), "
        f"{s['recording_s']:g} s of recording in {s['wall_time_s']:g} s "
        f"({s['real_time_factor']:g}x real time)"
    )
    if "ate_m" in s:
        line += f"; trajectory error {s['ate_m']:.3f} m (odometry {s['ate_odom_m']:.3f} m)"
    print(line)
    print(f"results: {result.out}/  ({', '.join(p.name for p in result.files)})")
    return EXIT_OK


def _cmd_plot(args: argparse.Namespace) -> int:
    from cosim.plotting.command import plot_run

    for path in plot_run(args.run_dir, at=args.at, gif=args.gif, out=args.out):
        print(f"wrote {path}")
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
    "bag": _cmd_bag,
    "map": _cmd_map,
    "plot": _cmd_plot,
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
    except BrokenPipeError:
        # the reader left (`cosim bag info BAG | head`): stop quietly as Unix tools do, and
        # keep the interpreter from failing to flush stdout on exit
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    except Exception:
        traceback.print_exc()
        print(
            "cosim: internal error (a bug; please report it with the traceback above)",
            file=sys.stderr,
        )
        return EXIT_BUG
