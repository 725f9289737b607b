"""Running a scenario: assemble, start, run the kernel, collect the summary and tables."""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

from adapters.unity.server import UnityOptions
from cosim.core.adapter import AdapterType
from cosim.core.errors import BridgeError, CosimError, ExportError, RegistryError
from cosim.core.registry import AdapterRegistry
from cosim.core.timebase import NS_PER_S, s_to_ns
from cosim.recording.foxglove import LiveOptions
from cosim.recording.setup import RecordingPlan, RecordingSession
from cosim.runner.arguments import run_arguments
from cosim.runner.assembly import Assembly, assemble
from cosim.runner.compiletime import CompileClock
from cosim.runner.conclusion import close_adapters, conclude
from cosim.runner.faults import (
    Hung,
    fault_of,
    plugin_faults_named,
)
from cosim.runner.outfolder import prepare_out, write_kept, write_run
from cosim.runner.result import RunResult
from cosim.runner.stopping import CHECK_EVERY_S, RunStopped, StopRequest
from cosim.runner.watchdog import Watchdog
from cosim.scenario.loader import check_runnable
from cosim.scenario.model import Scenario

ProgressFn = Callable[[float, float, float], None]
"""Progress callback: (sim time s, duration s, wall time s)."""

PROGRESS_EVERY_S = 0.5
"""Wall-clock seconds between progress calls."""


def execute(
    scenario: Scenario,
    *,
    progress: ProgressFn | None = None,
    names: list[str] | None = None,
    registry: AdapterRegistry | None = None,
    out: Path | None = None,
    force: bool = False,
    live: LiveOptions | None = None,
    on_ready: Callable[[RecordingSession], None] | None = None,
    adapters: Sequence[str | AdapterType] = (),
    stop: StopRequest | None = None,
    figures: bool = False,
    unity: UnityOptions | None = None,
    threads: int = 1,
) -> RunResult:
    """Run a scenario to its duration and return its result.

    Everything that can be refused (the scenario's world and adapters, the topics to
    record, the output folder, the live port) is checked before the run starts.

    Args:
        scenario: the scenario.
        progress: called with (sim s, duration s, wall s) during the run.
        names: adapters to run instead of the scenario's (see
            :func:`cosim.runner.assembly.assemble`).
        registry: adapter registry; defaults to the installed entry points.
        out: the run folder: the bag streams into ``out/bag`` while the run goes (per
            ``record.bag``); the other results are written by :func:`write_run`.
        force: replace the results in a non-empty ``out``.
        live: serve the run to Foxglove over WebSocket, paced by the real-time kernel.
        unity: serve the run to Unity scenes as a ROS-TCP-Endpoint, paced likewise.
        on_ready: called with the recording session once sinks are open, before the run
            (the command line prints the live view's address there).
        adapters: more adapters to run: registered names, or adapter classes (used for
            this run as if registered under their ``name``).
        stop: a stop request (:func:`cosim.runner.stopping.stop_on_signals`): while the
            kernel runs, a stop asked for ends the run at an event boundary and the result
            covers the simulated time reached (``stopped``); before, it raises
            :class:`~cosim.runner.stopping.RunStopped` at once.
        figures: the caller draws this run's figures into ``out/figures`` afterwards
            (``cosim run --figures``), so ``force`` removes an earlier run's figures too;
            without it they stay (drawn by ``cosim plot``, they are not this run's to remove).
        threads: worker threads for each instant's per-robot work (1: all on this thread);
            the tables are the same for any number.

    Raises:
        BridgeError: an external system failed while the kernel ran (a physical robot or a
            motion-capture server gone silent); the bag is finished and the error's
            ``kept`` holds the result of the simulated time reached.
        PluginError: a plugin's code raised, hung past ``scenario.hang_timeout_s`` or
            handed back a value cosim refuses; named, with its traceback (``details``) and,
            once the run had started, ``kept`` as for a ``BridgeError``.
        InternalError: cosim's own code failed once the run had started (a bug); ``kept``
            and ``details`` likewise.
    """
    check_runnable(scenario)
    with CompileClock() as clock:  # numba's compile time, said apart from the speed
        with _immediate(stop):
            plan = RecordingPlan.for_run(scenario, out, live, unity)
            registry, extra = with_adapters(
                registry or AdapterRegistry.from_entry_points(), adapters
            )
            with plugin_faults_named("building the run"):
                assembly = assemble(
                    scenario,
                    names=names,
                    registry=registry,
                    extra=extra,
                    realtime=plan.realtime,
                    speed=live.rate if live is not None else 1.0,
                    recording=plan.active,
                    threads=threads,
                )
            run = assembly.run
            topics = RecordingSession.topics_of(scenario, run.bus) if plan.active else {}
            session = RecordingSession(plan, topics, run.bus)
        folder = Path(out) if out is not None else None
        bag = plan.bag is not None
        prepare = (
            None
            if folder is None
            else lambda: prepare_out(folder, force=force, bag=bag, figures=figures)
        )
        unfinished: ExportError | None = None
        try:
            with _immediate(stop):
                if plan.active:
                    session.open(before_bag=prepare)
                    if session.unity is not None:  # where the run's Unity poses come from
                        run.provide(session.unity)
                elif prepare is not None:
                    prepare()
                if on_ready is not None:
                    on_ready(session)
            with _deferred(stop):
                result = _run_assembled(scenario, assembly, progress, stop, clock)
        finally:
            with _deferred(stop):  # the bag is finished (metadata.yaml) whatever stopped the run
                unfinished = _close(session)
    result.compile_time_s = round(clock.seconds, 3)
    result.bag = plan.bag
    result.recorded = session.counts()
    result.summary.update(session.summary())
    if result.failure is not None:
        if unfinished is not None and not isinstance(result.failure, ExportError):
            result.failure.say_kept(str(unfinished))
        result.failure.kept = result
        raise result.failure
    if unfinished is not None:  # the bag could not be finished: the rest of the run is kept
        unfinished.kept = result
        raise unfinished
    return result


def _close(session: RecordingSession) -> ExportError | None:
    """Finish the bag and the live servers; the error when the bag cannot be finished."""
    try:
        session.close()
    except ExportError as error:
        return error
    return None


def with_adapters(
    registry: AdapterRegistry, adapters: Sequence[str | AdapterType]
) -> tuple[AdapterRegistry, list[str]]:
    """The registry with the adapter classes among ``adapters`` added, and every name."""
    names = []
    for adapter in adapters:
        if isinstance(adapter, str):
            if adapter not in registry.names():
                raise RegistryError(
                    f"cosim.run(adapters=[..., {adapter!r}, ...]): {registry.unknown(adapter)}"
                )
            names.append(adapter)
            continue
        name = getattr(adapter, "name", None)
        if not isinstance(name, str) or not name:
            raise RegistryError(f"adapter {adapter!r} has no name (a class attribute, a string)")
        registry = registry.with_adapter(adapter)
        names.append(name)
    return registry, names


@contextlib.contextmanager
def _immediate(stop: StopRequest | None) -> Iterator[None]:
    with stop.immediate() if stop is not None else contextlib.nullcontext():
        yield


@contextlib.contextmanager
def _deferred(stop: StopRequest | None) -> Iterator[None]:
    with stop.deferred() if stop is not None else contextlib.nullcontext():
        yield


class _HaltError(Exception):
    """Raised by the progress check, between two events, to end a run asked to stop."""


def _run_assembled(
    scenario: Scenario,
    assembly: Assembly,
    progress: ProgressFn | None,
    stop: StopRequest | None = None,
    clock: CompileClock | None = None,
) -> RunResult:
    run = assembly.run
    duration_s = scenario.scenario.duration_s
    until_ns = s_to_ns(duration_s)
    wall_start = time.perf_counter()
    compiled_before_s = clock.seconds if clock is not None else 0.0
    watchdog = Watchdog(
        scenario.scenario.hang_timeout_s,
        busy=(lambda: clock.compiling) if clock is not None else None,
    )
    doing = "starting the run"
    next_progress = [0.0]

    def report(now_ns: int, events: int) -> None:
        wall = time.perf_counter() - wall_start
        if progress is not None and (wall >= next_progress[0] or now_ns >= until_ns):
            progress(now_ns / NS_PER_S, duration_s, wall)
            next_progress[0] = wall + PROGRESS_EVERY_S
        if stop is not None and stop.requested and now_ns < until_ns:
            raise _HaltError

    halted = stop is not None and stop.requested
    failure: CosimError | None = None
    events = 0
    counted = run.kernel.events_processed
    try:
        with watchdog:
            for name, adapter in assembly.adapters:
                doing = f"starting adapter {name!r}"
                watchdog.beat()
                adapter.start(run)
            doing = "running the simulation"
            if not halted:
                events = run.kernel.run(
                    until_ns,
                    progress=report if progress is not None or stop is not None else None,
                    progress_interval_s=CHECK_EVERY_S if stop is not None else PROGRESS_EVERY_S,
                    heartbeat=watchdog.beat if watchdog.active else None,
                )
    except _HaltError:
        halted, events = True, run.kernel.events_processed - counted
    except (BridgeError, ExportError) as error:  # the world failed: a silent robot, a full disk
        halted, events, failure = True, run.kernel.events_processed - counted, error
    except (Exception, Hung) as error:  # user code, or cosim's: named, and what ran kept
        halted, events = True, run.kernel.events_processed - counted
        failure = fault_of(error, doing=doing, t_ns=run.kernel.now_ns)
    finally:
        failure = close_adapters(assembly, failure)
    if failure is not None:
        halted = True
    # the run loop's own time: the first run on a machine compiles numba's kernels in it
    compiling_s = clock.seconds - compiled_before_s if clock is not None else 0.0
    wall_s = max(time.perf_counter() - wall_start - compiling_s, 0.0)
    reached_s = run.kernel.now_ns / NS_PER_S if halted else duration_s
    stopped = stop.signum if halted and stop is not None and stop.signum is not None else None
    return conclude(
        scenario,
        assembly,
        reached_s=reached_s,
        wall_s=wall_s,
        events=events,
        failure=failure,
        stopped=stopped,
    )


def run(
    scenario: Scenario | str | Path,
    *,
    seed: int | None = None,
    duration_s: float | None = None,
    out: str | Path | None = None,
    force: bool = False,
    progress: ProgressFn | None = None,
    live: LiveOptions | None = None,
    on_ready: Callable[[RecordingSession], None] | None = None,
    adapters: Sequence[str | AdapterType] = (),
    stop: StopRequest | None = None,
    figures: bool = False,
    unity: UnityOptions | None = None,
    threads: int | None = None,
) -> RunResult:
    """Run a scenario; optionally write its folder.

    ```python
    import cosim
    scenario = cosim.load_scenario("warehouse-random", overrides={"robots.count": 8})
    result = cosim.run(scenario, seed=3, adapters=[MySensorAdapter])
    result.tables["poses"].groupby("robot").v_mps.mean()
    ```

    Args:
        scenario: from :func:`cosim.load_scenario`; or a preset name or a scenario file,
            loaded as ``cosim.load_scenario(scenario)`` would.
        seed: overrides ``scenario.seed`` (an int >= 0; not a bool).
        duration_s: overrides ``scenario.duration_s`` (s).
        out: folder to write (``summary.json``, ``scenario.toml``, ``tables/``, ``bag/``).
        force: replace the results in a non-empty ``out``.
        progress: called with (sim s, duration s, wall s) during the run.
        live: serve the run live to Foxglove (see :class:`cosim.recording.foxglove.LiveOptions`).
        unity: serve the run to Unity's ROS-TCP-Connector scenes (see
            :class:`adapters.unity.server.UnityOptions`), paced in real time.
        on_ready: called once the recording is set up, before the run starts.
        adapters: more adapters to run: registered names, or adapter classes (a class is
            used for this run as if registered under its ``name``; the resolved
            ``scenario.toml`` cannot name it, so ``cosim run`` of that file runs without it);
            one name or class alone is taken as a list of one.
        stop: a stop request (:func:`cosim.runner.stopping.stop_on_signals`): a run asked
            to stop ends at an event boundary, and what ran is kept (the bag finished, the
            tables and a summary marked ``"stopped"`` written) before
            :class:`~cosim.runner.stopping.RunStopped` is raised with the result.
        figures: the caller draws the run's figures into ``out/figures`` afterwards, so
            ``force`` removes an earlier run's figures; without it, ``force`` keeps them.
        threads: worker threads for each simulated instant's per-robot work (lidar casts,
            scan matching and map updates, path planning); None: the cores available, 1:
            all on the calling thread. Tables and bags are the same for any number; the
            summary says how busy each thread was (``thread_busy_share``).

    Returns:
        The run's summary and tables (``summary["wall_time_s"]`` and
        ``["real_time_factor"]`` of the run loop without numba's compiling, which is in
        ``compile_time_s``).

    Raises:
        ArgumentError: (a ``ConfigError`` and a ``TypeError``) an argument of the wrong type,
            in one line naming it (:mod:`cosim.runner.arguments` checks them all first).
        ConfigError: an argument out of bounds (``seed=-1``), or a scenario given by name or
            file that does not load.
        RunStopped: the run was asked to stop (``stop``).
        BridgeError: an external system failed mid-run; with ``out``, what ran is written
            there first and the message says where.
        PluginError: a plugin's code failed (raised, hung, or handed back a value cosim
            refuses); once the run had started, what ran is written to ``out`` as for a
            ``BridgeError``, with the traceback in ``out/failure.txt``.
        InternalError: cosim's own code failed mid-run (a bug); likewise.
    """
    checked = run_arguments(
        scenario,
        seed=seed,
        duration_s=duration_s,
        out=out,
        force=force,
        progress=progress,
        live=live,
        on_ready=on_ready,
        adapters=adapters,
        stop=stop,
        figures=figures,
        unity=unity,
        threads=threads,
    )
    scenario, folder = checked.scenario, checked.out
    with _deferred(stop):
        try:
            result = execute(
                scenario,
                progress=progress,
                out=folder,
                force=force,
                live=live,
                on_ready=on_ready,
                adapters=checked.adapters,
                stop=stop,
                figures=figures,
                unity=unity,
                threads=checked.threads,
            )
        except CosimError as error:
            if error.kept is None or folder is None:
                raise
            write_kept(error, folder, tables=scenario.record.tables)
            raise
        if folder is not None:
            write_run(result, folder, tables=scenario.record.tables)
    if stop is not None and stop.signum is not None:
        raise RunStopped(stop.signum, result)
    return result


__all__ = ["RunResult", "RunStopped", "execute", "prepare_out", "run", "write_run"]
