"""Where the robots went: every trajectory on the world, and snapshots at chosen times."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from cosim.plotting.canvas import LEGEND_ROBOTS_MAX, Color, fleet_colors, save_png
from cosim.plotting.fleet import TRAIL_S, WAITING_COLOR, FleetLayer, TaskTimes, fleet_handles
from cosim.plotting.goals import GoalLayer, draw_goals, goal_handles
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
    (frame ``map``, m); in a run without tasks, every goal sent (stars, numbered in the order
    sent); people and forklifts as thin tracks and at their final place; with
    tasks, every task station once, as a diamond filled with the colour of the robot that
    completed its last completed task (white: none of its tasks completed), labelled with
    its task numbers (those not completed in parentheses).

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
    draw_goals(ax, run, colors)
    ax.set_title(
        f"{run.title}: trajectories, t = {track.t_s[0]:g} to {track.t_s[-1]:g} s", fontsize=10
    )
    handles = [
        *_robot_lines(run, colors),
        *_marks(run),
        *goal_handles(run),
        *people_handles(run),
        *world_handles(run.warehouse, shelf_color=SHELF_MUTED),
    ]
    figure.legend(handles=handles, loc="outside right upper", fontsize=8)
    return save_png(figure, png_path)


def snapshots_figure(run: RunData, times_s: Sequence[float], png_path: Path) -> Path:
    """Draw the fleet at each time of ``times_s`` (s), a panel each, to ``png_path``.

    Each panel: the world, every robot as a disc with a heading tick at the pose sample
    nearest the time, its trail over the last :data:`~cosim.plotting.fleet.TRAIL_S`, and the
    open tasks (filled with the colour of the robot holding it then, a dashed line to it;
    white: released or not yet claimed), each robot's current goal in a run without tasks
    (a star, a dotted line to it), and the people and forklifts at that time. Panels wrap after 3
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
        fleet = FleetLayer(ax, run, colors)
        fleet.show(i)
        GoalLayer(ax, run, colors).show(float(track.t_s[i]), track.x_m[i], track.y_m[i])
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
        *goal_handles(run),
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
                label="task station: robot that did its last task",
            ),
            Line2D(
                [],
                [],
                color=WAITING_COLOR,
                marker="D",
                mec="0.15",
                lw=0,
                label="task station, none done; (n): task n not done",
            ),
        ]
    return marks


def _stations(ax: Axes, run: RunData, colors: list[Color]) -> None:
    """Every task station once, filled and labelled as :func:`station_summary` says.

    Filled with the colour of the robot that completed its last completed task (white:
    none of its tasks completed).
    """
    tasks = TaskTimes.of(run)
    if not len(tasks.xy) or run.tasks is None:
        return
    stations = station_summary(tasks, [f"{k:g}" for k in run.tasks["task"]])
    faces = [colors[s.robot] if s.robot >= 0 else WAITING_COLOR for s in stations]
    xy = np.array([s.xy for s in stations])
    ax.scatter(
        x=xy[:, 0], y=xy[:, 1], s=36, marker="D", c=faces, edgecolors="0.15", linewidths=0.7,
        zorder=4,
    )  # fmt: skip
    if len(tasks.xy) > TASK_IDS_MAX:
        return
    for station in stations:
        ax.annotate(
            station.label,
            station.xy,
            xytext=(4, 3),
            textcoords="offset points",
            fontsize=6,
            color="0.15",
            zorder=7,
        )


@dataclass(frozen=True)
class Station:
    """A task station and its tasks over a run.

    Attributes:
        xy: the station (m, ``map``).
        robot: fleet index of the robot that completed its last completed task, -1: none.
        done: tasks completed there.
        label: its task numbers in creation order, those not completed in parentheses.
    """

    xy: tuple[float, float]
    robot: int
    done: int
    label: str


def station_summary(tasks: TaskTimes, names: list[str]) -> list[Station]:
    """The stations of ``tasks`` (``names``: each task's number as text), in first use order."""
    rows: dict[tuple[float, float], list[int]] = {}
    for k, (x, y) in enumerate(tasks.xy):
        rows.setdefault((round(float(x), 3), round(float(y), 3)), []).append(k)
    stations = []
    for ks in rows.values():
        done = [k for k in ks if np.isfinite(tasks.completed[k])]
        last = max(done, key=lambda k: float(tasks.completed[k])) if done else -1
        robot = int(tasks.served_by[last]) if done else -1
        label = ",".join(names[k] if k in done else f"({names[k]})" for k in ks)
        x, y = tasks.xy[ks[0]]
        stations.append(Station((float(x), float(y)), robot, len(done), label))
    return stations
