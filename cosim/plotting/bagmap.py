"""The picture of a mapped recording: the map with the estimated, odometry and reference paths."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from cosim.plotting.canvas import save_png
from models.arrays import FloatArray
from models.mapping.grid import LogOddsMap


def bag_map_figure(
    grid: LogOddsMap,
    estimate: FloatArray,
    odometry: FloatArray,
    reference: FloatArray | None,
    png_path: Path,
    title: str,
) -> Path:
    """Draw the map (black occupied, white free, grey unknown) and the trajectories.

    All three in the map frame (the odometry frame at the first scan); the reference
    already aligned onto the estimate.
    """
    cells = grid.occupancy()
    shade = np.full(cells.shape, 0.8)
    shade[cells == 0] = 1.0
    shade[cells == 100] = 0.0
    known = np.flatnonzero((cells != -1).any(axis=0)), np.flatnonzero((cells != -1).any(axis=1))
    g = grid.geometry
    r = g.resolution_m
    x0, y0 = g.origin_xy_m
    extent = (x0, x0 + g.width * r, y0, y0 + g.height * r)
    figure = Figure(figsize=(9.0, 8.0), layout="constrained")
    ax = figure.add_subplot()
    ax.imshow(shade, cmap="gray", vmin=0, vmax=1, origin="lower", extent=extent)
    ax.plot(odometry[:, 0], odometry[:, 1], color="#d62728", lw=1.0, ls="--", label="odometry")
    if reference is not None:
        ax.plot(
            reference[:, 0], reference[:, 1], color="#2ca02c", lw=1.4, label="reference (aligned)"
        )
    ax.plot(estimate[:, 0], estimate[:, 1], color="#1f77b4", lw=1.2, label="estimate")
    cols, rows = known
    if len(cols) and len(rows):
        ax.set_xlim(x0 + cols[0] * r - 1, x0 + (cols[-1] + 1) * r + 1)
        ax.set_ylim(y0 + rows[0] * r - 1, y0 + (rows[-1] + 1) * r + 1)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m, map)")
    ax.set_ylabel("y (m, map)")
    ax.set_title(title)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    return save_png(figure, png_path)
