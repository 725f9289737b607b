"""The end of a run: its adapters closed and finished, its summary and tables gathered.

Shared by every way a run is driven: :func:`cosim.runner.execute.execute` to its duration,
and a learning environment (:mod:`cosim.envs`) decision by decision.
"""

from __future__ import annotations

import platform
from collections.abc import Mapping
from importlib.metadata import version
from typing import Any

from cosim.core.errors import BridgeError, CosimError, ExportError
from cosim.core.plugins import PluginError, refuse
from cosim.core.recorder import merge_counts
from cosim.recording.dataframes import run_frames
from cosim.runner.assembly import Assembly
from cosim.runner.faults import Hung, InternalError, fault_of
from cosim.runner.lateness import record_lateness
from cosim.runner.provenance import run_plugins
from cosim.runner.result import RunResult
from cosim.runner.stopping import signal_name
from cosim.runner.watchdog import Watchdog
from cosim.scenario.model import Scenario


def cosim_version() -> str:
    """The installed cosim version."""
    return version("cosim")


def close_adapters(assembly: Assembly, failure: CosimError | None) -> CosimError | None:
    """Close the run's threads and every adapter with a ``close``; the run's first failure.

    Args:
        assembly: the assembled run.
        failure: what failed the run so far, if anything (kept first).
    """
    assembly.run.workers.close()
    for name, adapter in assembly.adapters:
        close = getattr(adapter, "close", None)
        if close is None:
            continue
        try:
            close()
        except Exception as error:
            if failure is None:
                failure = fault_of(error, doing=f"closing adapter {name!r}", t_ns=None)
    return failure


def conclude(
    scenario: Scenario,
    assembly: Assembly,
    *,
    reached_s: float,
    wall_s: float,
    events: int,
    failure: CosimError | None,
    stopped: int | None = None,
) -> RunResult:
    """Sum up a run whose kernel stopped: the adapters' ``finish``, the summary and tables.

    Args:
        scenario: the scenario run.
        assembly: the assembled run, its adapters closed (:func:`close_adapters`).
        reached_s: the simulated time the run covers (s).
        wall_s: the wall time its kernel ran (s).
        events: kernel events processed.
        failure: what failed the run, if anything (its summary says so first).
        stopped: the signal a stopped run was stopped by.
    """
    run = assembly.run
    duration_s = scenario.scenario.duration_s
    counts = run.recorder.counts
    sent = sum(counts.values())
    summary: dict[str, Any] = {
        "scenario": scenario.name,
        "source": scenario.source,
        "seed": scenario.seed,
        "version": cosim_version(),
        "python": platform.python_version(),
        "plugins": run_plugins(scenario, assembly),
        "sim_time_s": reached_s,
        "wall_time_s": round(wall_s, 4),
        "real_time_factor": round(reached_s / wall_s, 2) if wall_s > 0 else None,
        "events": events,
        **run.workers.summary(wall_s),
        "messages_sent": sent,
        "messages_delivered": counts["delivered"],
        "messages_dropped": sent - counts["delivered"],
        "network_messages": run.recorder.network_messages,
        "network_bytes": run.recorder.network_bytes,
    }
    now_ns = run.kernel.now_ns
    if stopped is not None:
        # a run that did not reach its duration says so before anything else
        summary = {"stopped": signal_name(stopped), "planned_duration_s": duration_s, **summary}
    if run.kernel.lateness is not None:
        summary.update(record_lateness(run.kernel.lateness, run.recorder))
    unfinished = []
    for name, adapter in assembly.adapters:
        try:
            with Watchdog(scenario.scenario.hang_timeout_s):
                metrics = adapter.finish(run)
            if not isinstance(metrics, Mapping):
                raise refuse(
                    adapter,
                    f"finish() returned {type(metrics).__name__}; expected a mapping of "
                    "summary metrics (dict)",
                )
            merge_counts(summary, metrics)
        except ValueError as error:  # a summary key given twice
            failure = failure or refuse(adapter, f"finish(): {error}").at(run.kernel.now_ns)
            unfinished.append(name)
        except (Exception, Hung) as error:
            unfinished.append(name)
            if failure is None:  # once a run failed, adapters may fail to sum it up
                failure = fault_of(error, doing=f"finishing adapter {name!r}", t_ns=now_ns)
    if failure is not None:
        summary = {**failure_summary(failure, duration_s, unfinished), **summary}
    return RunResult(
        scenario,
        summary,
        run_frames(run.recorder),
        volatile=run.recorder.volatile,
        maps=dict(run.recorder.maps),
        files=dict(run.recorder.files),
        stopped=stopped,
        failure=failure,
    )


def failure_summary(failure: CosimError, planned_s: float, unfinished: list[str]) -> dict[str, Any]:
    """The summary keys of a failed run, first: what failed, whose fault, what is missing.

    ``failed`` is the one-line error; ``failure`` says whose fault it was (``plugin``,
    ``cosim`` or ``external``/``input``), the plugin, and the adapters whose metrics are
    missing because their ``finish`` failed after the fault.
    """
    if isinstance(failure, PluginError):
        kind = "plugin"
    elif isinstance(failure, InternalError):
        kind = "cosim"
    elif isinstance(failure, BridgeError | ExportError):
        kind = "external"
    else:
        kind = "input"
    detail: dict[str, Any] = {"kind": kind}
    plugin = getattr(failure, "plugin", None)
    if plugin is not None:
        detail["plugin"] = plugin.as_dict()
    if unfinished:
        detail["unfinished_adapters"] = unfinished
    return {"failed": str(failure), "failure": detail, "planned_duration_s": planned_s}
