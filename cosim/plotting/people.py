"""People and forklifts (``tables/humans``) drawn over the world (frame ``map``, m).

Workers are near-black discs of ``humans.worker_radius_m``; forklifts yellow rectangles of
``humans.forklift_size_m`` turned to their heading. A snapshot shows everyone at the
latest sample at or before its time; the trajectories figure shows their tracks thin.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection, PatchCollection
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Patch, Polygon

from cosim.plotting.rundata import RunData
from models.arrays import FloatArray
from models.humans.bodies import two_disc_cover

PERSON_COLOR = "#1c1c1c"
"""Workers: near-black discs with a white rim, unlike any robot's colour (robots take
Tableau's or turbo's colours, physical twins red and virtual robots green)."""
FORKLIFT_COLOR = "#edc948"
"""Forklifts: yellow, as painted."""
TRACK_ALPHA = 0.35


class PeopleSamples:
    """``tables/humans`` by sample time: who was where at any time of the run."""

    def __init__(self, run: RunData) -> None:
        humans = run.humans
        self.frame = (
            humans.sort_values(["t_s", "id"], kind="stable").reset_index(drop=True)
            if humans is not None
            else None
        )
        self.times = np.zeros(0)
        self.starts = np.zeros(1, dtype=np.int64)
        if self.frame is not None:
            t = self.frame["t_s"].to_numpy()
            self.times, first = np.unique(t, return_index=True)
            self.starts = np.append(first, len(t))
        cfg = run.scenario.humans
        self.radius_m = cfg.worker_radius_m
        self.size_m = cfg.forklift_size_m

    def at(self, t_s: float) -> pd.DataFrame | None:
        """The rows of the latest sample at or before ``t_s`` (None before the first)."""
        if self.frame is None:
            return None
        k = int(np.searchsorted(self.times, t_s + 1e-9, side="right")) - 1
        if k < 0:
            return None
        return self.frame.iloc[self.starts[k] : self.starts[k + 1]]

    def discs(self, t_s: float) -> FloatArray:
        """(k, 3) discs ``x_m, y_m, radius_m`` of everyone at ``t_s``, as the lidar saw them.

        A worker is one disc; a forklift two, covering its body.
        """
        rows = self.at(t_s)
        if rows is None:
            return np.zeros((0, 3))
        people = rows[rows["kind"] != "forklift"]
        forklifts = rows[rows["kind"] == "forklift"]
        xy = people[["x_m", "y_m"]].to_numpy()
        return np.vstack(
            [
                np.column_stack([xy, np.full(len(xy), self.radius_m)]),
                two_disc_cover(
                    forklifts["x_m"].to_numpy(),
                    forklifts["y_m"].to_numpy(),
                    forklifts["yaw_rad"].to_numpy(),
                    *self.size_m,
                ),
            ]
        )


class PeopleLayer(PeopleSamples):
    """Everyone SUMO moved, at one time; empty for runs without people."""

    def __init__(self, ax: Axes, run: RunData) -> None:
        """Create the (empty) artists on ``ax``."""
        super().__init__(run)
        self.people = PatchCollection(
            [], facecolor=PERSON_COLOR, edgecolor="white", linewidths=0.8, zorder=5
        )
        self.forklifts = PatchCollection(
            [], facecolor=FORKLIFT_COLOR, edgecolor="0.15", linewidths=0.6, zorder=5
        )
        ax.add_collection(self.people)
        ax.add_collection(self.forklifts)

    def show(self, t_s: float) -> list[Artist]:
        """Move the people to time ``t_s`` (s); return the artists (to redraw)."""
        rows = self.at(t_s)
        people: list[Patch] = []
        forklifts: list[Patch] = []
        if rows is not None:
            for kind, x, y, yaw in zip(
                rows["kind"], rows["x_m"], rows["y_m"], rows["yaw_rad"], strict=True
            ):
                if kind == "forklift":
                    forklifts.append(Polygon(_rectangle(x, y, yaw, *self.size_m), closed=True))
                else:
                    people.append(Circle((x, y), self.radius_m))
        self.people.set_paths(people)
        self.forklifts.set_paths(forklifts)
        return [self.people, self.forklifts]


def _rectangle(x: float, y: float, yaw: float, length: float, width: float) -> np.ndarray:
    c, s = np.cos(yaw), np.sin(yaw)
    corners = np.array([[1, 1], [-1, 1], [-1, -1], [1, -1]]) * [length / 2, width / 2]
    turned: np.ndarray = corners @ np.array([[c, s], [-s, c]]) + [x, y]
    return turned


def draw_tracks(ax: Axes, run: RunData) -> None:
    """Every person's and forklift's path over the run, thin and light."""
    if run.humans is None:
        return
    segments = []
    colors = []
    for (_, kind), rows in run.humans.groupby(["id", "kind"], sort=True):
        ordered = rows.sort_values("t_s")
        segments.append(ordered[["x_m", "y_m"]].to_numpy())
        colors.append(FORKLIFT_COLOR if kind == "forklift" else PERSON_COLOR)
    ax.add_collection(
        LineCollection(segments, colors=colors, linewidths=0.6, alpha=TRACK_ALPHA, zorder=2)
    )


def people_inks(run: RunData) -> list[str]:
    """The colours people add to a run's drawings: none for a run without people."""
    if run.humans is None:
        return []
    return [PERSON_COLOR, FORKLIFT_COLOR]


def people_handles(run: RunData) -> list[Line2D]:
    """Legend entries for the people and forklifts of the run (none without them)."""
    if run.humans is None:
        return []
    kinds = set(run.humans["kind"])
    people = run.humans.loc[run.humans["kind"] != "forklift", "id"].nunique()
    handles = []
    if kinds - {"forklift"}:
        handles.append(
            Line2D(
                [],
                [],
                color=PERSON_COLOR,
                marker="o",
                ls="none",
                mec="white",
                label=f"{people} people (SUMO)",
            )
        )
    if "forklift" in kinds:
        handles.append(
            Line2D(
                [],
                [],
                color=FORKLIFT_COLOR,
                marker="s",
                ls="none",
                mec="0.15",
                label="forklifts (SUMO)",
            )
        )
    return handles
