"""What every figure of a run shares: resolution, robot colours and writing PNG files."""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from matplotlib import colormaps
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import hsv_to_rgb
from matplotlib.figure import Figure

from cosim.core.errors import ExportError

if TYPE_CHECKING:
    from cosim.plotting.rundata import RunData

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


PHYSICAL_COLOR: Color = (0.84, 0.15, 0.16, 1.0)
"""A physical robot's twin, red as in the paper's mixed-reality figures (and only it)."""
_TAB10_NOT_RED = (0, 1, 2, 4, 5, 6, 8, 9, 7)
"""Tableau 10 without its red (index 3), grey last (it is also the colour of 'no robot')."""
_TAB20_NOT_RED = tuple(i for i in range(20) if i not in (6, 7))
"""Tableau 20 without its red pair."""
HUE_SPAN = (0.1, 0.9)
"""Hues (HSV, 0 and 1 are red) of the colour wheel of large fleets: red left out."""


def robot_colors(count: int) -> list[Color]:
    """``count`` distinct colours, none of them red (red is the physical robots').

    Tableau 10 without red for up to 9, Tableau 20 without its red pair for up to 18, and
    beyond a wheel of hues from orange to magenta in three brightness levels.
    """
    if count <= len(_TAB10_NOT_RED):
        return [colormaps["tab10"](i) for i in _TAB10_NOT_RED[:count]]
    if count <= len(_TAB20_NOT_RED):
        return [colormaps["tab20"](i) for i in _TAB20_NOT_RED[:count]]
    hues = np.linspace(*HUE_SPAN, count)
    values = (0.95, 0.7, 0.82)
    colors: list[Color] = []
    for k, hue in enumerate(hues):
        r, g, b = hsv_to_rgb((float(hue), 0.85, values[k % 3]))
        colors.append((float(r), float(g), float(b), 1.0))
    return colors


def fleet_colors(robots: Sequence[str], physical: Iterable[str] = ()) -> list[Color]:
    """The colour of each robot of a run, in the order of ``robots``: every figure uses it.

    The physical robots (their twins) are red, as in the paper's mixed-reality figures;
    the virtual robots take, in fleet order, the distinct colours of :func:`robot_colors`,
    which has no red. A robot's colour depends only on the fleet and which robots are
    physical, so it is the same in every figure and frame of a run.

    Args:
        robots: robot names in fleet order (``RunData.track.robots``).
        physical: names of the physical robots (``scenario.physical.robots``).
    """
    physical = set(physical)
    virtual = iter(robot_colors(sum(1 for r in robots if r not in physical)))
    return [PHYSICAL_COLOR if r in physical else next(virtual) for r in robots]


def run_colors(run: RunData) -> list[Color]:
    """:func:`fleet_colors` of a run's fleet (``run.track.robots``)."""
    return fleet_colors(list(run.track.robots), run.scenario.physical.robots)


def short_label(robot: str) -> str:
    """A robot's name shortened for labels on a crowded map: ``robot_12`` -> ``12``."""
    match = re.fullmatch(r"robot_(\d+)", robot)
    return match.group(1) if match else robot
