"""Where the robots went: every trajectory on the world, and snapshots at chosen times."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from cosim.plotting.canvas import LEGEND_ROBOTS_MAX, Color, fleet_colors, save_png
from cosim.plotting.fleet import TRAIL_S, WAITING_COLOR, FleetLayer, TaskTimes, fleet_handles
from cosim.plotting.people import PeopleLayer, draw_tracks, people_handles
from cosim.plotting.rundata import RunData
from cosim.plotting.world import SHELF_MUTED, draw_world, world_handles, world_inches

WORLD_IN = 7.5
"""Longer side of the world in the trajectories figure (inches)."""
PANEL_IN = 4.2
"""Longer side of the world in each snapshot panel (inches)."""
LEGEND_IN = 2.0
"""Width kept for a legend outside the axes (inches)."""
TASK_IDS_MAX = 40
"""Task stations are labelled with their task numbers up to this many tasks."""


def trajectories_figure(run: RunData, png_path: Path) -> Path:
    """Draw every robot's trajectory over the world to ``png_path``.

    A colour per robot, its start as a square, its final pose as a disc with a heading tick
    (frame ``map``, m); people and forklifts as thin tracks and at their final place; with
    tasks, every task station as a diamond filled with the colour
    of the robot that completed it (white: not completed), labelled with its task numbers.

    Raises:
        ExportError: naming the path if the file cannot be written.
    """
    track = run.track
    colors = fleet_colors(list(track.robots), run.scenario.physical.robots)
    width, height = world_inches(run.warehouse, WORLD_IN)
    figure = Figure(figsize=(width + LEGEND_IN + 0.8, height + 0.8), layout="constrained")
    ax = figure.add_subplot()
    draw_world(ax, run.warehouse, shelf_color=SHELF_MUTED)
    draw_tracks(ax, run)
    line_width = 1.3 if len(track.robots) <= LEGEND_ROBOTS_MAX else 0.7
    for r, color in enumerate(colors):
        ax.plot(track.x_m[:, r], track.y_m[:, r], color=color, lw=line_width, alpha=0.85)
        start = np.flatnonzero(np.isfinite(track.x_m[:, r]))
        if len(start):
            x0, y0 = track.x_m[start[0], r], track.y_m[start[0], r]
            ax.plot(x0, y0, marker="s", ms=6, mfc="none", mec=color, mew=1.3, zorder=4)
    FleetLayer(ax, run, colors, trail_s=0.0, tasks=False).show(len(track.t_s) - 1)
    PeopleLayer(ax, run).show(float(track.t_s[-1]))
    _stations(ax, run, colors)
    ax.set_title(
        f"{run.title}: trajectories, t = {track.t_s[0]:g} to {track.t_s[-1]:g} s", fontsize=10
    )
    handles = [
        *_robot_lines(run, colors),
        *_marks(run),
        *people_handles(run),
        *world_handles(run.warehouse, shelf_color=SHELF_MUTED),
    ]
    figure.legend(handles=handles, loc="outside right upper", fontsize=8)
    return save_png(figure, png_path)


def snapshots_figure(run: RunData, times_s: Sequence[float], png_path: Path) -> Path:
    """Draw the fleet at each time of ``times_s`` (s), a panel each, to ``png_path``.

    Each panel: the world, every robot as a disc with a heading tick at the pose sample
    nearest the time, its trail over the last :data:`~cosim.plotting.fleet.TRAIL_S`, and the
    open tasks (filled with the holder's colour, a dashed line to it), and the people and
    forklifts at that time. Panels wrap after 3
    (2 for 4 times); times are expected within the run (checked by the caller).

    Raises:
        ExportError: naming the path if the file cannot be written.
    """
    track = run.track
    colors = fleet_colors(list(track.robots), run.scenario.physical.robots)
    count = len(times_s)
    cols = 2 if count == 4 else min(count, 3)
    rows = math.ceil(count / cols)
    width, height = world_inches(run.warehouse, PANEL_IN)
    figure = Figure(
        figsize=(cols * (width + 0.3) + LEGEND_IN + 0.6, rows * (height + 0.45) + 0.5),
        layout="constrained",
    )
    grid = figure.subplots(rows, cols, sharex=True, sharey=True, squeeze=False)
    panels: list[Axes] = list(grid.flat)
    for ax in panels[count:]:
        figure.delaxes(ax)
    for k, (ax, t) in enumerate(zip(panels, times_s, strict=False)):
        draw_world(ax, run.warehouse, shelf_color=SHELF_MUTED, labels=False)
        i = track.index_at(t)
        FleetLayer(ax, run, colors).show(i)
        PeopleLayer(ax, run).show(float(track.t_s[i]))
        ax.set_title(f"t = {track.t_s[i]:.1f} s", fontsize=10)
        if k % cols == 0:
            ax.set_ylabel("y (m, map)")
        if k + cols >= count:  # nothing below it
            ax.set_xlabel("x (m, map)")
            ax.xaxis.set_tick_params(labelbottom=True)
    figure.suptitle(f"{run.title}: snapshots, trails of the last {TRAIL_S:g} s", fontsize=11)
    handles = [
        *fleet_handles(run, colors),
        *people_handles(run),
        *world_handles(run.warehouse, shelf_color=SHELF_MUTED),
    ]
    # beside the first row's last panel: a figure legend would run into the title
    panels[min(cols, count) - 1].legend(
        handles=handles, loc="upper left", bbox_to_anchor=(1.03, 1.0), fontsize=8
    )
    return save_png(figure, png_path)


def default_times(run: RunData, count: int = 4) -> list[float]:
    """``count`` evenly spaced times (s) ending at the last pose, the first after the start."""
    t0, t1 = float(run.track.t_s[0]), float(run.track.t_s[-1])
    return [t0 + (t1 - t0) * (k + 1) / count for k in range(count)]


def _robot_lines(run: RunData, colors: list[Color]) -> list[Line2D]:
    if len(run.track.robots) > LEGEND_ROBOTS_MAX:
        return [Line2D([], [], color="0.4", label=f"{len(colors)} robots, a colour each")]
    return [
        Line2D([], [], color=c, lw=1.3, label=_label(run, name))
        for name, c in zip(run.track.robots, colors, strict=True)
    ]


def _label(run: RunData, robot: str) -> str:
    return f"{robot} (physical)" if robot in run.scenario.physical.robots else robot


def _marks(run: RunData) -> list[Line2D]:
    marks = [
        Line2D([], [], color="0.3", marker="s", mfc="none", lw=0, label="start"),
        Line2D([], [], color="0.3", marker="o", mec="0.1", lw=0, label="end (heading tick)"),
    ]
    if run.tasks is not None:
        marks += [
            Line2D(
                [],
                [],
                color="0.55",
                marker="D",
                mec="0.15",
                lw=0,
                label="task station, done (robot's colour)",
            ),
            Line2D(
                [],
                [],
                color=WAITING_COLOR,
                marker="D",
                mec="0.15",
                lw=0,
                label="task station, not done",
            ),
        ]
    return marks


def _stations(ax: Axes, run: RunData, colors: list[Color]) -> None:
    """Every task station, filled with the colour of the robot that completed its last task."""
    tasks = TaskTimes.of(run)
    if not len(tasks.xy):
        return
    done = np.isfinite(tasks.completed) & (tasks.holder >= 0)
    faces = [colors[h] if d else WAITING_COLOR for h, d in zip(tasks.holder, done, strict=True)]
    ax.scatter(
        x=tasks.xy[:, 0],
        y=tasks.xy[:, 1],
        s=36,
        marker="D",
        c=faces,
        edgecolors="0.15",
        linewidths=0.7,
        zorder=4,
    )
    if len(tasks.xy) > TASK_IDS_MAX or run.tasks is None:
        return
    ids: dict[tuple[float, float], list[str]] = {}
    for (x, y), task in zip(tasks.xy, run.tasks["task"], strict=True):
        ids.setdefault((round(float(x), 2), round(float(y), 2)), []).append(f"{task:g}")
    for (x, y), names in ids.items():
        ax.annotate(
            ",".join(names),
            (x, y),
            xytext=(4, 3),
            textcoords="offset points",
            fontsize=6,
            color="0.15",
            zorder=7,
        )
