"""Assertions on a run's timing: message latency, the order of events, assignment deadlines.

Each reads the run's tables (``result.tables``, the columns of ``docs/reference/tables``)
and raises :class:`AssertionError` with the numbers that broke the rule, so that it reads
the same in a pytest report and in a plain script. None passes on an empty table: a rule
with nothing to judge fails, saying so.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from fnmatch import fnmatchcase
from typing import Any, NamedTuple

import numpy as np
import pandas as pd

from cosim.runner.result import RunResult

LISTED = 5
"""Offending rows a message lists before it says how many more there are."""


def need_table(result: RunResult, name: str, written_by: str) -> pd.DataFrame:
    """``result.tables[name]``, or an assertion naming what writes it.

    Args:
        result: the run.
        name: the table (``tasks``).
        written_by: what a run needs for it (``the task source: robots.driver = 'tasks'``).
    """
    frame = result.tables.get(name)
    if frame is None:
        raise AssertionError(
            f"the run has no tables/{name} (written by {written_by}); its tables: "
            f"{', '.join(sorted(result.tables)) or 'none'}"
        )
    return frame


def listed(items: Sequence[str]) -> str:
    """The first :data:`LISTED` items, and how many more."""
    shown = "; ".join(items[:LISTED])
    return shown + (f"; and {len(items) - LISTED} more" if len(items) > LISTED else "")


def seconds(value: Any) -> str:
    """A time in seconds (a float, or a table's cell) as messages show it (``9.00636 s``)."""
    return f"{_decimal(float(value))} s"


def _decimal(value: float) -> str:
    """Seconds to the nanosecond, without trailing zeros (``8.806359972``, ``9.006``)."""
    return f"{value:.9f}".rstrip("0").rstrip(".") if np.isfinite(value) else str(value)


# -- latency -----------------------------------------------------------------------------------
class Latency(NamedTuple):
    """One-way latency of a topic's delivered messages (ms).

    Attributes:
        delivered: copies delivered (one per message and receiving host).
        dropped: copies not delivered (lost, queue full, out of range, partitioned).
        p50_ms: median (ms).
        p95_ms: 95th percentile (ms).
        p99_ms: 99th percentile (ms).
        max_ms: the largest (ms).
    """

    delivered: int
    dropped: int
    p50_ms: float
    p95_ms: float
    p99_ms: float
    max_ms: float


def assert_latency(
    result: RunResult,
    *,
    topic: str,
    p50_ms: float | None = None,
    p95_ms: float | None = None,
    p99_ms: float | None = None,
    max_ms: float | None = None,
    remote_only: bool = True,
) -> Latency:
    """Assert bounds on the one-way latency of a topic's delivered messages.

    Latency is ``t_recv_ns - t_sent_ns`` of ``tables/messages``, one value per message and
    receiving host; percentiles as :func:`numpy.percentile` computes them (linear).

    ```python
    assert_latency(result, topic="/fleet/claims", p95_ms=20)
    ```

    Args:
        result: the run (with ``record.messages = true``, the default).
        topic: a topic, or a glob pattern (``/fleet/dta/*``, ``/robot_*/scan``).
        p50_ms: bound on the median (ms).
        p95_ms: bound on the 95th percentile (ms).
        p99_ms: bound on the 99th percentile (ms).
        max_ms: bound on the largest latency (ms).
        remote_only: only copies from one host to another (a copy to the publishing
            host itself arrives at once and would dilute the percentiles).

    Returns:
        The latency figures, for a test to print or compare.

    Raises:
        AssertionError: a bound is exceeded, or no message of ``topic`` was delivered.
        ValueError: no bound given.
    """
    bounds = {"p50": p50_ms, "p95": p95_ms, "p99": p99_ms, "max": max_ms}
    if all(bound is None for bound in bounds.values()):
        raise ValueError("assert_latency needs a bound: p50_ms, p95_ms, p99_ms or max_ms")
    messages = need_table(result, "messages", "the recorder, unless record.messages = false")
    names = pd.unique(messages["topic"].astype(str))
    chosen = [name for name in names if fnmatchcase(name, topic)]
    rows = messages[messages["topic"].astype(str).isin(chosen)]
    where = f"on {topic}"
    if remote_only:
        rows = rows[rows["src_host"].astype(str) != rows["dst_host"].astype(str)]
        where += " between hosts"
    if rows.empty:
        raise AssertionError(
            f"no message {where} in tables/messages (its topics: {listed(sorted(names))})"
        )
    delivered = rows[rows["status"].astype(str) == "delivered"]
    if delivered.empty:
        statuses = rows["status"].astype(str).value_counts()
        raise AssertionError(
            f"none of the {len(rows)} messages {where} was delivered "
            f"({', '.join(f'{s}: {n}' for s, n in statuses.items())})"
        )
    sent = delivered["t_sent_ns"].to_numpy(dtype=np.int64)
    received = delivered["t_recv_ns"].to_numpy(dtype=np.int64)
    latency_ms = (received - sent) / 1e6
    p50, p95, p99 = (float(v) for v in np.percentile(latency_ms, [50, 95, 99]))
    found = Latency(
        len(delivered), len(rows) - len(delivered), p50, p95, p99, float(latency_ms.max())
    )
    measured = {"p50": p50, "p95": p95, "p99": p99, "max": found.max_ms}
    broken = [
        f"{what} = {measured[what]:.6g} ms > {bound:g} ms"
        for what, bound in bounds.items()
        if bound is not None and measured[what] > bound
    ]
    if broken:
        raise AssertionError(
            f"latency {where}: {'; '.join(broken)} (over {found.delivered} delivered "
            f"messages: p50 = {p50:.6g} ms, p95 = {p95:.6g} ms, p99 = {p99:.6g} ms, "
            f"max = {found.max_ms:.6g} ms; {found.dropped} not delivered)"
        )
    return found


# -- order of events ---------------------------------------------------------------------------
ORDERED_BY: Mapping[str, tuple[str, str]] = {
    "events": ("kind", "t_ns"),
    "messages": ("topic", "t_sent_ns"),
    "navigation": ("event", "t_s"),
    "collisions": ("kind", "t_s"),
}
"""Table -> (the column a step names first, the time column rows are ordered by)."""

Step = str | tuple[str, Mapping[str, Any]]
"""``"done"``, or ``("done", {"detail": "task 0 by robot_3"})``: a value, or a compiled
regular expression searched in the column's text (``re.compile("robot_[12]")``)."""


def assert_order(
    result: RunResult,
    steps: Sequence[Step],
    *,
    table: str = "events",
    key: str | None = None,
    time: str | None = None,
) -> list[float]:
    """Assert that rows matching ``steps`` occur in this order (each after the one before).

    Rows are taken in time order, rows of one instant in the order they were recorded;
    each step matches the first row after the previous step's row.

    ```python
    assert_order(result, [
        ("task", {"source": "task_source"}),
        ("done", {"detail": "task 0 by robot_3"}),
    ])
    assert_order(result, ["/fleet/tasks", "/fleet/claims"], table="messages")
    ```

    Args:
        result: the run.
        steps: what each row must be: the value of ``key`` (an event's ``kind``, a
            message's ``topic``), and optionally other columns' values.
        table: ``events`` (the default), ``messages``, ``navigation``,
            ``collisions``, or any table with ``key`` and ``time`` given.
        key: the column a step names first (default: per table, see :data:`ORDERED_BY`).
        time: the column rows are ordered by (default: per table).

    Returns:
        The time of each matched row (s).

    Raises:
        AssertionError: a step matches no row after the previous step's.
        ValueError: no step, or a column the table does not have.
    """
    if not steps:
        raise ValueError("assert_order needs at least one step")
    default_key, default_time = ORDERED_BY.get(table, (None, None))
    key, time = key or default_key, time or default_time
    if key is None or time is None:
        raise ValueError(f"tables/{table}: give key= and time= (the columns to use)")
    frame = need_table(result, table, "an adapter of the run")
    frame = frame.sort_values(time, kind="stable").reset_index(drop=True)
    times_s = frame[time].to_numpy(dtype=np.float64) / (1e9 if time.endswith("_ns") else 1.0)
    matched: list[float] = []
    last = -1
    for number, step in enumerate(steps, start=1):
        name, where = (step, {}) if isinstance(step, str) else step
        rows = np.flatnonzero(_matches(frame, table, {key: name, **where}))
        after = rows[rows > last]
        if len(after) == 0:
            said = f"step {number} {_shown(step)}"
            steps_before = "step 1" if number == 2 else f"steps 1-{number - 1}"
            before = (
                f" ({steps_before} matched at t = {', '.join(map(_decimal, matched))} s)"
                if matched
                else ""
            )
            if len(rows) == 0:
                raise AssertionError(f"{said}: no row of tables/{table} matches it{before}")
            raise AssertionError(
                f"{said} does not come after step {number - 1}{before}: it matches only "
                f"earlier, at t = {', '.join(map(_decimal, times_s[rows][:LISTED]))} s"
            )
        last = int(after[0])
        matched.append(float(times_s[last]))
    return matched


def _matches(frame: pd.DataFrame, table: str, where: Mapping[str, Any]) -> np.ndarray:
    mask = np.ones(len(frame), dtype=bool)
    for column, value in where.items():
        if column not in frame.columns:
            raise ValueError(
                f"tables/{table} has no column {column!r} (its columns: {', '.join(frame.columns)})"
            )
        if isinstance(value, re.Pattern):
            text = frame[column].astype(str)
            mask &= text.str.contains(value, regex=True).to_numpy(dtype=bool)
        else:
            mask &= (frame[column] == value).to_numpy(dtype=bool)
    return mask


def _shown(step: Step) -> str:
    if isinstance(step, str):
        return repr(step)
    name, where = step
    shown = {k: (v.pattern if isinstance(v, re.Pattern) else v) for k, v in where.items()}
    return f"({name!r}, {shown!r})"


# -- assignment deadlines ----------------------------------------------------------------------
TASKS_WRITER = "the task source: robots.driver = 'tasks'"


def assert_tasks_assigned_within(result: RunResult, deadline_s: float) -> float:
    """Assert that every task was claimed by a robot within ``deadline_s`` of appearing.

    Reads ``tables/tasks`` (``t_created_s``, ``t_assigned_s``). A task never claimed
    fails if the run went on for ``deadline_s`` after it appeared; tasks that appeared
    later are not judged (the run ended too soon to tell).

    Args:
        result: a run with tasks (``robots.driver = "tasks"``).
        deadline_s: the longest wait from a task's creation to its first claim (s).

    Returns:
        The longest wait of a judged task (s).

    Raises:
        AssertionError: a task waited longer, or no task could be judged.
    """
    tasks = need_table(result, "tasks", TASKS_WRITER)
    end_s = float(result.summary["sim_time_s"])
    created = tasks["t_created_s"].to_numpy(dtype=np.float64)
    assigned = tasks["t_assigned_s"].to_numpy(dtype=np.float64)
    waited = np.where(np.isnan(assigned), end_s - created, assigned - created)
    judged = ~np.isnan(assigned) | (end_s - created > deadline_s)
    if not judged.any():
        raise AssertionError(
            f"no task to judge: none was claimed, and none appeared {deadline_s:g} s before "
            f"the run ended at {seconds(end_s)} ({len(tasks)} tasks): run longer"
        )
    late = []
    for row, wait, assigned_s in zip(tasks.itertuples(), waited, assigned, strict=True):
        if wait <= deadline_s:
            continue
        when = (
            f"never claimed by the end at {seconds(end_s)}"
            if math.isnan(assigned_s)
            else f"claimed at {seconds(assigned_s)}, after {seconds(wait)}"
        )
        late.append(f"task {row.task} (appeared at {seconds(row.t_created_s)}, {when})")
    if late:
        raise AssertionError(
            f"{len(late)} of {int(judged.sum())} tasks not claimed within {deadline_s:g} s "
            f"of appearing: {listed(late)}"
        )
    return float(waited[judged].max())


def assert_epochs_decided_within(result: RunResult, deadline_s: float) -> float:
    """Assert that in every epoch each robot's protocol decided within ``deadline_s``.

    Reads ``tables/assignments`` (one row per round of a robot that had not decided): an
    epoch starts at its first round; a robot decides at its first round with
    ``converged``. A robot that never decided fails unless a later epoch (or the end of
    the run) came before the deadline. Central protocols (``hungarian``) and protocols
    that decide at once record no rounds: assert on the tasks instead
    (:func:`assert_tasks_assigned_within`).

    Returns:
        The longest time to decide (s).

    Raises:
        AssertionError: a robot decided later, or never, or no round was recorded.
    """
    rounds = need_table(result, "assignments", "the task assignment: robots.driver = 'tasks'")
    if rounds.empty:
        raise AssertionError(
            "tables/assignments has no rounds: the protocol decided on the base station or "
            "without rounds; assert on the tasks (assert_tasks_assigned_within)"
        )
    end_s = float(result.summary["sim_time_s"])
    first_rounds = rounds.groupby("epoch")["t_s"].min().sort_index()
    starts = {epoch: float(t) for epoch, t in first_rounds.items()}
    ends = dict(zip(starts, [*list(starts.values())[1:], end_s], strict=True))
    slowest, late = 0.0, []
    for (epoch, robot), rows in rounds.groupby(["epoch", "robot"], observed=True, sort=True):
        start = starts[epoch]
        decided = rows.loc[rows["converged"].astype(bool), "t_s"]
        if len(decided):
            took = float(decided.min()) - start
            slowest = max(slowest, took)
            if took > deadline_s:
                late.append(f"epoch {epoch}: {robot} decided after {seconds(took)}")
        elif float(ends[epoch]) - start > deadline_s:
            late.append(
                f"epoch {epoch}: {robot} never decided (epoch started at {seconds(start)}, "
                f"lasted {seconds(float(ends[epoch]) - start)})"
            )
    if late:
        raise AssertionError(
            f"{len(late)} robots' protocols did not decide within {deadline_s:g} s of their "
            f"epoch's first round: {listed(late)}"
        )
    return slowest
