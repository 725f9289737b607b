"""The fleet at one instant on a world axes: robots, their recent trails, open tasks.

One :class:`FleetLayer` per axes; :meth:`FleetLayer.show` moves it to any pose sample, so the
same drawing serves the snapshot panels and every frame of the animation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
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
    """The tasks of a run as arrays (times in s; NaN: not yet / never).

    Attributes:
        xy: (k, 2) task stations in ``map`` (m).
        created: (k,) creation times (s).
        assigned: (k,) times the final holder was assigned (s).
        started: (k,) service start times (s).
        completed: (k,) completion times (s).
        holder: (k,) fleet index of the holder (``RunData.tasks.holder``), -1 for none.
    """

    xy: FloatArray
    created: FloatArray
    assigned: FloatArray
    started: FloatArray
    completed: FloatArray
    holder: IntArray

    @classmethod
    def of(cls, run: RunData) -> TaskTimes:
        """The run's tasks (none when it has no tasks table)."""
        tasks = run.tasks
        if tasks is None:
            return cls.of_none()
        index = {name: i for i, name in enumerate(run.track.robots)}

        def times(column: str) -> FloatArray:
            values: FloatArray = tasks[column].to_numpy(np.float64)
            return values

        return cls(
            xy=tasks[["x_m", "y_m"]].to_numpy(np.float64),
            created=times("t_created_s"),
            assigned=times("t_assigned_s"),
            started=times("t_started_s"),
            completed=times("t_completed_s"),
            holder=np.array([index.get(r, -1) for r in tasks["holder"]], dtype=np.int64),
        )

    @classmethod
    def of_none(cls) -> TaskTimes:
        """No task."""
        empty = np.zeros(0)
        return cls(np.zeros((0, 2)), empty, empty, empty, empty, np.zeros(0, dtype=np.int64))

    def open_at(self, t_s: float) -> BoolArray:
        """Tasks created and not completed at ``t_s`` (NaN compares false: never completed)."""
        done: BoolArray = self.completed <= t_s
        return (self.created <= t_s) & ~done

    def held_at(self, t_s: float) -> BoolArray:
        """Tasks whose (final) holder has them at ``t_s``."""
        return (self.holder >= 0) & (self.assigned <= t_s)


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
        held = tasks.held_at(t_s) & shown
        faces = [
            self.colors[h] if is_held else WAITING_COLOR
            for h, is_held in zip(tasks.holder[shown], held[shown], strict=True)
        ]
        self.stations.set_offsets(tasks.xy[shown] if shown.any() else np.zeros((0, 2)))
        self.stations.set_facecolor(faces if faces else "none")
        holders = tasks.holder[held]
        robots = np.column_stack([x[holders], y[holders]])
        self.links.set_segments(list(np.stack([robots, tasks.xy[held]], axis=1)))
        self.links.set_colors([self.colors[h] for h in holders] if len(holders) else "none")


def fleet_handles(run: RunData, colors: list[Color]) -> list[Line2D]:
    """Legend entries: a robot per colour (one entry for large fleets), the task markers."""
    handles = [
        Line2D([], [], color=c, marker="o", markeredgecolor="0.1", label=name)
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
