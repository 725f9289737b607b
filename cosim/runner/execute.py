"""Running a scenario: assemble, start, run the kernel, collect the summary and tables."""

from __future__ import annotations

import json
import platform
import shutil
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from importlib.metadata import version
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from adapters.world.files import write_map
from cosim.core.adapter import AdapterType
from cosim.core.errors import ExportError, RegistryError
from cosim.core.kernel import Lateness
from cosim.core.recorder import MapArtifact, Recorder, TableSpec, merge_counts
from cosim.core.registry import AdapterRegistry
from cosim.core.timebase import NS_PER_S, s_to_ns
from cosim.recording.foxglove import LiveOptions
from cosim.recording.setup import RecordingPlan, RecordingSession
from cosim.runner.assembly import Assembly, assemble
from cosim.scenario.loader import dump_scenario
from cosim.scenario.model import Scenario
from models.occupancy import OccupancyGrid

ProgressFn = Callable[[float, float, float], None]
"""Progress callback: (sim time s, duration s, wall time s)."""

OUTPUTS = ("summary.json", "scenario.toml", "tables", "figures", "bag", "maps", "sumo")
"""What a run writes into its folder (``--force`` removes exactly these)."""


@dataclass
class RunResult:
    """The outcome of a run.

    Attributes:
        scenario: the scenario that ran (with its seed and duration).
        summary: flat metrics and provenance.
        tables: DataFrames by table name (``poses``, ``messages``, ``events``, ...).
        out: the run folder, when written.
        bag: the bag directory, when one was written.
        recorded: messages recorded per topic (bag or live view).
        maps: final occupancy maps by name (written as ``maps/NAME.yaml`` + ``.pgm``).
        files: other files for the run folder by relative path (SUMO's ``sumo/...``).
    """

    scenario: Scenario
    summary: dict[str, Any]
    tables: dict[str, pd.DataFrame] = field(repr=False)
    out: Path | None = None
    volatile: dict[str, tuple[str, ...]] = field(default_factory=dict, repr=False)
    bag: Path | None = None
    recorded: dict[str, int] = field(default_factory=dict, repr=False)
    maps: dict[str, MapArtifact] = field(default_factory=dict, repr=False)
    files: dict[str, bytes] = field(default_factory=dict, repr=False)

    def deterministic_tables(self) -> dict[str, pd.DataFrame]:
        """The tables without their wall-clock columns: equal for equal scenario and seed."""
        return {
            name: frame.drop(columns=list(self.volatile.get(name, ())))
            for name, frame in self.tables.items()
        }


def cosim_version() -> str:
    """The installed cosim version."""
    return version("cosim")


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
        on_ready: called with the recording session once sinks are open, before the run
            (the command line prints the live view's address there).
        adapters: more adapters to run: registered names, or adapter classes (used for
            this run as if registered under their ``name``).
    """
    plan = RecordingPlan.for_run(scenario, out, live)
    registry, extra = with_adapters(registry or AdapterRegistry.from_entry_points(), adapters)
    assembly = assemble(
        scenario,
        names=names,
        registry=registry,
        extra=extra,
        realtime=live is not None,
        speed=live.rate if live is not None else 1.0,
        recording=plan.active,
    )
    run = assembly.run
    topics = RecordingSession.topics_of(scenario, run.bus) if plan.active else {}
    session = RecordingSession(plan, topics, run.bus)
    folder = Path(out) if out is not None else None
    prepare = None if folder is None else lambda: prepare_out(folder, force=force)
    if plan.active:
        session.open(before_bag=prepare)
    elif prepare is not None:
        prepare()
    try:
        if on_ready is not None:
            on_ready(session)
        result = _run_assembled(scenario, assembly, progress)
    finally:
        session.close()
    result.bag = plan.bag
    result.recorded = session.counts()
    return result


def with_adapters(
    registry: AdapterRegistry, adapters: Sequence[str | AdapterType]
) -> tuple[AdapterRegistry, list[str]]:
    """The registry with the adapter classes among ``adapters`` added, and every name."""
    names = []
    for adapter in adapters:
        if isinstance(adapter, str):
            names.append(adapter)
            continue
        name = getattr(adapter, "name", None)
        if not isinstance(name, str) or not name:
            raise RegistryError(f"adapter {adapter!r} has no name (a class attribute, a string)")
        registry = registry.with_adapter(adapter)
        names.append(name)
    return registry, names


def _run_assembled(
    scenario: Scenario, assembly: Assembly, progress: ProgressFn | None
) -> RunResult:
    run = assembly.run
    duration_s = scenario.scenario.duration_s
    until_ns = s_to_ns(duration_s)
    wall_start = time.perf_counter()
    for _name, adapter in assembly.adapters:
        adapter.start(run)

    def report(now_ns: int, _events: int) -> None:
        if progress is not None:
            progress(now_ns / NS_PER_S, duration_s, time.perf_counter() - wall_start)

    try:
        events = run.kernel.run(until_ns, progress=report if progress else None)
    finally:
        for _name, adapter in assembly.adapters:
            close = getattr(adapter, "close", None)
            if close is not None:
                close()
    wall_s = time.perf_counter() - wall_start
    counts = run.recorder.counts
    sent = sum(counts.values())
    summary: dict[str, Any] = {
        "scenario": scenario.name,
        "source": scenario.source,
        "seed": scenario.seed,
        "version": cosim_version(),
        "python": platform.python_version(),
        "sim_time_s": duration_s,
        "wall_time_s": round(wall_s, 4),
        "real_time_factor": round(duration_s / wall_s, 2) if wall_s > 0 else None,
        "events": events,
        "messages_sent": sent,
        "messages_delivered": counts["delivered"],
        "messages_dropped": sent - counts["delivered"],
        "network_messages": run.recorder.network_messages,
        "network_bytes": run.recorder.network_bytes,
    }
    if run.kernel.lateness is not None:
        summary.update(record_lateness(run.kernel.lateness, run.recorder))
    for name, adapter in assembly.adapters:
        try:
            merge_counts(summary, adapter.finish(run))
        except ValueError as error:
            raise RuntimeError(f"adapter {name!r}: {error}") from error
    return RunResult(
        scenario,
        summary,
        run.recorder.frames(),
        volatile=run.recorder.volatile,
        maps=dict(run.recorder.maps),
        files=dict(run.recorder.files),
    )


REALTIME = TableSpec(
    "realtime",
    "Real-time runs only: one row per batch of events due at one simulated instant.",
    {
        "t_s": "the batch's simulated instant (s)",
        "lateness_ms": "wall-clock time past the instant it was due (ms; volatile)",
        "events": "events processed in the batch",
    },
    volatile=("lateness_ms",),
)


def record_lateness(lateness: Lateness, recorder: Recorder) -> dict[str, Any]:
    """Write ``tables/realtime`` (one row per event batch) and return the summary keys.

    Columns: t_s (the batch's simulated instant), lateness_ms (wall-clock ms past the
    instant it was due), events (in the batch). Wall-clock figures: volatile.
    """
    late_ms = np.frombuffer(lateness.late_ns, dtype=np.int64) / 1e6
    table = recorder.table(REALTIME)
    table.extend(
        t_s=np.frombuffer(lateness.t_ns, dtype=np.int64) / NS_PER_S,
        lateness_ms=late_ms,
        events=np.frombuffer(lateness.events, dtype=np.int64),
    )
    if late_ms.size == 0:
        return {"max_lateness_ms": None, "p99_lateness_ms": None, "late_batches": 0}
    return {
        "max_lateness_ms": round(float(late_ms.max()), 3),
        "p99_lateness_ms": round(float(np.percentile(late_ms, 99)), 3),
        "late_batches": int((late_ms > 1.0).sum()),
    }


def prepare_out(out: Path, *, force: bool) -> None:
    """Make sure ``out`` can take a run's results.

    Raises:
        ExportError: if ``out`` is a file, or a non-empty folder and ``force`` is false.
    """
    if out.exists() and not out.is_dir():
        raise ExportError(f"{out}: exists and is not a folder")
    if out.is_dir() and any(out.iterdir()):
        if not force:
            raise ExportError(f"{out}: folder is not empty; not overwriting (use --force)")
        for name in OUTPUTS:
            target = out / name
            if target.is_dir():
                shutil.rmtree(target)
            elif target.exists():
                target.unlink()


def write_run(result: RunResult, out: Path, *, tables: bool = True) -> None:
    """Write a run's folder atomically: into ``out.partial`` first, then renamed in place."""
    out = Path(out)
    partial = out.with_name(out.name + ".partial")
    if partial.exists():
        shutil.rmtree(partial)
    try:
        partial.mkdir(parents=True)
        (partial / "scenario.toml").write_text(dump_scenario(result.scenario), encoding="utf-8")
        if tables:
            (partial / "tables").mkdir()
            for name, frame in result.tables.items():
                frame.to_parquet(partial / "tables" / f"{name}.parquet", index=False)
        for name, grid in result.maps.items():
            write_map(
                OccupancyGrid(grid.resolution_m, grid.origin_xy_m, grid.data),
                partial / "maps" / f"{name}.yaml",
            )
        for relative, data in result.files.items():
            target = partial / relative
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
        (partial / "summary.json").write_text(
            json.dumps(result.summary, indent=2, allow_nan=False) + "\n", encoding="utf-8"
        )
        out.mkdir(parents=True, exist_ok=True)
        for entry in sorted(partial.iterdir()):
            entry.rename(out / entry.name)
        partial.rmdir()
    except OSError as error:
        raise ExportError(f"{out}: cannot write results ({error})") from error
    result.out = out


def run(
    scenario: Scenario,
    *,
    seed: int | None = None,
    duration_s: float | None = None,
    out: str | Path | None = None,
    force: bool = False,
    progress: ProgressFn | None = None,
    live: LiveOptions | None = None,
    on_ready: Callable[[RecordingSession], None] | None = None,
    adapters: Sequence[str | AdapterType] = (),
) -> RunResult:
    """Run a scenario; optionally write its folder.

    ```python
    import cosim
    scenario = cosim.load_scenario("warehouse-random", overrides={"robots.count": 8})
    result = cosim.run(scenario, seed=3, adapters=[MySensorAdapter])
    result.tables["poses"].groupby("robot").v_mps.mean()
    ```

    Args:
        scenario: from :func:`cosim.load_scenario`.
        seed: overrides ``scenario.seed``.
        duration_s: overrides ``scenario.duration_s`` (s).
        out: folder to write (``summary.json``, ``scenario.toml``, ``tables/``, ``bag/``).
        force: replace the results in a non-empty ``out``.
        progress: called with (sim s, duration s, wall s) during the run.
        live: serve the run live to Foxglove (see :class:`cosim.recording.foxglove.LiveOptions`).
        on_ready: called once the recording is set up, before the run starts.
        adapters: more adapters to run: registered names, or adapter classes (a class is
            used for this run as if registered under its ``name``; the resolved
            ``scenario.toml`` cannot name it, so ``cosim run`` of that file runs without it).

    Returns:
        The run's summary and tables.
    """
    if seed is not None:
        scenario = scenario.with_seed(seed)
    if duration_s is not None:
        scenario = scenario.with_duration(duration_s)
    folder = Path(out) if out is not None else None
    result = execute(
        scenario,
        progress=progress,
        out=folder,
        force=force,
        live=live,
        on_ready=on_ready,
        adapters=adapters,
    )
    if folder is not None:
        write_run(result, folder, tables=scenario.record.tables)
    return result
