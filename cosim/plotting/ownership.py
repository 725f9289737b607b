"""Who held which task when, from the task's life: claimed, released or given way, served.

The tasks table names only the robot that served a task (``robot``) and when a robot first
claimed it (``t_assigned_s``); a claim given up in between is an event whose source is the
robot (``release``: the robot gave the task up, e.g. stuck; ``conflict``: it gave way to a
better claim), each naming the task (``task N: ...``). The task source writes ``conflict``
events too (source ``task_source``, ``task N: robot_3 replaced`` or ``... rejected``): how
it settled a claim on a task another robot held, which no robot gave up by itself; a
robot that lost gives way when it hears the better claim, in a ``conflict`` of its own. A
claim shows in the navigation table as a goal sent to the task's station. From these, each
task's holdings: the robots that released it, in order, each from its claim to its
release, then the robot that served it (or, if none did, the robot sent to its station
right after the last release or the first claim) up to the completion, or to the end of
the run if the task was still open.
"""

from __future__ import annotations

import re
from collections.abc import Collection

import numpy as np
import pandas as pd

STATION_TOLERANCE_M = 1e-6
"""A navigation goal this close to a task station is a goal to that station (m)."""
CLAIM_WINDOW_S = 5.0
"""A goal to a task's station counts as the claim of an unserved task only this close to
the claim or release time (s): later goals to a shared station serve other tasks."""
HOLD_COLUMNS = ("task", "robot", "t_from_s", "t_to_s", "end")
GIVE_UP_KINDS = ("release", "conflict")
"""Event kinds by which a robot gives its task up, when the event's source is that robot."""
_TASK_ID = re.compile(r"task (\d+)")


def task_holds(
    tasks: pd.DataFrame,
    navigation: pd.DataFrame | None,
    events: pd.DataFrame | None,
    *,
    robots: Collection[str],
) -> pd.DataFrame:
    """Every holding of a task by a robot (columns :data:`HOLD_COLUMNS`).

    Args:
        tasks: the tasks table (``task``, ``x_m``, ``y_m``, ``t_created_s``,
            ``t_assigned_s``, ``robot`` (``""``: none served it), ``t_started_s``,
            ``t_completed_s``; times in s).
        navigation: the navigation table (``t_s``, ``robot``, ``event``, ``goal_x_m``,
            ``goal_y_m``), or None.
        events: the events table (``t_s``, ``source``, ``kind``, ``detail``), or None.
        robots: the fleet's names: only their own events give a task up.

    Returns:
        A row per holding: ``task``; ``robot``; ``t_from_s`` (claim, s); ``t_to_s``
        (release or completion, s; NaN: held to the end of the run); ``end``
        (``released``, ``completed`` or ``open``). A task never claimed has no row.
    """
    goals = _goals(navigation)
    gives = _give_ups(events, robots)
    rows: list[tuple[float, str, float, float, str]] = []
    for task in tasks.to_dict("records"):
        k = float(task["task"])
        assigned = float(task["t_assigned_s"])
        if not np.isfinite(assigned):
            continue
        station = (float(task["x_m"]), float(task["y_m"]))
        created = float(task["t_created_s"])
        started, completed = float(task["t_started_s"]), float(task["t_completed_s"])
        released = gives.get(int(k), [])
        start = assigned
        for i, (t_r, robot) in enumerate(released):
            if i > 0:
                start = _claim(goals, station, robot, released[i - 1][0], t_r, start)
            rows.append((k, robot, start, t_r, "released"))
            start = t_r
        served = str(task["robot"])
        last = released[-1][0] if released else created
        if served:
            upto = started if np.isfinite(started) else np.inf
            begin = _claim(goals, station, served, last, upto, start) if released else assigned
        else:
            anchor = released[-1][0] if released else assigned
            found = _nearest(goals, station, max(last, created), anchor)
            if found is None:
                continue
            served, begin = found[0], found[1] if released else assigned
        end = "completed" if np.isfinite(completed) else "open"
        rows.append((k, served, begin, completed if np.isfinite(completed) else np.nan, end))
    frame = pd.DataFrame(rows, columns=list(HOLD_COLUMNS))
    return frame.astype({"task": "float64", "robot": str, "t_from_s": "float64"})


def holder_at(holds: pd.DataFrame, t_s: float) -> dict[float, str]:
    """The robot holding each task at ``t_s`` (s), by task id (tasks held by none left out)."""
    to = holds["t_to_s"].fillna(np.inf)
    now = holds[(holds["t_from_s"] <= t_s) & (t_s < to)]
    return dict(zip(now["task"].astype(float), now["robot"].astype(str), strict=True))


def _goals(navigation: pd.DataFrame | None) -> pd.DataFrame:
    if navigation is None:
        return pd.DataFrame({"t_s": [], "robot": [], "goal_x_m": [], "goal_y_m": []})
    return navigation[navigation["event"] == "goal"]


def _give_ups(
    events: pd.DataFrame | None, robots: Collection[str]
) -> dict[int, list[tuple[float, str]]]:
    """Per task id: (time s, robot) of each release or give-way by a robot, in time order."""
    out: dict[int, list[tuple[float, str]]] = {}
    if events is None:
        return out
    by_robot = events["source"].astype(str).isin(list(robots))
    given = events[by_robot & events["kind"].isin(GIVE_UP_KINDS)].sort_values("t_s", kind="stable")
    for t_s, source, detail in zip(given["t_s"], given["source"], given["detail"], strict=True):
        match = _TASK_ID.match(str(detail))
        if match:
            out.setdefault(int(match.group(1)), []).append((float(t_s), str(source)))
    return out


def _at_station(goals: pd.DataFrame, station: tuple[float, float]) -> pd.DataFrame:
    x, y = station
    near = (goals["goal_x_m"] - x).abs() + (goals["goal_y_m"] - y).abs() <= STATION_TOLERANCE_M
    return goals[near]


def _claim(
    goals: pd.DataFrame,
    station: tuple[float, float],
    robot: str,
    after_s: float,
    before_s: float,
    default_s: float,
) -> float:
    """When ``robot`` claimed the task: its last goal to the station in the interval."""
    sent = _at_station(goals, station)
    sent = sent[(sent["robot"] == robot) & (sent["t_s"] >= after_s) & (sent["t_s"] <= before_s)]
    return float(sent["t_s"].max()) if len(sent) else max(default_s, after_s)


def _nearest(
    goals: pd.DataFrame, station: tuple[float, float], after_s: float, anchor_s: float
) -> tuple[str, float] | None:
    """The robot sent to the station nearest ``anchor_s`` (within the claim window)."""
    sent = _at_station(goals, station)
    sent = sent[(sent["t_s"] >= after_s) & ((sent["t_s"] - anchor_s).abs() <= CLAIM_WINDOW_S)]
    if not len(sent):
        return None
    best = int(np.argmin(np.abs(sent["t_s"].to_numpy(np.float64) - anchor_s)))
    return str(sent["robot"].iloc[best]), float(sent["t_s"].iloc[best])
