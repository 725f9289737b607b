"""The fleet at one instant on a world axes: robots, their recent trails, open tasks.

One :class:`FleetLayer` per axes; :meth:`FleetLayer.show` moves it to any pose sample, so the
same drawing serves the snapshot panels and every frame of the animation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.collections import EllipseCollection, LineCollection, PathCollection
from matplotlib.lines import Line2D
from matplotlib.text import Text

from cosim.plotting.canvas import LEGEND_ROBOTS_MAX, Color, short_label
from cosim.plotting.rundata import RunData
from models.arrays import BoolArray, FloatArray, IntArray

TRAIL_S = 10.0
"""Length of the trail drawn behind each robot (s)."""
WAITING_COLOR = "white"
"""Face of a task no robot holds yet."""


@dataclass(frozen=True)
class TaskTimes:
    """The tasks of a run and who held them when, as arrays (times in s; NaN: never).

    Attributes:
        xy: (k, 2) task stations in ``map`` (m).
        created: (k,) creation times (s).
        completed: (k,) completion times (s).
        served_by: (k,) fleet index of the robot that served the task, -1 for none.
        hold_task: (h,) task row of each holding (``RunData.holds``).
        hold_robot: (h,) fleet index of the holding robot.
        hold_from: (h,) start of each holding (s).
        hold_to: (h,) its end (s; inf: held to the end of the run).
    """

    xy: FloatArray
    created: FloatArray
    completed: FloatArray
    served_by: IntArray
    hold_task: IntArray
    hold_robot: IntArray
    hold_from: FloatArray
    hold_to: FloatArray

    @classmethod
    def of(cls, run: RunData) -> TaskTimes:
        """The run's tasks (none when it has no tasks table)."""
        tasks, holds = run.tasks, run.holds
        if tasks is None:
            return cls.of_none()
        index = {name: i for i, name in enumerate(run.track.robots)}
        row = {float(k): i for i, k in enumerate(tasks["task"])}
        if holds is None or holds.empty:
            holds = pd.DataFrame({"task": [], "robot": [], "t_from_s": [], "t_to_s": []})
        known = [
            float(k) in row and str(r) in index
            for k, r in zip(holds["task"], holds["robot"], strict=True)
        ]
        holds = holds[np.array(known, dtype=bool)] if len(holds) else holds
        return cls(
            xy=tasks[["x_m", "y_m"]].to_numpy(np.float64),
            created=tasks["t_created_s"].to_numpy(np.float64),
            completed=tasks["t_completed_s"].to_numpy(np.float64),
            served_by=np.array([index.get(str(r), -1) for r in tasks["robot"]], dtype=np.int64),
            hold_task=np.array([row[float(k)] for k in holds["task"]], dtype=np.int64),
            hold_robot=np.array([index[str(r)] for r in holds["robot"]], dtype=np.int64),
            hold_from=holds["t_from_s"].to_numpy(np.float64),
            hold_to=np.nan_to_num(holds["t_to_s"].to_numpy(np.float64), nan=np.inf),
        )

    @classmethod
    def of_none(cls) -> TaskTimes:
        """No task."""
        empty = np.zeros(0)
        none = np.zeros(0, dtype=np.int64)
        return cls(np.zeros((0, 2)), empty, empty, none, none, none, empty, empty)

    def open_at(self, t_s: float) -> BoolArray:
        """Tasks created and not completed at ``t_s`` (NaN compares false: never completed)."""
        done: BoolArray = self.completed <= t_s
        return (self.created <= t_s) & ~done

    def holders_at(self, t_s: float) -> IntArray:
        """(k,) fleet index of the robot holding each task at ``t_s`` (s), -1 for none.

        A task released is held by no one until another robot claims it.
        """
        holder: IntArray = np.full(len(self.xy), -1, dtype=np.int64)
        now = (self.hold_from <= t_s) & (t_s < self.hold_to)
        holder[self.hold_task[now]] = self.hold_robot[now]
        return holder


class FleetLayer:
    """Robots as discs with a heading tick, trails of the last ``trail_s``, open tasks."""

    def __init__(
        self,
        ax: Axes,
        run: RunData,
        colors: list[Color],
        *,
        trail_s: float = TRAIL_S,
        tasks: bool = True,
        label_robots: bool | None = None,
    ) -> None:
        """Create the (empty) artists on ``ax``.

        Args:
            ax: a world axes (frame ``map``, m).
            run: the run.
            colors: a colour per robot, in fleet order.
            trail_s: trail length (s).
            tasks: draw the open tasks and who holds them.
            label_robots: write each robot's number beside it; default: for fleets too
                large for a legend entry per robot.
        """
        self.track = run.track
        self.colors = colors
        self.trail_s = trail_s
        self.tasks = TaskTimes.of(run) if tasks else TaskTimes.of_none()
        self.radius_m = run.scenario.robots.radius_m
        count = len(self.track.robots)
        diameter = np.full(count, 2 * self.radius_m)
        # task links under robots, robots over trails
        self.trails = LineCollection([], colors=colors, linewidths=1.3, alpha=0.85, zorder=3)
        self.links = LineCollection([], linestyles="--", linewidths=0.9, zorder=3)
        self.stations: PathCollection = ax.scatter(
            [], [], s=36, marker="D", edgecolors="0.15", linewidths=0.7, zorder=4
        )
        self.discs = EllipseCollection(
            diameter,
            diameter,
            np.zeros(count),
            units="xy",
            offsets=np.zeros((count, 2)),
            offset_transform=ax.transData,
            facecolors=colors,
            edgecolors="0.1",
            linewidths=0.6,
            zorder=5,
        )
        self.headings = LineCollection([], colors="0.05", linewidths=1.0, zorder=6)
        for artist in (self.trails, self.links, self.discs, self.headings):
            ax.add_collection(artist)
        if label_robots is None:
            label_robots = count > LEGEND_ROBOTS_MAX
        self.labels: list[Text] = []
        if label_robots:
            self.labels = [
                ax.text(0, 0, short_label(name), fontsize=4.5, ha="left", va="bottom", zorder=7)
                for name in self.track.robots
            ]

    def show(self, i: int) -> list[Artist]:
        """Move every artist to pose sample ``i``; return the artists (to redraw)."""
        track = self.track
        x, y, yaw = track.x_m[i], track.y_m[i], track.yaw_rad[i]
        self.discs.set_offsets(np.column_stack([x, y]))
        tip = np.column_stack([x + self.radius_m * np.cos(yaw), y + self.radius_m * np.sin(yaw)])
        self.headings.set_segments(list(np.stack([np.column_stack([x, y]), tip], axis=1)))
        first = track.since(i, self.trail_s)
        trails = []
        for r in range(len(track.robots)):
            points = np.column_stack([track.x_m[first : i + 1, r], track.y_m[first : i + 1, r]])
            trails.append(points[np.isfinite(points).all(axis=1)])
        self.trails.set_segments(trails)
        if self.labels:
            for label, px, py in zip(self.labels, x, y, strict=True):
                label.set_position((px + self.radius_m, py + self.radius_m))
        self._show_tasks(float(track.t_s[i]), x, y)
        return [self.trails, self.links, self.stations, self.discs, self.headings, *self.labels]

    def _show_tasks(self, t_s: float, x: FloatArray, y: FloatArray) -> None:
        tasks = self.tasks
        shown = tasks.open_at(t_s)
        holder = tasks.holders_at(t_s)
        held = (holder >= 0) & shown
        # waiting tasks first: a held task at a shared station is drawn over them
        order = np.flatnonzero(shown)
        order = order[np.argsort(holder[order] >= 0, kind="stable")]
        faces = [self.colors[h] if h >= 0 else WAITING_COLOR for h in holder[order]]
        self.stations.set_offsets(tasks.xy[order] if len(order) else np.zeros((0, 2)))
        self.stations.set_facecolor(faces if faces else "none")
        holders = holder[held]
        robots = np.column_stack([x[holders], y[holders]])
        self.links.set_segments(list(np.stack([robots, tasks.xy[held]], axis=1)))
        self.links.set_colors([self.colors[h] for h in holders] if len(holders) else "none")


def robot_label(run: RunData, robot: str) -> str:
    """A robot's name for legends, ``(physical)`` added for a physical robot's twin."""
    return f"{robot} (physical)" if robot in run.scenario.physical.robots else robot


def fleet_handles(run: RunData, colors: list[Color]) -> list[Line2D]:
    """Legend entries: a robot per colour (one entry for large fleets), the task markers."""
    handles = [
        Line2D([], [], color=c, marker="o", markeredgecolor="0.1", label=robot_label(run, name))
        for name, c in zip(run.track.robots, colors, strict=True)
    ]
    if len(handles) > LEGEND_ROBOTS_MAX:
        handles = [
            Line2D(
                [],
                [],
                color=colors[len(colors) // 3],
                marker="o",
                markeredgecolor="0.1",
                label=f"{len(colors)} robots, a colour each",
            )
        ]
    if run.tasks is not None:
        handles += [
            Line2D(
                [],
                [],
                color="0.4",
                marker="D",
                markerfacecolor=WAITING_COLOR,
                lw=0,
                markeredgecolor="0.15",
                label="task, waiting",
            ),
            Line2D(
                [],
                [],
                color="0.4",
                ls="--",
                marker="D",
                markerfacecolor="0.55",
                markeredgecolor="0.15",
                label="task, held (robot's colour)",
            ),
        ]
    return handles
