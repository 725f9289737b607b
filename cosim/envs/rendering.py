"""What an environment shows when asked (``render_mode="rgb_array"``): the room from above.

The building (walls, shelves, obstacles), every robot's footprint and heading in its
colour, its goal, and the people and other moving things, drawn with the same world and
colours as cosim's figures. A frame costs a few tens of milliseconds: for videos of an
evaluation, not for every training step.
"""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Circle

from adapters.agents.contract import AgentView
from cosim.plotting.canvas import robot_colors
from cosim.plotting.world import draw_world, world_inches
from models.arrays import UInt8Array
from models.world.obstacles import DynamicObstacles
from models.world.warehouse import Warehouse

LONGER_IN = 6.0
"""The frame's longer side (inches, at 100 dpi: 600 pixels)."""
RENDER_MODES = ("rgb_array",)
"""What an environment can render (besides None: nothing)."""


def checked_render_mode(render_mode: str | None) -> str | None:
    """``render_mode`` if an environment can render it.

    Raises:
        ValueError: for any other (``"human"``: there is no window to draw in).
    """
    if render_mode is not None and render_mode not in RENDER_MODES:
        raise ValueError(f"render_mode={render_mode!r}: expected None or 'rgb_array'")
    return render_mode


def frame(view: AgentView) -> UInt8Array:
    """The room now, as an (height, width, 3) RGB image."""
    run = view.run
    warehouse = run.service(Warehouse)
    figure = Figure(figsize=world_inches(warehouse, LONGER_IN), dpi=100, layout="constrained")
    canvas = FigureCanvasAgg(figure)
    axes = figure.subplots()
    draw_world(axes, warehouse, labels=False)
    fleet = view.fleet
    colors = robot_colors(len(fleet))
    for i in range(len(fleet)):
        x, y, yaw, r = fleet.x[i], fleet.y[i], fleet.yaw[i], fleet.radius_m[i]
        axes.add_patch(Circle((x, y), r, facecolor=colors[i], alpha=0.6, edgecolor="black"))
        axes.plot([x, x + r * np.cos(yaw)], [y, y + r * np.sin(yaw)], color="black", lw=1)
        axes.plot(*view.goal_xy[i], marker="x", color=colors[i], markersize=9, mew=2)
    if run.has_service(DynamicObstacles):
        discs = run.service(DynamicObstacles).discs
        for x, y, r in discs:
            axes.add_patch(Circle((x, y), r, facecolor="tab:red", alpha=0.5))
    axes.set_title(f"t = {view.now_ns / 1e9:.1f} s", fontsize=9)
    canvas.draw()  # type: ignore[no-untyped-call]
    rgba = np.asarray(canvas.buffer_rgba())  # type: ignore[no-untyped-call]
    return np.ascontiguousarray(rgba[..., :3])
