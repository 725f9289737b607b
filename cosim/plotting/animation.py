"""An animated GIF of a run: robots, trails, one robot's lidar, tasks and who holds them.

Bounded in size and time: at most :data:`MAX_FRAMES` frames (the poses subsampled evenly,
so a long run plays faster), a modest resolution, and a fixed palette shared by all
frames. The world is drawn once; each frame restores it and draws only what moves (Agg
blitting), then Pillow writes the frames.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import LineCollection
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from PIL import Image

from cosim.core.errors import ExportError
from cosim.plotting.canvas import Color, fleet_colors
from cosim.plotting.fleet import FleetLayer, fleet_handles
from cosim.plotting.goals import GOAL_FACE, GoalLayer, goal_handles
from cosim.plotting.people import PeopleLayer, people_handles, people_inks
from cosim.plotting.rays import LidarRays
from cosim.plotting.rundata import RunData
from cosim.plotting.world import (
    OBSTACLE_COLOR,
    SHELF_MUTED,
    draw_world,
    world_handles,
    world_inches,
)
from models.arrays import FloatArray

MAX_FRAMES = 150
"""Most frames in a GIF."""
FRAME_MS = 100
"""Display time of a frame (ms): 10 frames per second."""
GIF_DPI = 80
"""Resolution of the frames (dots per inch)."""
WORLD_IN = 6.0
"""Longer side of the world in a frame (inches)."""
LEGEND_IN = 2.1
"""Width kept for the legend right of the world (inches)."""
RAY_COLOR = "#e6194b"
INKS = ("white", "black", "0.05", "0.1", "0.15", "0.2", "0.3", "0.45", "0.6", "0.75", "0.9")
"""Colours drawn besides the robots' (text, edges, walls, grids), for the palette."""
PALETTE_SIZE = 256
"""Colours of a GIF palette."""


def frame_indices(samples: int, max_frames: int = MAX_FRAMES) -> list[int]:
    """Pose samples drawn: at most ``max_frames``, evenly spaced, the first and last included."""
    if samples <= max_frames:
        return list(range(samples))
    return sorted({round(float(v)) for v in np.linspace(0, samples - 1, max_frames)})


def animation_gif(
    run: RunData, gif_path: Path, *, max_frames: int = MAX_FRAMES, lidar_robot: int = 0
) -> Path:
    """Write an animated GIF of the run to ``gif_path``.

    Args:
        run: the run.
        gif_path: where to write the GIF.
        max_frames: most frames (the pose samples are subsampled evenly to fit).
        lidar_robot: fleet index of the robot whose lidar beams are drawn (recomputed,
            noise-free; see :mod:`cosim.plotting.rays`).

    Returns:
        ``gif_path``.

    Raises:
        ExportError: naming the path if the file cannot be written.
    """
    track = run.track
    colors = fleet_colors(list(track.robots), run.scenario.physical.robots)
    width, height = world_inches(run.warehouse, WORLD_IN)
    figure = Figure(figsize=(width + LEGEND_IN, height + 0.5), dpi=GIF_DPI, layout="constrained")
    canvas = FigureCanvasAgg(figure)
    ax = figure.add_subplot()
    draw_world(ax, run.warehouse, shelf_color=SHELF_MUTED)
    layer = FleetLayer(ax, run, colors, label_robots=False)  # unreadable at GIF resolution
    goals = GoalLayer(ax, run, colors)
    people = PeopleLayer(ax, run)
    rays = LidarRays(run, lidar_robot, max_rays=90)
    beams = LineCollection([], colors=RAY_COLOR, linewidths=0.4, alpha=0.5, zorder=2)
    ax.add_collection(beams)
    hits = ax.scatter([], [], s=3, color=RAY_COLOR, zorder=2, linewidths=0)
    clock = ax.text(0.01, 1.01, "", transform=ax.transAxes, ha="left", va="bottom", fontsize=10)
    figure.suptitle(run.title, fontsize=11)
    indices = frame_indices(len(track.t_s), max_frames)
    speedup = _speedup(track.t_s, indices)
    lidar = Line2D([], [], color=RAY_COLOR, lw=0.8, label=f"lidar, {track.robots[lidar_robot]}")
    handles = [
        *fleet_handles(run, colors),
        *goal_handles(run),
        *people_handles(run),
        lidar,
        *world_handles(run.warehouse, shelf_color=SHELF_MUTED),
    ]
    figure.legend(handles=handles, loc="outside right upper", fontsize=8)

    moving = [beams, hits, *people.show(float(track.t_s[indices[0]])), *layer.show(indices[0])]
    moving += [goals.links, goals.markers]
    moving.append(clock)
    for artist in moving:
        artist.set_animated(True)
    # matplotlib leaves these Agg canvas methods unannotated
    canvas.draw()  # type: ignore[no-untyped-call]  # the world, axes, legend; once
    canvas.draw()  # type: ignore[no-untyped-call]  # again: the layout settles
    background = canvas.copy_from_bbox(figure.bbox)  # type: ignore[no-untyped-call]
    # people's inks only with people: a palette entry more would requantize every frame
    inks: list[Color | str] = [
        *colors,
        RAY_COLOR,
        SHELF_MUTED,
        OBSTACLE_COLOR,
        *people_inks(run),
        *([GOAL_FACE] if goal_handles(run) else []),
        *INKS,
    ]
    palette = _palette(inks, robots=len(colors))
    frames = []  # indexed at once: a quarter of the memory of RGB frames
    for i in indices:
        canvas.restore_region(background)  # type: ignore[no-untyped-call]
        origin, ends, hit = rays.cast(i)
        beams.set_segments([np.array([origin, end]) for end in ends])
        hits.set_offsets(ends[hit] if hit.any() else np.zeros((0, 2)))
        clock.set_text(f"t = {track.t_s[i]:5.1f} s   ({speedup:g}x real time)")
        people_now = people.show(float(track.t_s[i]))
        goals.show(float(track.t_s[i]), track.x_m[i], track.y_m[i])
        drawn = [beams, hits, goals.links, goals.markers, *people_now, *layer.show(i), clock]
        for artist in drawn:  # in z order
            ax.draw_artist(artist)
        pixels = np.asarray(canvas.buffer_rgba())  # type: ignore[no-untyped-call]
        rgb = Image.fromarray(pixels).convert("RGB")
        frames.append(rgb.quantize(palette=palette, dither=Image.Dither.NONE))
    return _write_gif(frames, Path(gif_path))


def _speedup(t_s: FloatArray, indices: list[int]) -> float:
    """Simulated seconds shown per second of playback, rounded for the label."""
    if len(indices) < 2:
        return 1.0
    per_frame = float(t_s[indices[-1]] - t_s[indices[0]]) / (len(indices) - 1)
    return round(per_frame / (FRAME_MS / 1000), 1)


def _palette(inks: list[Color | str], *, robots: int) -> Image.Image:
    """A palette of every colour drawn, each also blended with white as antialiasing does.

    A palette fitted to the pixels (median cut) would give the small robot discs no colour
    of their own; this one has each robot's, with as many blends as fit in 256 colours.
    """
    levels = int(np.clip((PALETTE_SIZE - 4 * (len(inks) - robots)) // max(robots, 1), 1, 4))
    weights = np.linspace(1.0, 0.25, 4)
    rgb: list[tuple[float, float, float]] = []
    for k, ink in enumerate(inks):
        color = np.array(to_rgb(ink))
        for w in weights[: levels if k < robots else 4]:
            r, g, b = (float(v) for v in w * color + (1 - w))
            rgb.append((r, g, b))
    values = (np.array(rgb[:PALETTE_SIZE]) * 255).round().astype(np.uint8).ravel()
    palette = Image.new("P", (1, 1))
    palette.putpalette(values.tolist() + [255] * (3 * PALETTE_SIZE - len(values)))
    return palette


def _write_gif(indexed: list[Image.Image], gif_path: Path) -> Path:
    """Save the frames (palette images) as a looping GIF."""
    try:
        gif_path.parent.mkdir(parents=True, exist_ok=True)
        indexed[0].save(
            gif_path,
            format="GIF",
            save_all=True,
            append_images=indexed[1:],
            duration=FRAME_MS,
            loop=0,
        )
    except OSError as error:
        raise ExportError(f"{gif_path}: cannot write: {error.strerror or error}") from None
    return gif_path
