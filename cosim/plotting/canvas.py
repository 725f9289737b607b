"""What every figure of a run shares: resolution, robot colours and writing PNG files."""

from __future__ import annotations

import re
from collections.abc import Iterable
from pathlib import Path

import numpy as np
from matplotlib import colormaps
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from cosim.core.errors import ExportError

DPI = 150
"""Resolution of PNG figures (dots per inch)."""
LEGEND_ROBOTS_MAX = 10
"""Fleets up to this size get a legend entry per robot; larger ones are labelled on the map."""

Color = tuple[float, float, float, float]
"""An RGBA colour, each channel in [0, 1]."""


def save_png(figure: Figure, png_path: Path, *, dpi: float = DPI) -> Path:
    """Render ``figure`` with Agg to ``png_path`` (creating its folder).

    ``bbox_inches="tight"`` grows the canvas to hold legends placed outside the axes.

    Raises:
        ExportError: naming the path if the file cannot be written.
    """
    png_path = Path(png_path)
    try:
        png_path.parent.mkdir(parents=True, exist_ok=True)
        FigureCanvasAgg(figure)  # attaches itself: savefig renders with Agg, not pyplot
        figure.savefig(png_path, format="png", dpi=dpi, bbox_inches="tight")
    except OSError as error:
        raise ExportError(f"{png_path}: cannot write: {error.strerror or error}") from None
    return png_path


def robot_order(names: Iterable[str]) -> list[str]:
    """Robot names in fleet order: ``robot_2`` before ``robot_10`` (numbers compared as such)."""

    def key(name: str) -> tuple[str, int, str]:
        match = re.fullmatch(r"(.*?)(\d+)", name)
        return (match.group(1), int(match.group(2)), "") if match else (name, -1, name)

    return sorted(set(names), key=key)


def robot_colors(count: int) -> list[Color]:
    """A distinct colour per robot: Tableau's 10 or 20 for small fleets, turbo beyond.

    Turbo is cut at both ends: its darkest blue and red are hard to tell from walls.
    """
    if count <= 10:
        return [colormaps["tab10"](i) for i in range(count)]
    if count <= 20:
        return [colormaps["tab20"](i) for i in range(count)]
    return [colormaps["turbo"](float(v)) for v in np.linspace(0.08, 0.92, count)]


PHYSICAL_COLOR: Color = (0.84, 0.15, 0.16, 1.0)
"""A physical robot's twin, red as in the paper's mixed-reality figures."""


def fleet_colors(robots: list[str], physical: tuple[str, ...]) -> list[Color]:
    """Colours of a fleet, robot by robot.

    With physical robots, their twins are red and the virtual robots shades of green (the
    paper's convention); otherwise every robot gets a distinct colour.
    """
    if not physical:
        return robot_colors(len(robots))
    virtual = [r for r in robots if r not in physical]
    greens = [colormaps["Greens"](float(v)) for v in np.linspace(0.85, 0.45, max(len(virtual), 1))]
    shade = iter(greens)
    return [PHYSICAL_COLOR if r in physical else next(shade) for r in robots]


def short_label(robot: str) -> str:
    """A robot's name shortened for labels on a crowded map: ``robot_12`` -> ``12``."""
    match = re.fullmatch(r"robot_(\d+)", robot)
    return match.group(1) if match else robot
