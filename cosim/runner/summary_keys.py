"""Every ``summary.json`` key, declared: cosim's own (the runner's) and every writer's.

The runner writes the keys of :data:`RUN_KEYS` itself (provenance, times, message counts,
and the keys of a stopped, failed or real-time run); every other key comes from an
adapter's ``finish()`` or from an entry an adapter asks for its summary, each declared
in that class's ``summary_keys`` attribute (:mod:`cosim.core.summary`).
:func:`declared_summaries` gathers them all, cosim's built-ins and plugins alike, for the
summary reference and for ``cosim check-plugin``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from adapters.unity.server import UnitySink
from cosim.core.registry import installed_groups
from cosim.core.summary import SummaryKey, summary_keys_of

RUN_KEYS: Mapping[str, SummaryKey] = {
    "stopped": SummaryKey(
        "text",
        "the signal that stopped the run before its duration (SIGINT, SIGTERM)",
        when="a run stopped early",
    ),
    "failed": SummaryKey(
        "text",
        "the error that ended the run early, in one line",
        when="a failed run",
    ),
    "failure": SummaryKey(
        "record",
        "whose fault the failure was: kind (plugin, cosim, external or input), the plugin "
        "(package, version, group, name, target) and unfinished_adapters",
        when="a failed run",
    ),
    "planned_duration_s": SummaryKey(
        "s", "the duration the run was to simulate", when="a run stopped early or failed"
    ),
    "scenario": SummaryKey("text", "the scenario's name (scenario.name)"),
    "source": SummaryKey("text", "the file or preset the scenario was loaded from"),
    "seed": SummaryKey("id", "the scenario seed every random stream derives from"),
    "version": SummaryKey("text", "cosim's version", volatile=True),
    "python": SummaryKey("text", "the Python version that ran it", volatile=True),
    "plugins": SummaryKey(
        "record",
        "every package whose code the run used: cosim, then each adapter, section and "
        "registry choice (package, version, group, name, target)",
    ),
    "sim_time_s": SummaryKey("s", "simulated time reached (the duration, unless stopped)"),
    "wall_time_s": SummaryKey(
        "s",
        "wall-clock time of the run loop, numba's compile time left out",
        volatile=True,
    ),
    "real_time_factor": SummaryKey(
        "ratio",
        "simulated seconds per wall-clock second (null when no wall time was measured)",
        volatile=True,
    ),
    "events": SummaryKey("count", "kernel events processed"),
    "threads": SummaryKey(
        "count",
        "worker threads of the run (--threads; the tables are the same for any number)",
        volatile=True,
    ),
    "thread_busy": SummaryKey(
        "record",
        "each thread's time running per-robot work of an instant (busy_s, s) and its "
        "share_of_wall (0..1), thread 0 being the run's own; batches: instants spread "
        "over more than one thread",
        volatile=True,
    ),
    "messages_sent": SummaryKey(
        "count", "messages published over the bus, one per destination host"
    ),
    "messages_delivered": SummaryKey("count", "of messages_sent, those delivered"),
    "messages_dropped": SummaryKey(
        "count", "of messages_sent, those dropped: lost, queue full, out of range or partitioned"
    ),
    "network_messages": SummaryKey(
        "count", "of messages_sent, those between two different hosts (over the network)"
    ),
    "network_bytes": SummaryKey("bytes", "wire size of the network_messages, summed"),
    "max_lateness_ms": SummaryKey(
        "ms",
        "largest wall-clock delay of an event batch past its due instant (null: no batch)",
        when="real-time runs",
        volatile=True,
    ),
    "p99_lateness_ms": SummaryKey(
        "ms",
        "99th percentile of the batches' lateness (null: no batch)",
        when="real-time runs",
        volatile=True,
    ),
    "late_batches": SummaryKey(
        "count", "event batches more than 1 ms late", when="real-time runs", volatile=True
    ),
}
"""The keys the runner writes itself (:mod:`cosim.runner.execute`), in the order written."""


@dataclass(frozen=True)
class DeclaredSummary:
    """The summary keys one writer declares.

    Attributes:
        writer: what writes them (``the runner``, ``adapter `fleet```, ...).
        package: the package that registers the writer.
        keys: key -> its declaration, in the order written.
    """

    writer: str
    package: str
    keys: Mapping[str, SummaryKey]


def declared_summaries() -> list[DeclaredSummary]:
    """The runner's keys, the Unity endpoint's, then every loadable registry entry's.

    Entries of every registry may declare keys (an adapter, a protocol, a pose source, a
    network backend, ...), in a ``summary_keys`` class attribute; entries that declare
    none are left out.
    """
    found = [
        DeclaredSummary("the runner (every run)", "cosim", RUN_KEYS),
        DeclaredSummary(
            "the Unity endpoint (`cosim run --unity`)", "cosim", UnitySink.summary_keys
        ),
    ]
    for group in installed_groups():
        registry = group.installed()
        for name, entry in registry.load_all().items():
            keys = summary_keys_of(entry)
            if keys:
                writer = f"{group.words} `{name}`"
                found.append(DeclaredSummary(writer, registry.package(name), keys))
    return found


def declared_keys(*extra: object) -> dict[str, SummaryKey]:
    """Every declared key (the first declaration of each), with ``extra`` entries' own.

    Args:
        extra: entries given in code (not installed) whose declarations count too.
    """
    found: dict[str, SummaryKey] = {}
    for summary in declared_summaries():
        for key, value in summary.keys.items():
            found.setdefault(key, value)
    for entry in extra:
        for key, value in summary_keys_of(entry).items():
            found.setdefault(key, value)
    return found
