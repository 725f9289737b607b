"""Who served which task when: a lane per robot, a bar per task (travel, then service)."""

from __future__ import annotations

from collections.abc import Hashable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from cosim.plotting.canvas import Color, run_colors, save_png
from cosim.plotting.rundata import RunData

BAR_HEIGHT = 0.5
"""Height of a travel or service bar (lanes are 1 apart)."""
WAIT_OFFSET = 0.36
"""How far below its lane's centre a task's wait (created to assigned) is drawn."""
LANE_IN = 0.34
"""Height of a lane (inches)."""
UNHELD = "no robot"
"""The lane of tasks no robot held by the end of the run."""


def timeline_figure(run: RunData, png_path: Path) -> Path:
    """Draw the task timeline of a run (which has a tasks table) to ``png_path``.

    A lane per robot (fleet order, top to bottom, labelled in the robot's colour, the
    colour it has in every figure of the run) and one for tasks no robot held. Per task:
    a dotted line from its creation (tick) to its first claim, then a bar per holding
    (``RunData.holds``) in the holding robot's lane: pale while travelling (claim to
    service start), full during the service (started to completed); a holding given up
    (released, or given way) ends in a cross; bars still open at the end of the run are
    hatched and run to the last pose. Times in s from the start of the run.

    Raises:
        ExportError: naming the path if the file cannot be written.
    """
    tasks, holds = run.tasks, run.holds
    if tasks is None or holds is None:
        raise ValueError("timeline_figure needs a run with tasks")  # callers check first
    robots = list(run.track.robots)
    colors = run_colors(run)
    unheld = ~tasks["task"].isin(holds["task"])
    lanes = robots + ([UNHELD] if unheld.any() else [])
    lane_of = {name: i for i, name in enumerate(lanes)}
    end_s = float(run.track.t_s[-1])
    figure = Figure(figsize=(10.0, 1.4 + LANE_IN * len(lanes)), layout="constrained")
    ax = figure.add_subplot()
    by_task = {float(str(k)): rows for k, rows in holds.groupby("task", sort=False)}
    for task in tasks.to_dict("records"):
        rows = by_task.get(float(task["task"]))
        if rows is None:
            _wait(ax, task, float(lane_of[UNHELD]), end_s)
            continue
        first = rows.iloc[0]
        _wait(ax, task, lane_of[str(first["robot"])] + WAIT_OFFSET, float(first["t_from_s"]))
        for hold in rows.to_dict("records"):
            y = lane_of.get(str(hold["robot"]))
            if y is not None:
                _hold_bars(ax, task, hold, y, colors[y] if y < len(robots) else "0.6", end_s)
    ax.set_yticks(range(len(lanes)), [_lane_label(run, n) for n in lanes])
    for label, name in zip(ax.get_yticklabels(), lanes, strict=True):
        label.set_fontsize(8 if len(lanes) <= 20 else 5)
        if name in lane_of and lane_of[name] < len(robots):
            label.set_color(colors[lane_of[name]])
            label.set_fontweight("bold")
    ax.set_ylim(len(lanes) - 0.4, -0.6)  # first robot on top
    ax.set_xlim(0.0, max(end_s, float(np.nanmax(tasks["t_created_s"]))) * 1.01)
    ax.set_xlabel("time (s)")
    ax.grid(True, axis="x", alpha=0.3)
    done = int(np.isfinite(tasks["t_completed_s"]).sum())
    given_up = int((holds["end"] == "released").sum())
    ax.set_title(
        f"{run.title}: tasks, {done} of {len(tasks)} completed, {given_up} claims given up",
        fontsize=10,
    )
    figure.legend(handles=_handles(), loc="outside right upper", fontsize=8)
    return save_png(figure, png_path)


def _lane_label(run: RunData, name: str) -> str:
    return f"{name} (physical)" if name in run.scenario.physical.robots else name


def _wait(ax: Axes, task: Mapping[Hashable, Any], y: float, until_s: float) -> None:
    """The wait of a task, from its creation (a tick) to ``until_s`` (its first claim)."""
    created = float(task["t_created_s"])
    ax.plot([created, until_s], [y] * 2, ls=":", color="0.45", lw=1.0)
    ax.plot([created], [y], marker="|", ms=6, color="0.3")


def _hold_bars(
    ax: Axes,
    task: Mapping[Hashable, Any],
    hold: Mapping[Hashable, Any],
    y: int,
    color: Color | str,
    end_s: float,
) -> None:
    """The bars of one holding: travel, then (if this holding served it) the service."""
    start, until = float(hold["t_from_s"]), float(hold["t_to_s"])
    released = hold["end"] == "released"
    started, completed = float(task["t_started_s"]), float(task["t_completed_s"])
    serving = not released and np.isfinite(started)
    travel_end = started if serving else (until if np.isfinite(until) else end_s)
    _bar(ax, y, start, travel_end, color, 0.35, open_end=not released and not serving)
    if serving:
        service_end = completed if np.isfinite(completed) else end_s
        _bar(ax, y, started, service_end, color, 0.95, open_end=not np.isfinite(completed))
    if released:
        ax.plot([until], [y], marker="x", ms=6, mew=1.4, color="0.1", zorder=5)
    ax.annotate(
        f"{float(task['task']):g}",
        (start, y - BAR_HEIGHT / 2),
        xytext=(1, 1),
        textcoords="offset points",
        fontsize=6,
        va="bottom",
        color="0.1",
    )


def _bar(
    ax: Axes, y: int, start: float, end: float, color: Color | str, alpha: float, *, open_end: bool
) -> None:
    ax.barh(
        y,
        max(end - start, 0.0),
        left=start,
        height=BAR_HEIGHT,
        color=color,
        alpha=alpha,
        hatch="///" if open_end else None,
        edgecolor="0.2",
        linewidth=0.4,
    )


def _handles() -> list[Line2D | Patch]:
    return [
        Line2D([], [], ls=":", color="0.45", marker="|", label="waiting (created to assigned)"),
        Patch(facecolor="0.6", alpha=0.35, edgecolor="0.2", label="travel (assigned to started)"),
        Patch(facecolor="0.6", edgecolor="0.2", label="service (started to completed)"),
        Patch(facecolor="white", hatch="///", edgecolor="0.2", label="not finished at the end"),
        Line2D([], [], marker="x", mew=1.4, color="0.1", lw=0, label="claim given up (released)"),
    ]
