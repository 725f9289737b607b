"""The navigation goals of a run without tasks (the goals driver, the paper's Scenario 2).

With tasks, a goal is a task station and the stations are drawn instead; without, the
goals the driver sent (``tables/navigation``, event ``goal``) are what the robots drove
to: every distinct goal in the trajectories figure, numbered in the order first sent,
and each robot's current goal in the snapshots and animation frames.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection, PathCollection
from matplotlib.lines import Line2D

from cosim.plotting.canvas import Color
from cosim.plotting.rundata import RunData
from models.arrays import FloatArray

GOAL_MARKER = "*"
GOAL_FACE = "gold"
"""Face of a goal marker."""
GOAL_SIZE = 110.0
"""Area of a goal marker (points squared)."""
GOAL_ROUND_M = 1e-3
"""Goals this close are one goal (m)."""
GOAL_IDS_MAX = 30
"""Goals are numbered up to this many distinct goals."""


def goal_events(run: RunData) -> pd.DataFrame:
    """The goals sent (``t_s``, ``robot``, ``goal_x_m``, ``goal_y_m``) of a run without tasks.

    Empty for a run with tasks (its goals are task stations) or without navigation table.
    """
    nav = run.navigation
    if run.tasks is not None or nav is None:
        return pd.DataFrame({"t_s": [], "robot": [], "goal_x_m": [], "goal_y_m": []})
    goals = nav[nav["event"] == "goal"]
    return goals[["t_s", "robot", "goal_x_m", "goal_y_m"]].sort_values("t_s", kind="stable")


def distinct_goals(run: RunData) -> list[tuple[float, float, str]]:
    """Each distinct goal (x m, y m, the robot first sent there), in the order first sent."""
    seen: dict[tuple[int, int], tuple[float, float, str]] = {}
    for _, row in goal_events(run).iterrows():
        x, y = float(row["goal_x_m"]), float(row["goal_y_m"])
        key = (round(x / GOAL_ROUND_M), round(y / GOAL_ROUND_M))
        seen.setdefault(key, (x, y, str(row["robot"])))
    return list(seen.values())


def draw_goals(ax: Axes, run: RunData, colors: list[Color]) -> PathCollection | None:
    """Every distinct goal as a star edged in the colour of the robot first sent there.

    Numbered in the order first sent (up to :data:`GOAL_IDS_MAX` goals). Returns the
    markers, or None when the run has no goals to draw.
    """
    goals = distinct_goals(run)
    if not goals:
        return None
    index = {name: i for i, name in enumerate(run.track.robots)}
    edges = [colors[index[r]] if r in index else (0.3, 0.3, 0.3, 1.0) for _, _, r in goals]
    xy = np.array([(x, y) for x, y, _ in goals])
    markers = ax.scatter(
        xy[:, 0], xy[:, 1], s=GOAL_SIZE, marker=GOAL_MARKER, facecolors=GOAL_FACE,
        edgecolors=edges, linewidths=1.0, zorder=4,
    )  # fmt: skip
    if len(goals) <= GOAL_IDS_MAX:
        for k, (x, y, _) in enumerate(goals, start=1):
            ax.annotate(
                f"g{k}", (x, y), xytext=(5, 4), textcoords="offset points", fontsize=7,
                color="0.1", zorder=7,
            )  # fmt: skip
    return markers


class GoalLayer:
    """Each robot's current goal (the last sent by then): a star and a dotted line to it."""

    def __init__(self, ax: Axes, run: RunData, colors: list[Color]) -> None:
        """Create the (empty) artists on ``ax`` (a world axes, frame ``map``, m)."""
        self.robots = list(run.track.robots)
        self.colors = colors
        self.events = goal_events(run)
        self.markers = ax.scatter(
            [], [], s=GOAL_SIZE, marker=GOAL_MARKER, facecolors=GOAL_FACE, linewidths=1.0, zorder=4
        )
        self.links = LineCollection([], linestyles=":", linewidths=1.0, zorder=3)
        ax.add_collection(self.links)

    def current(self, t_s: float) -> dict[str, tuple[float, float]]:
        """Each robot's goal at ``t_s`` (s): the last sent at or before it."""
        sent = self.events[self.events["t_s"] <= t_s]
        last = sent.groupby("robot", sort=False).last()
        return {str(r): (float(g.goal_x_m), float(g.goal_y_m)) for r, g in last.iterrows()}

    def show(self, t_s: float, x: FloatArray, y: FloatArray) -> None:
        """Draw the goals at ``t_s`` (s) for robots at ``x``, ``y`` (m, fleet order)."""
        goals = self.current(t_s)
        ranks = [i for i, r in enumerate(self.robots) if r in goals]
        points = np.array([goals[self.robots[i]] for i in ranks]).reshape(-1, 2)
        self.markers.set_offsets(points)
        self.markers.set_edgecolor([self.colors[i] for i in ranks] if ranks else "none")
        self.links.set_segments(
            [np.array([[x[i], y[i]], p]) for i, p in zip(ranks, points, strict=True)]
        )
        self.links.set_colors([self.colors[i] for i in ranks] if ranks else "none")


def goal_handles(run: RunData) -> list[Line2D]:
    """The legend entry of goals, if the run has goals to draw."""
    if goal_events(run).empty:
        return []
    return [
        Line2D(
            [], [], marker=GOAL_MARKER, ms=10, mfc=GOAL_FACE, mec="0.3", lw=0,
            label="goal (g1, g2...: order sent)",
        )
    ]  # fmt: skip
