"""The ``cosim`` command line's arguments: every subcommand, its flags and their checks.

A flag's value is checked as it is parsed; a bad one is one line and exit status 2
(``cosim run --live-port 70000``: "70000 is not a TCP port").
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import NoReturn

from adapters.physical.standin_options import add_arguments as add_standin_arguments
from cosim.cli.checkplugin import add_arguments as add_check_plugin_arguments
from cosim.cli.exits import EXIT_INPUT
from cosim.cli.hostname import host_argument
from cosim.cli.values import (
    cell_size_m,
    duration_s,
    folder,
    non_negative_float,
    non_negative_int,
    port,
    positive_float,
    positive_int,
    registry_kind,
    score,
    threads,
    times,
)
from cosim.scenario.fields import key_bounds
from cosim.scenario.sections import ScenarioSection


class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line and exit 2."""

    def error(self, message: str) -> NoReturn:
        """Print one line naming the problem and exit 2."""
        self.exit(
            EXIT_INPUT, f"{self.prog}: error: {one_line(message)} (see `{self.prog} --help`)\n"
        )


def one_line(text: str) -> str:
    """``text`` with its line breaks and other control characters escaped as ``repr`` does."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


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
    parser = Parser(
        prog="cosim",
        description=(
            "Deterministic discrete-event co-simulation of autonomous mobile robot fleets: "
            "kinematics, lidar and the network between robots, recorded as tables."
        ),
        epilog="Exit status: 0 done, 2 invalid input, 1 internal error.",
    )
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
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
    run.add_argument(
        "--standin",
        action="store_true",
        help="start a stand-in robot process (cosim standin) for every physical robot of "
        "the scenario, so mixed-reality scenarios run without hardware",
    )
    run.add_argument(
        "--out",
        type=folder,
        help="results folder (default: runs/NAME-seedN, or runs/NAME-seedN-2, -3, ... when "
        "that one holds a run)",
    )
    run.add_argument("--seed", type=non_negative_int, help="override scenario.seed")
    run.add_argument(
        "--duration-s",
        type=duration_s,
        help="override scenario.duration_s (s; "
        f"{key_bounds(ScenarioSection, 'duration_s').describe()}, as the key)",
    )
    run.add_argument(
        "--force",
        action="store_true",
        help="replace the results of an earlier run in a non-empty --out (default: "
        "runs/NAME-seedN); other files stay, and figures/ too unless --figures/--gif redraw it",
    )
    run.add_argument("--quiet", action="store_true", help="print nothing but errors")
    run.add_argument(
        "--threads",
        type=threads,
        help="worker threads for each instant's per-robot work: lidar casts, scan matching "
        "and map updates, path planning (default: the cores available; 1: one thread). "
        "The tables and the bag are the same for any number",
    )
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
        "--live-port", type=port, default=8765, help="TCP port of the live view (default 8765)"
    )
    live.add_argument(
        "--live-host",
        type=host_argument,
        default="127.0.0.1",
        help="address to bind (default 127.0.0.1: this machine only; 0.0.0.0: every interface)",
    )
    live.add_argument(
        "--live-rate",
        type=positive_float,
        default=1.0,
        help="simulated seconds per wall-clock second (default 1.0: real time)",
    )
    live.add_argument(
        "--live-wait",
        action="store_true",
        help="start the run only once a viewer has subscribed to a topic",
    )
    unity = run.add_argument_group(
        "Unity",
        "Serve the run as a ROS-TCP-Endpoint (ROS-TCP-Connector 0.7, ROS 2 mode), paced "
        "against the wall clock: in Unity, Robotics > ROS Settings > ROS IP Address and Port.",
    )
    unity.add_argument(
        "--unity", action="store_true", help="serve the run to Unity scenes (ROS-TCP-Connector)"
    )
    unity.add_argument(
        "--unity-port",
        type=port,
        default=10000,
        help="TCP port Unity connects to (default 10000, the Connector's)",
    )
    unity.add_argument(
        "--unity-host",
        type=host_argument,
        default="127.0.0.1",
        help="address to bind (default 127.0.0.1: this machine only; 0.0.0.0: every interface)",
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
    check.add_argument(
        "--print",
        action="store_true",
        help=(
            "print the fully resolved scenario (without [provenance]: nothing ran) alone on "
            "stdout, the ok line and notes on stderr: `> mine.toml` writes a scenario file"
        ),
    )

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
    world.add_argument("--seed", type=non_negative_int, help="override scenario.seed")
    world.add_argument("--png", type=Path, metavar="F.png", help="write a picture of the world")
    world.add_argument("--map", type=Path, metavar="F.yaml", help="write a map_server map")
    world.add_argument("--sdf", type=Path, metavar="F.sdf", help="write a Gazebo SDF world")
    world.add_argument(
        "--resolution-m", type=positive_float, default=0.05, help="map resolution (m/cell)"
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
    study.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="SECTION.KEY=VALUE",
        help="set one scenario key in every run, over [overrides], e.g. --set robots.count=8 "
        "(repeatable; values are TOML; not a key the study varies)",
    )
    study.add_argument("--out", type=Path, help="study folder (default: runs/studies/NAME)")
    study.add_argument("--workers", type=positive_int, help="local processes (default: cores)")
    study.add_argument(
        "--scheduler",
        metavar="tcp://HOST:PORT",
        help="run on this Dask scheduler instead of local processes",
    )
    study.add_argument(
        "--scheduler-timeout-s",
        type=positive_float,
        default=20.0,
        metavar="S",
        help="how long to wait for the Dask scheduler to answer (default: 20 s)",
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
        description="Commands on ROS 2 bags: a rosbag2 folder, a bare .mcap or .db3 file, or "
        "a run folder (its bag/).",
    )
    bag_commands = bag.add_subparsers(dest="bag_command", metavar="COMMAND", parser_class=Parser)
    bag_commands.required = True
    info = bag_commands.add_parser(
        "info",
        help="print a bag's topics, types, message counts and duration",
        description="Print a bag's storage, size, message count, time span, and per topic its "
        "type and message count.",
    )
    info.add_argument(
        "bag", metavar="BAG", type=Path, help="a bag folder, a .mcap/.db3 file, or a run folder"
    )

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
    mapping.add_argument(
        "bag", metavar="BAG", type=Path, help="a bag folder, a .mcap/.db3 file, or a run folder"
    )
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
        "--resolution-m",
        type=cell_size_m,
        default=0.05,
        help="map cell size, 0.01 to 1 m (0.05 m)",
    )
    mapping.add_argument(
        "--min-travel-m",
        type=non_negative_float,
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
        type=score,
        default=0.0,
        help="score (0..1) by which a matched pose must beat the odometry's prediction "
        "(default 0: corrections of noisy real odometry matter; runs use 0.02)",
    )
    mapping.add_argument(
        "--refine",
        choices=("score", "walls"),
        default="score",
        help="what the matcher's sub-cell step fits: the match score (default, robust on "
        "real recordings) or the walls fitted to where returns fell (runs' default: exact on "
        "simulated walls, worse on rough real ones)",
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
            "earlier run can be plotted (keys renamed since are read under their new names, "
            "sections of plugins not installed are carried: a note on stderr says each): the "
            "world with trajectories, snapshots with trails, "
            "a task timeline, the network over time, assignment convergence. PNGs go to "
            "RUN_DIR/figures/."
        ),
    )
    plot.add_argument("run_dir", metavar="RUN_DIR", type=Path, help="a run's folder")
    plot.add_argument(
        "--at",
        type=times,
        metavar="T1,T2,...",
        help="snapshot times (s), comma-separated (default: evenly spaced over the run)",
    )
    plot.add_argument("--gif", action="store_true", help="also write an animation run.gif")
    plot.add_argument("--out", type=Path, help="folder for the figures (default RUN_DIR/figures)")

    standin = commands.add_parser(
        "standin",
        help="run a stand-in physical robot speaking ROS 2 over DDS",
        description=(
            "Play a physical robot without hardware: a separate process on the DDS domain "
            "that integrates /NAME/cmd_vel (geometry_msgs/Twist) within the robot's limits and "
            "publishes its pose on /NAME/pose (geometry_msgs/PoseStamped, as a motion-capture "
            "bridge would, with latency and noise) and its odometry on /NAME/odom. Runs "
            "until Ctrl-C or --duration-s; DDS stays on loopback unless --interface is given."
        ),
    )
    add_standin_arguments(standin)

    commands.add_parser(
        "scenarios",
        help="list the presets, one line each",
        description="List the scenario presets shipped with cosim.",
    )
    listing = commands.add_parser(
        "plugins",
        help="list every registry (adapters, sections, drivers, protocols, controllers, "
        "planners, traffic policies, mocap sources, network models, map sharing, ...) and what "
        "is registered in it",
        description=(
            "List what installed packages register, cosim's own built-ins beside any plugin's: "
            "each entry with the package and version it comes from and a one-line description. "
            "A plugin that cannot be loaded is listed with the reason (it stops no run that "
            "does not use it). A name two packages register in one registry is listed once, "
            "marked CLASH, with both packages: it stops every run that uses that registry, so "
            "the command then exits 2."
        ),
    )
    listing.add_argument(
        "kinds",
        nargs="*",
        metavar="KIND",
        type=registry_kind,
        help="only these registries, by entry-point group (cosim.planners), short name "
        "(planners) or singular (planner); default: all",
    )
    checking = commands.add_parser(
        "check-plugin", help="run cosim's checks of its built-ins on a plugin, one line each"
    )
    add_check_plugin_arguments(checking, duration_s=duration_s)
    return parser
