"""The world drawn on an axes: walls, shelves, extra obstacles (frame ``map``, metres).

Also the figure of ``cosim world --png``: the world and the robots' start poses.
"""

from __future__ import annotations

import math
from pathlib import Path

from matplotlib.axes import Axes
from matplotlib.collections import PatchCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Patch, Rectangle

from adapters.naming import robot_name
from cosim.plotting.canvas import save_png
from models.arrays import FloatArray
from models.world.warehouse import Warehouse, WarehouseSpec

WALL_COLOR = "0.3"
SHELF_COLOR = "#c8864a"
"""Shelves of the world figure (strong: the shelves are its subject)."""
SHELF_MUTED = "#e8d3b9"
"""Shelves under trajectories and robots (pale: the robots are the subject)."""
OBSTACLE_COLOR = "#9aa5b1"
ROBOT_COLOR = "#1f77b4"
MAX_INCHES = 8.0
"""Longer side of a world figure (inches); the other follows the world's aspect."""
MARGIN_M = 0.5
"""Free space drawn around the outer walls (m)."""


def world_inches(warehouse: Warehouse, longer_in: float) -> tuple[float, float]:
    """Width and height (inches) of the world drawn with its longer side ``longer_in``."""
    xmin, ymin, xmax, ymax = warehouse.bounds
    span_x, span_y = xmax - xmin + 2 * MARGIN_M, ymax - ymin + 2 * MARGIN_M
    scale = longer_in / max(span_x, span_y)
    return span_x * scale, span_y * scale


def draw_world(
    ax: Axes, warehouse: Warehouse, *, shelf_color: str = SHELF_COLOR, labels: bool = True
) -> None:
    """Draw walls, shelves and extra obstacles on ``ax``, equal aspect, axes in ``map`` (m).

    Args:
        ax: the axes.
        warehouse: the world.
        shelf_color: the shelves' face colour.
        labels: label the axes ``x (m, map)`` and ``y (m, map)``.
    """
    ax.add_collection(_boxes(warehouse.walls, facecolor=WALL_COLOR, edgecolor="none"))
    ax.add_collection(_boxes(warehouse.shelves, facecolor=shelf_color, edgecolor="0.45"))
    ax.add_collection(_boxes(warehouse.obstacles, facecolor=OBSTACLE_COLOR, edgecolor="0.3"))
    xmin, ymin, xmax, ymax = warehouse.bounds
    ax.set_xlim(xmin - MARGIN_M, xmax + MARGIN_M)
    ax.set_ylim(ymin - MARGIN_M, ymax + MARGIN_M)
    ax.set_aspect("equal")
    if labels:
        ax.set_xlabel("x (m, map)")
        ax.set_ylabel("y (m, map)")


def world_handles(warehouse: Warehouse, *, shelf_color: str = SHELF_COLOR) -> list[Patch]:
    """Legend entries of what :func:`draw_world` drew."""
    handles = [Patch(facecolor=WALL_COLOR, label="walls")]
    if len(warehouse.shelves):
        handles.append(Patch(facecolor=shelf_color, edgecolor="0.45", label="shelves"))
    if len(warehouse.obstacles):
        handles.append(Patch(facecolor=OBSTACLE_COLOR, edgecolor="0.3", label="obstacles"))
    return handles


def _boxes(boxes: FloatArray, *, facecolor: str, edgecolor: str) -> PatchCollection:
    rectangles = [Rectangle((x0, y0), x1 - x0, y1 - y0) for x0, y0, x1, y1 in boxes]
    return PatchCollection(rectangles, facecolor=facecolor, edgecolor=edgecolor, linewidth=0.5)


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
    width, height = world_inches(warehouse, MAX_INCHES)
    # room for the axis labels and legend around the plot itself
    figure = Figure(figsize=(max(3.0, width) + 1.5, max(3.0, height) + 1.0))
    ax = figure.add_subplot()
    draw_world(ax, warehouse)
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
    ax.set_title(title)
    starts = Line2D(
        [], [], color=ROBOT_COLOR, marker="o", fillstyle="none", lw=0, label="robot starts"
    )
    ax.legend(
        handles=[*world_handles(warehouse), starts],
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize=8,
    )
    return save_png(figure, Path(png_path))
