"""The ``cosim`` command line.

Each command is a function of the parsed arguments returning the exit status;
:mod:`cosim.cli.exits` says what each status means and prints the errors.
"""

from __future__ import annotations

import argparse
import functools
import os
import sys
import traceback
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from cosim.cli.args import build_parser
from cosim.cli.checkplugin import check_plugin_command
from cosim.cli.exits import (
    EXIT_BUG,
    EXIT_OK,
    EXIT_RUNS_FAILED,
    failed_runs_line,
    say_error,
)
from cosim.cli.progress import ProgressLine
from cosim.cli.runreport import print_run
from cosim.core.errors import ConfigError, CosimError
from cosim.scenario import (
    Scenario,
    load_scenario,
    parse_override,
    preset_names,
    preset_summary,
)
from cosim.scenario.provenance import provenance_note

if TYPE_CHECKING:
    from cosim.recording.setup import RecordingSession
    from cosim.runner.stopping import RunStopped, StopRequest


def _load(args: argparse.Namespace) -> Scenario:
    """The scenario of ``args``; a note on stderr when its ``[provenance]`` is not installed."""
    overrides: dict[str, Any] = {}
    for text in args.overrides:
        key, value = parse_override(text)
        overrides[key] = value
    scenario = load_scenario(args.scenario, overrides)
    note = provenance_note(scenario.source, scenario.resolved_with)
    for line in (*scenario.notes, *([note] if note is not None else [])):
        print(line, file=sys.stderr)
    return scenario


def _describe(scenario: Scenario) -> str:
    world = scenario.world
    return (
        f"{scenario.name} ({scenario.source}): {scenario.robots.count} robots, "
        f"{world.size_m[0]:g} m x {world.size_m[1]:g} m, layout {world.layout}, "
        f"{scenario.scenario.duration_s:g} s, seed {scenario.seed}"
    )


def _cmd_run(args: argparse.Namespace) -> int:
    """``cosim run``; SIGINT, SIGTERM and SIGHUP stop it keeping what ran (128 + signal)."""
    from cosim.runner.stopping import RunStopped, stop_on_signals

    ran: list[Path] = []  # the results folder, once the run has written it
    try:
        with stop_on_signals() as stop:
            return _run_and_report(args, stop, ran)
    except RunStopped as stopped:
        print(f"cosim: {_stopped_line(stopped, ran)}", file=sys.stderr)
        return stopped.exit_status


def _run_and_report(args: argparse.Namespace, stop: StopRequest, ran: list[Path]) -> int:
    from adapters.physical.domain import claim_run_domain
    from adapters.physical.launcher import Standins
    from adapters.unity.server import UnityOptions
    from cosim.cli.hostname import check_live_host, check_ports, run_listeners
    from cosim.recording.foxglove import LiveOptions
    from cosim.runner.execute import run
    from cosim.runner.stopping import RunStopped

    if args.bag is not None:
        args.overrides.append(f"record.bag={args.bag}")
    scenario = _load(args)
    if args.seed is not None:
        scenario = scenario.with_seed(args.seed)
    if args.live:
        check_live_host(args.live_host)
    if args.unity:
        check_live_host(args.unity_host, flag="--unity-host")
    check_ports(*run_listeners(args))  # one port for two: "in use" would blame another program
    out = _out_folder(args, scenario, quiet=args.quiet)
    live = (
        LiveOptions(args.live_host, args.live_port, args.live_rate, args.live_wait)
        if args.live
        else None
    )
    # a run with robots on DDS takes a domain no other run on this machine hears
    domain = claim_run_domain(scenario)
    if domain is not None:
        scenario = domain.scenario
        if not args.quiet:
            print(domain.claim.describe(), flush=True)
    progress = None if args.quiet else ProgressLine(label=f"{scenario.name}: ")
    standins = None
    try:
        standins = Standins(scenario) if args.standin else None
        if standins is not None:
            started = standins.start()
            if not args.quiet:
                print(f"stand-in robots: {', '.join(started)}", flush=True)
        try:
            result = run(
                scenario,
                duration_s=args.duration_s,
                out=out,
                force=args.force,
                progress=progress,
                live=live,
                on_ready=lambda session: _ready(session, quiet=args.quiet),
                stop=stop,
                figures=args.figures or args.gif,
                unity=UnityOptions(args.unity_host, args.unity_port) if args.unity else None,
                threads=args.threads,
            )
        except RunStopped as stopped:
            if stopped.result is not None and stopped.result.out is not None:
                ran.append(out)
            raise
    finally:
        if progress is not None:
            progress.close()
        if standins is not None:
            standins.stop()
        if domain is not None:
            domain.close()
    ran.append(out)
    figures = []
    if args.figures or args.gif:
        from cosim.plotting.command import plot_run

        figures = plot_run(out, gif=args.gif)
    if not args.quiet:
        print_run(result, out, figures)
    return EXIT_OK


def _out_folder(args: argparse.Namespace, scenario: Scenario, *, quiet: bool) -> Path:
    """``--out``, or ``runs/NAME-seedN`` numbered (``-2``, ...) when that one holds a run.

    With ``--force`` and no ``--out``, ``runs/NAME-seedN`` itself (its earlier run replaced).
    """
    from cosim.runner.outfolder import default_out

    if args.out is not None:
        return Path(args.out)
    base = Path("runs") / f"{scenario.name}-seed{scenario.seed}"
    if args.force:
        return base
    out = default_out(base)
    if out != base and not quiet:
        print(
            f"results folder: {out}/ ({base}/ holds an earlier run; "
            "--out DIR chooses, --force replaces it)",
            flush=True,
        )
    return out


def _stopped_line(stopped: RunStopped, ran: list[Path]) -> str:
    """What a stopped run kept, in one line."""
    name = str(stopped)
    result = stopped.result
    if not ran:
        return f"{name} before the run's results were written"
    out = ran[0]
    if result is None or result.stopped is None:
        return f"{name}; the run had finished: its results are complete in {out}/"
    s = result.summary
    return (
        f"{name} at {s['sim_time_s']:g} s of {s['planned_duration_s']:g} s simulated; "
        f'the results so far are in {out}/ (summary.json says "stopped")'
    )


def _ready(session: RecordingSession, *, quiet: bool) -> None:
    """Say where the live view and the Unity endpoint are; hold the run for a viewer if asked."""
    unity = session.unity
    if unity is not None and not quiet:
        print(
            f"unity: ROS-TCP-Endpoint on {unity.options.host}:{unity.port}  (Unity: Robotics > "
            "ROS Settings: Protocol ROS2, ROS IP Address and Port; real time)",
            flush=True,
        )
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


def _cmd_check(args: argparse.Namespace) -> int:
    from cosim.recording.setup import RecordingSession
    from cosim.runner.assembly import assemble
    from cosim.runner.faults import plugin_faults_named
    from cosim.scenario import dump_scenario

    scenario = _load(args)
    # builds the world and every adapter: impossible requests fail here, as do topic
    # patterns that match nothing the run would record
    recording = scenario.record.bag != "none"
    with plugin_faults_named("building the run"):
        assembly = assemble(scenario, recording=recording)
    if recording:
        RecordingSession.topics_of(scenario, assembly.run.bus)
    if args.print:
        # the TOML alone on stdout, so that `cosim check S --print > mine.toml` is a scenario file
        print(f"ok: {_describe(scenario)}", file=sys.stderr)
        print(dump_scenario(scenario), end="")
    else:
        print(f"ok: {_describe(scenario)}")
    return EXIT_OK


def _cmd_world(args: argparse.Namespace) -> int:
    from adapters.world.warehouse import scenario_warehouse
    from cosim.cli.world import world_command

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
    from cosim.studies.lifeline import StudyStopped, stop_on_signals
    from cosim.studies.runner import Progress, run_study
    from cosim.studies.validate import load_study

    # SIGTERM stops a study as Ctrl-C does: finished runs kept, one line, 128 + the signal
    try:
        with stop_on_signals() as stop:
            spec = load_study(args.study, dict(map(parse_override, args.overrides)))
            out = args.out or Path("runs") / "studies" / spec.name
            total = len(spec.runs())
            where = (
                f"Dask at {args.scheduler}"
                if args.scheduler
                else f"{args.workers or 'all'} workers"
            )
            print(
                f"{spec.name}: {total} runs ({len(spec.combinations())} combinations x "
                f"{len(spec.seeds)} seeds) on {where} -> {out}/",
                flush=True,
            )
            results = run_study(
                spec,
                out,
                workers=args.workers,
                scheduler=args.scheduler,
                scheduler_timeout_s=args.scheduler_timeout_s,
                resume=args.resume,
                progress=None if args.quiet else Progress(),
                stop=stop,
            )
    except StudyStopped as stopped:
        print(f"cosim: {stopped.message}", file=sys.stderr)
        return stopped.exit_status
    failed = int((results["status"] != "ok").sum()) if len(results) else 0
    print(
        f"results: {out}/results.parquet ({len(results)} runs, {failed} failed)"
        + (f", report: {out}/report.md" if (out / "report.md").exists() else "")
    )
    if failed:
        print(f"cosim: {failed_runs_line(results, out)}", file=sys.stderr)
        return EXIT_RUNS_FAILED
    return EXIT_OK


def _cmd_bag(args: argparse.Namespace) -> int:
    from adapters.bags.reader import bag_info, format_info
    from cosim.runner.runfolder import bag_of

    print(format_info(bag_info(bag_of(args.bag))))
    return EXIT_OK


def _cmd_map(args: argparse.Namespace) -> int:
    from cosim.cli.bagmap import map_bag
    from cosim.runner.runfolder import bag_of
    from models.mapping.matcher import MatcherParams
    from models.mapping.slam import UpdateGate

    progress = None if args.quiet else ProgressLine(label=f"{args.bag.name}: ")
    try:
        result = map_bag(
            bag_of(args.bag),
            args.out,
            scan_topic=args.scan,
            odom_topic=args.odom,
            reference_topic=args.reference,
            resolution_m=args.resolution_m,
            gate=UpdateGate(min_travel_m=args.min_travel_m),
            matcher=MatcherParams(margin=args.match_margin, refine_against=args.refine),
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
        f"{s['loop_closures']} loop closures, {s['loop_closures_not_needed']} revisits "
        "already in place), "
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

    say = functools.partial(print, file=sys.stderr)  # a line on how an old run was read
    for path in plot_run(args.run_dir, at=args.at, gif=args.gif, out=args.out, note=say):
        print(f"wrote {path}")
    return EXIT_OK


def _cmd_scenarios(_args: argparse.Namespace) -> int:
    names = preset_names()
    width = max(len(n) for n in names)
    for name in names:
        print(f"{name:<{width}}  {preset_summary(name)}")
    return EXIT_OK


def _cmd_plugins(args: argparse.Namespace) -> int:
    from cosim.cli.plugins import list_plugins
    from cosim.core.registry import group_named

    return list_plugins([group_named(kind) for kind in args.kinds] or None)


def _cmd_standin(args: argparse.Namespace) -> int:
    from adapters.physical.standin import serve

    return serve(args)


COMMANDS = {
    "run": _cmd_run,
    "check": _cmd_check,
    "world": _cmd_world,
    "study": _cmd_study,
    "bag": _cmd_bag,
    "map": _cmd_map,
    "plot": _cmd_plot,
    "scenarios": _cmd_scenarios,
    "plugins": _cmd_plugins,
    "check-plugin": check_plugin_command,
    "standin": _cmd_standin,
}


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return COMMANDS[args.command](args)
    except (CosimError, ConfigError) as error:
        return say_error(error)
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
