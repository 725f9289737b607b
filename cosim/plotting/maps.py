"""The maps a run's robots built (``maps/``) and their quality over time (``map_quality``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

from adapters.world.files import read_map
from cosim.core.errors import ExportError
from cosim.plotting.canvas import run_colors, save_png
from cosim.plotting.rundata import RunData

PANELS_PER_ROW = 3
MOST_ROBOTS = 5
"""Robots' maps drawn beside the fleet's (the first ones); the table has them all."""


def has_maps(run: RunData) -> bool:
    """Whether the run folder holds mapping results."""
    return (run.path / "maps" / "fleet.yaml").is_file()


def maps_figure(run: RunData, png_path: Path) -> Path:
    """The fleet's fused map and the first robots' maps, with the true obstacles outlined."""
    folder = run.path / "maps"
    robots = sorted(
        (p.stem for p in folder.glob("robot_*.yaml")), key=lambda n: int(n.split("_")[1])
    )
    names = ["fleet", *robots[:MOST_ROBOTS]]
    quality = _quality(run)
    rows = (len(names) + PANELS_PER_ROW - 1) // PANELS_PER_ROW
    cols = min(len(names), PANELS_PER_ROW)
    figure = Figure(figsize=(4.2 * cols, 4.2 * rows + 0.4), layout="constrained")
    axes = figure.subplots(rows, cols, squeeze=False).ravel()
    for ax in axes[len(names) :]:
        ax.remove()
    for ax, name in zip(axes, names, strict=False):
        grid = read_map(folder / f"{name}.yaml")
        shade = np.full(grid.data.shape, 0.8)
        shade[grid.data == 0] = 1.0
        shade[grid.data == 100] = 0.0
        x0, y0 = grid.origin_xy_m
        r = grid.resolution_m
        extent = (x0, x0 + grid.width * r, y0, y0 + grid.height * r)
        ax.imshow(shade, cmap="gray", vmin=0, vmax=1, origin="lower", extent=extent)
        for bx0, by0, bx1, by1 in run.warehouse.boxes:
            ax.add_patch(
                Rectangle((bx0, by0), bx1 - bx0, by1 - by0, fill=False, ec="#d62728", lw=0.4)
            )
        label = name
        if quality is not None and name in quality.index:
            q = quality.loc[name]
            label += f": coverage {q.coverage:.2f}, IoU {q.iou:.2f}, ATE {q.ate_m:.2f} m"
        ax.set_title(label, fontsize=9)
        ax.set_aspect("equal")
        ax.tick_params(labelsize=7)
    axes[0].set_ylabel("y (m, map)")
    axes[min(len(names), PANELS_PER_ROW) - 1].set_xlabel("x (m, map)")
    figure.suptitle(f"{run.title}: maps (true obstacles outlined in red)")
    return save_png(figure, png_path)


def quality_figure(run: RunData, png_path: Path) -> Path | None:
    """Coverage, IoU and ATE over time, a line per robot and a thick one for the fleet."""
    path = run.path / "tables" / "map_quality.parquet"
    if not path.is_file():
        return None
    table = pd.read_parquet(path)
    if table.empty:
        return None
    colors = dict(zip(run.track.robots, run_colors(run), strict=True))
    figure = Figure(figsize=(12.0, 3.6), layout="constrained")
    axes = figure.subplots(1, 3)
    for ax, column, unit in zip(
        axes, ("coverage", "iou", "ate_m"), ("share", "share", "m"), strict=True
    ):
        for robot, rows in table.groupby("robot", observed=True, sort=False):
            fleet = robot == "fleet"
            color = "k" if fleet else colors.get(str(robot), "0.5")
            ax.plot(
                rows.t_s, rows[column], lw=2.2 if fleet else 0.8, color=color,
                alpha=1.0 if fleet else 0.6, label="fleet" if fleet else None,
            )  # fmt: skip
        if column == "ate_m":
            fleet_rows = table[table.robot == "fleet"]
            ax.plot(fleet_rows.t_s, fleet_rows.ate_odom_m, color="0.35", ls="--",
                    label="odometry alone (fleet)")  # fmt: skip
        ax.set_xlabel("time (s)")
        ax.set_ylabel(f"{column} ({unit})")
        ax.grid(True, alpha=0.3)
    axes[2].legend(fontsize=8, loc="upper left")
    figure.suptitle(f"{run.title}: map quality (thin lines: each robot)")
    return save_png(figure, png_path)


def _quality(run: RunData) -> pd.DataFrame | None:
    path = run.path / "tables" / "map_quality.parquet"
    if not path.is_file():
        return None
    try:
        table = pd.read_parquet(path)
    except (OSError, ValueError) as error:
        raise ExportError(f"{path}: cannot read: {error}") from None
    return table.groupby("robot", observed=True).last()
