"""Assertions on a run's outcome: no collisions, no conflicts, the same run twice.

Like :mod:`cosim.testing.timing`, each raises :class:`AssertionError` naming what broke
the rule (which robot hit what and when, which task two robots claimed), and none passes
on a run that could not have broken it (a run without the collisions adapter is no proof
of no collisions).
"""

from __future__ import annotations

import json
from collections.abc import Collection

import pandas as pd

from cosim.runner.result import RunResult
from cosim.studies.worker import VOLATILE_METRICS
from cosim.testing.timing import TASKS_WRITER, listed, need_table, seconds

VOLATILE = frozenset({*VOLATILE_METRICS, "max_lateness_ms", "p99_lateness_ms", "late_batches"})
"""Summary entries of the machine, not of the scenario and seed (wall clock, versions)."""


def assert_no_collisions(result: RunResult, *, kinds: Collection[str] | None = None) -> None:
    """Assert that no robot touched anything (``tables/collisions``).

    Args:
        result: a run with the ``collisions`` adapter (the ``navigation`` and ``tasks``
            drivers run it; otherwise ``scenario.adapters = ["collisions"]``).
        kinds: only contacts with these (``{"robot"}``: robots with robots; ``wall``,
            ``shelf``, ``person``, ``forklift``); default: any.

    Raises:
        AssertionError: listing the first contacts (robot, what, when, at what speed).
    """
    contacts = need_table(
        result, "collisions", 'the collisions adapter: scenario.adapters = ["collisions"]'
    )
    if kinds is not None:
        contacts = contacts[contacts["kind"].astype(str).isin(set(kinds))]
    if contacts.empty:
        return
    said = [
        f"{row.robot} hit {row.other} ({row.kind}) at t = {seconds(row.t_s)} at "
        f"{row.speed_mps:.3g} m/s"
        for row in contacts.sort_values("t_s", kind="stable").itertuples()
    ]
    what = f" with a {' or '.join(sorted(kinds))}" if kinds is not None else ""
    raise AssertionError(f"{len(said)} collisions{what}: {listed(said)}")


def assert_no_conflicts(result: RunResult) -> None:
    """Assert that no task was claimed by two robots at once.

    The task source counts a conflict whenever a robot claims a task another robot holds
    (``summary["conflicts"]``); each is an event ``conflict`` of ``task_source`` saying
    which claim lost. A protocol whose robots agree before they claim has none on a
    network that loses nothing.

    Raises:
        AssertionError: listing the conflicts (task, robot, outcome, when).
    """
    if "conflicts" not in result.summary:
        raise AssertionError(
            f"the run has no task source (written by {TASKS_WRITER}): no claims to judge"
        )
    count = int(result.summary["conflicts"])
    if count == 0:
        return
    events = need_table(result, "events", "the recorder")
    rows = events[
        (events["source"].astype(str) == "task_source") & (events["kind"].astype(str) == "conflict")
    ]
    said = [f"{row.detail} at t = {seconds(row.t_s)}" for row in rows.itertuples()]
    raise AssertionError(f"{count} conflicts (a task claimed by two robots): {listed(said)}")


def assert_same_run(first: RunResult, second: RunResult) -> None:
    """Assert that two runs gave the same tables and summary (but for wall-clock figures).

    Two runs of one scenario with one seed must: a difference names the table, its
    first differing column and row, or the summary keys.

    Raises:
        AssertionError: the first difference.
    """
    ours, theirs = first.deterministic_tables(), second.deterministic_tables()
    if ours.keys() != theirs.keys():
        raise AssertionError(
            f"the runs wrote different tables: {sorted(ours)} and {sorted(theirs)}"
        )
    for name, frame in ours.items():
        other = theirs[name]
        if frame.shape != other.shape:
            raise AssertionError(f"tables/{name}: {frame.shape} rows x columns, then {other.shape}")
        try:
            pd.testing.assert_frame_equal(frame, other)
        except AssertionError as error:
            first_line = str(error).strip().splitlines()[0]
            raise AssertionError(f"tables/{name} differs: {first_line}") from None
    mine = {k: v for k, v in first.summary.items() if k not in VOLATILE}
    other_summary = {k: v for k, v in second.summary.items() if k not in VOLATILE}
    changed = sorted(
        k
        for k in mine.keys() | other_summary.keys()
        if _json(mine.get(k)) != _json(other_summary.get(k))
    )
    if changed:
        shown = [f"{k}: {mine.get(k)!r} then {other_summary.get(k)!r}" for k in changed]
        raise AssertionError(f"the summaries differ: {listed(shown)}")


def _json(value: object) -> str:
    """A value as JSON, so that NaN equals NaN (``json.dumps`` writes both alike)."""
    return json.dumps(value, sort_keys=True, default=repr)
