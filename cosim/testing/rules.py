"""Behaviour rules of ``cosim check-plugin``: what a group's entries must do in a short run.

Each rule reads the run's tables and returns an :class:`~cosim.testing.verdicts.Outcome`
naming the numbers. The built-ins keep every rule of their group (the project's tests run
``cosim check-plugin`` on each), so a rule a plugin breaks is one cosim's own code keeps.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from cosim.runner.result import RunResult
from cosim.testing.outcomes import assert_no_conflicts
from cosim.testing.timing import assert_tasks_assigned_within, listed, need_table, seconds
from cosim.testing.verdicts import Outcome, fail, ok, skip

Rule = Callable[[RunResult, Any], Outcome]
"""A behaviour rule: (the run, the entry under check) -> its outcome."""

DEADLINE_S = 5.0
"""How long a task may wait for a claim on a network that loses nothing (s): the
built-in protocols take under 1.1 s (``hungarian`` waits for a rebroadcast, 1 s)."""
MIN_TRAVEL_M = 0.5
"""How far every robot must drive in a run in which no robot reached a goal (m)."""
POSE_COLUMNS = ("x_m", "y_m", "yaw_rad", "v_mps", "w_radps")


def coordinated(protocol: Any) -> bool:
    """Whether a protocol's robots can agree before they claim.

    They can when they exchange messages, or when the base station decides. One that
    exchanges nothing (``greedy``) cannot: its robots' first choices may collide, and a
    robot that gives way waits for the next epoch.
    """
    return getattr(protocol, "message", None) is not None or getattr(protocol, "central", False)


def assigns(result: RunResult, protocol: Any) -> Outcome:
    """Every task is claimed within :data:`DEADLINE_S` of appearing.

    Of a protocol whose robots decide alone (see :func:`coordinated`), only that some task
    is.
    """
    try:
        if coordinated(protocol):
            longest = assert_tasks_assigned_within(result, DEADLINE_S)
            return ok(
                "assigns",
                f"every task claimed within {DEADLINE_S:g} s of appearing on a network that "
                f"loses nothing (the longest wait {seconds(longest)})",
            )
        tasks = need_table(result, "tasks", "the task source")
    except AssertionError as error:
        return fail("assigns", f"{error} (on a network that loses nothing)")
    waits = (tasks["t_assigned_s"] - tasks["t_created_s"]).dropna()
    if waits.empty or float(waits.min()) > DEADLINE_S:
        return fail(
            "assigns",
            f"no task of {len(tasks)} claimed within {DEADLINE_S:g} s of appearing (robots "
            "deciding alone must at least claim tasks)",
        )
    return ok(
        "assigns",
        f"{len(waits)} of {len(tasks)} tasks claimed, the first {seconds(float(waits.min()))} "
        "after appearing (it exchanges no messages: every task within "
        f"{DEADLINE_S:g} s is asked only of protocols that coordinate)",
    )


def conflicts(result: RunResult, protocol: Any) -> Outcome:
    """No task claimed by two robots on a network that loses nothing."""
    if not coordinated(protocol):
        count = result.summary.get("conflicts")
        return skip(
            "conflicts",
            f"{count} allowed: it exchanges no messages, so its robots cannot agree before "
            "they claim",
        )
    try:
        assert_no_conflicts(result)
    except AssertionError as error:
        return fail("conflicts", f"{error} on a network that loses nothing")
    return ok("conflicts", "no task claimed by two robots on a network that loses nothing")


def finite(result: RunResult, _entry: Any) -> Outcome:
    """Every robot's pose and speeds stay finite (the commands it was given were)."""
    try:
        poses = need_table(result, "poses", "the poses adapter")
    except AssertionError as error:
        return fail("finite", str(error))
    values = poses[list(POSE_COLUMNS)].to_numpy(dtype=np.float64)
    bad = ~np.isfinite(values).all(axis=1)
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        first = poses.iloc[row]
        said = ", ".join(f"{c} = {first[c]}" for c in POSE_COLUMNS if not np.isfinite(first[c]))
        return fail(
            "finite",
            f"{first['robot']}'s {said} at t = {seconds(float(first['t_s']))} "
            f"({int(bad.sum())} of {len(poses)} pose samples not finite)",
        )
    robots = poses["robot"].nunique()
    return ok("finite", f"{len(poses)} pose samples of {robots} robots, all finite")


def moves(result: RunResult, _entry: Any) -> Outcome:
    """Robots reach goals, or at least every robot drives :data:`MIN_TRAVEL_M`."""
    try:
        poses = need_table(result, "poses", "the poses adapter")
    except AssertionError as error:
        return fail("moves", str(error))
    driven = {}
    for robot, rows in poses.sort_values("t_s", kind="stable").groupby("robot", observed=True):
        steps = np.hypot(np.diff(rows["x_m"].to_numpy()), np.diff(rows["y_m"].to_numpy()))
        driven[str(robot)] = float(np.nansum(steps))
    arrivals = int(result.summary.get("arrivals") or 0)
    said = ", ".join(f"{robot} {metres:.3g} m" for robot, metres in driven.items())
    still = [robot for robot, metres in driven.items() if metres < MIN_TRAVEL_M]
    took = seconds(float(result.summary["sim_time_s"]))
    if arrivals == 0 and (still or not driven):
        return fail(
            "moves",
            f"no goal reached in {took}, and {len(still)} of {len(driven)} robots drove less "
            f"than {MIN_TRAVEL_M:g} m ({said or 'no pose recorded'})",
        )
    return ok("moves", f"{arrivals} goals reached in {took}; driven: {said}")


def delivers(result: RunResult, _entry: Any) -> Outcome:
    """Every message between two hosts is delivered, never before it was sent.

    The trial's network loses nothing: a message not delivered is the backend's doing.
    """
    try:
        messages = need_table(result, "messages", "the recorder")
    except AssertionError as error:
        return fail("delivers", str(error))
    remote = messages[messages["src_host"].astype(str) != messages["dst_host"].astype(str)]
    if remote.empty:
        return fail("delivers", "no message went from one host to another")
    status = remote["status"].astype(str)
    lost = remote[status != "delivered"]
    if len(lost):
        counts = ", ".join(
            f"{s} {n}" for s, n in status[status != "delivered"].value_counts().items()
        )
        said = [
            f"{row.topic} {row.src_host} -> {row.dst_host} sent at t = {seconds(row.t_sent_s)}"
            for row in lost.itertuples()
        ]
        return fail(
            "delivers",
            f"{len(lost)} of {len(remote)} messages between hosts not delivered on a network "
            f"that loses nothing ({counts}): {listed(said)}",
        )
    delivered = remote
    sent = delivered["t_sent_ns"].to_numpy(dtype=np.int64)
    received = delivered["t_recv_ns"].to_numpy(dtype=np.int64)
    early = np.flatnonzero(received < sent)
    if len(early):
        row = delivered.iloc[int(early[0])]
        return fail(
            "delivers",
            f"{len(early)} messages delivered before they were sent: the first {row['topic']} "
            f"{row['src_host']} -> {row['dst_host']} sent at {row['t_sent_ns']} ns, "
            f"delivered at {row['t_recv_ns']} ns",
        )
    slowest = float((received - sent).max()) / 1e6
    return ok(
        "delivers",
        f"all {len(remote)} messages between hosts delivered, none before it was sent "
        f"(latency up to {slowest:.6g} ms)",
    )


def tracks(result: RunResult, _entry: Any) -> Outcome:
    """Poses of the source reach the robots' software (``mocap_poses``)."""
    taken = result.summary.get("mocap_poses")
    if not taken:
        return fail(
            "tracks",
            f"no pose of the source reached the robots' software (mocap_poses = {taken!r})",
        )
    rejected = result.summary.get("mocap_rejected_jumps", 0)
    return ok("tracks", f"{taken} poses taken in ({rejected} refused as jumps)")
