"""Figures (PNG) of a run's world and results, drawn with matplotlib's Agg renderer.

Every figure is a standalone :class:`matplotlib.figure.Figure` on a
:class:`~matplotlib.backends.backend_agg.FigureCanvasAgg`: pyplot and its global state
are never touched, so figures can be drawn from worker processes and tests without a
display and without changing the caller's matplotlib backend.
"""

from __future__ import annotations

import math
from pathlib import Path

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Patch, Rectangle

from adapters.naming import robot_name
from cosim.errors import ExportError
from models.world import Warehouse, WarehouseSpec

WALL_COLOR = "0.3"
SHELF_COLOR = "#c8864a"
ROBOT_COLOR = "#1f77b4"
DPI = 150
MAX_INCHES = 8.0
"""Longer side of a world figure (inches); the other follows the world's aspect."""


def _save(figure: Figure, png_path: Path) -> Path:
    """Render ``figure`` to ``png_path`` (creating its folder), as an :class:`ExportError`."""
    try:
        png_path.parent.mkdir(parents=True, exist_ok=True)
        FigureCanvasAgg(figure)  # attaches itself: savefig renders with Agg, not pyplot
        # "tight" grows the canvas to hold the legend outside the axes
        figure.savefig(png_path, format="png", dpi=DPI, bbox_inches="tight")
    except OSError as error:
        raise ExportError(f"{png_path}: cannot write: {error.strerror or error}") from None
    return png_path


def world_figure(
    warehouse: Warehouse,
    png_path: Path,
    *,
    title: str,
    robot_radius_m: float = WarehouseSpec.robot_radius_m,
) -> Path:
    """Draw walls, shelves and robot start poses of a warehouse to a PNG file.

    Args:
        warehouse: the world (frame ``map``, axes in metres).
        png_path: where to write the PNG.
        title: the figure title.
        robot_radius_m: footprint radius drawn around each start pose (m).

    Returns:
        ``png_path``.

    Raises:
        ExportError: naming the path if the file cannot be written.
    """
    xmin, ymin, xmax, ymax = warehouse.bounds
    span_x, span_y = xmax - xmin, ymax - ymin
    scale = MAX_INCHES / max(span_x, span_y)
    # room for the axis labels and legend around the plot itself
    figure = Figure(figsize=(max(3.0, span_x * scale) + 1.5, max(3.0, span_y * scale) + 1.0))
    ax = figure.add_subplot()
    for x0, y0, x1, y1 in warehouse.walls:
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, facecolor=WALL_COLOR, lw=0))
    for x0, y0, x1, y1 in warehouse.shelves:
        ax.add_patch(
            Rectangle((x0, y0), x1 - x0, y1 - y0, facecolor=SHELF_COLOR, edgecolor="0.2", lw=0.5)
        )
    # upright labels over a dock row (robots ~1 m apart) would overlap: they run vertically,
    # and shrink for big fleets, whose dock rows are as close as the robots in them
    fontsize = 6.0 if len(warehouse.starts) <= 10 else 3.5
    for i, (x, y, yaw) in enumerate(warehouse.starts):
        ax.add_patch(
            Circle((x, y), robot_radius_m, facecolor="none", edgecolor=ROBOT_COLOR, lw=1.0)
        )
        tip = (x + robot_radius_m * math.cos(yaw), y + robot_radius_m * math.sin(yaw))
        ax.plot([x, tip[0]], [y, tip[1]], color=ROBOT_COLOR, lw=1.0)
        ax.annotate(
            robot_name(i),
            (x, y + robot_radius_m),
            xytext=(0, 1),
            textcoords="offset points",
            ha="center",
            va="bottom",
            rotation=90,
            fontsize=fontsize,
        )
    ax.set_xlim(xmin - 0.5, xmax + 0.5)
    ax.set_ylim(ymin - 0.5, ymax + 0.5)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m, map)")
    ax.set_ylabel("y (m, map)")
    ax.set_title(title)
    ax.legend(
        handles=[
            Patch(facecolor=WALL_COLOR, label="walls"),
            Patch(facecolor=SHELF_COLOR, edgecolor="0.2", label="shelves"),
            Line2D(
                [], [], color=ROBOT_COLOR, marker="o", fillstyle="none", lw=0, label="robot starts"
            ),
        ],
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize=8,
    )
    return _save(figure, Path(png_path))
