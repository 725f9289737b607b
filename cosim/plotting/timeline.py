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

from cosim.plotting.canvas import Color, robot_colors, save_png
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

    A lane per robot (fleet order, top to bottom) and one for tasks no robot held. Per
    task, in its holder's lane: a dotted line from its creation (tick) to the assignment,
    a pale bar for the travel (assigned to started), a full bar for the service (started to
    completed), the task number at the bar's start; bars still open at the end of the run
    are hatched and run to the last pose. Times in s from the start of the run.

    Raises:
        ExportError: naming the path if the file cannot be written.
    """
    tasks = run.tasks
    if tasks is None:
        raise ValueError("timeline_figure needs a run with tasks")  # callers check first
    robots = list(run.track.robots)
    colors = robot_colors(len(robots))
    unheld = tasks["holder"] == ""
    lanes = robots + ([UNHELD] if unheld.any() else [])
    end_s = float(run.track.t_s[-1])
    figure = Figure(figsize=(10.0, 1.4 + LANE_IN * len(lanes)), layout="constrained")
    ax = figure.add_subplot()
    lane_of = {name: i for i, name in enumerate(lanes)}
    for task in tasks.to_dict("records"):
        holder = str(task["holder"]) or UNHELD
        y = lane_of[holder]
        color: Color | str = colors[y] if holder != UNHELD else "0.6"
        _task_bars(ax, task, y, color, end_s)
    ax.set_yticks(range(len(lanes)), lanes, fontsize=8 if len(lanes) <= 20 else 5)
    ax.set_ylim(len(lanes) - 0.4, -0.6)  # first robot on top
    ax.set_xlim(0.0, max(end_s, float(np.nanmax(tasks["t_created_s"]))) * 1.01)
    ax.set_xlabel("time (s)")
    ax.grid(True, axis="x", alpha=0.3)
    done = int(np.isfinite(tasks["t_completed_s"]).sum())
    ax.set_title(f"{run.title}: tasks, {done} of {len(tasks)} completed", fontsize=10)
    figure.legend(handles=_handles(), loc="outside right upper", fontsize=8)
    return save_png(figure, png_path)


def _task_bars(
    ax: Axes, task: Mapping[Hashable, Any], y: int, color: Color | str, end_s: float
) -> None:
    created, assigned, started, completed = (
        float(task[c]) for c in ("t_created_s", "t_assigned_s", "t_started_s", "t_completed_s")
    )
    # a task nobody took is all wait: on the lane's centre line, not under bars
    wait_y = y + WAIT_OFFSET if np.isfinite(assigned) else float(y)
    wait_end = assigned if np.isfinite(assigned) else end_s
    ax.plot([created, wait_end], [wait_y] * 2, ls=":", color="0.45", lw=1.0)
    ax.plot([created], [wait_y], marker="|", ms=6, color="0.3")
    if np.isfinite(assigned):
        travel_end = started if np.isfinite(started) else end_s
        _bar(ax, y, assigned, travel_end, color, 0.35, open_end=not np.isfinite(started))
    if np.isfinite(started):
        service_end = completed if np.isfinite(completed) else end_s
        _bar(ax, y, started, service_end, color, 0.95, open_end=not np.isfinite(completed))
    first = assigned if np.isfinite(assigned) else created
    ax.annotate(
        f"{float(task['task']):g}",
        (first, y - BAR_HEIGHT / 2 if np.isfinite(assigned) else wait_y),
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
    ]
