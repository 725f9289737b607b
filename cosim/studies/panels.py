"""The panels of a study figure: a facet grid, labels in words, a caption, PNG and CSV out."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from cosim.core.errors import ExportError
from cosim.studies.labels import axis_label, short_label

DPI = 150
PANELS_PER_ROW = 3
"""Facet panels per row of a figure; more values wrap onto further rows."""


def panels(
    stats: pd.DataFrame, facet: str | None, *, width_in: float
) -> tuple[list[object], Figure, list[Axes]]:
    """A panel per facet value, wrapped into rows of at most :data:`PANELS_PER_ROW`.

    The panels share the y axis; unused cells of the last row are removed, so the axes
    returned (in row-major order) are exactly one per facet value.
    """
    facets: list[object] = levels(stats[facet]) if facet else [None]
    cols = min(len(facets), PANELS_PER_ROW)
    rows = -(-len(facets) // cols)
    figure = Figure(figsize=(width_in * cols + 1.0, 3.8 * rows + 0.5), layout="constrained")
    grid = figure.subplots(rows, cols, sharey=True, squeeze=False)
    cells: list[Axes] = list(grid.flat)
    for ax in cells[len(facets) :]:
        figure.delaxes(ax)
    axes = cells[: len(facets)]
    for ax, value in zip(axes, facets, strict=True):
        if facet:
            ax.set_title(f"{short_label(facet)} = {value_label(value)}", fontsize=10)
    return facets, figure, axes


def label_axes(axes: list[Axes], x: str, y: str) -> None:
    """Label x under the panels with none below them, y left of each row of :func:`panels`."""
    cols = min(len(axes), PANELS_PER_ROW)
    for k, ax in enumerate(axes):
        if k + cols >= len(axes):
            ax.set_xlabel(axis_label(x))
        if k % cols == 0:
            ax.set_ylabel(axis_label(y))


def save_figure(figure: Figure, path: Path, *, data: pd.DataFrame | None = None) -> Path:
    """Write a figure as PNG (Agg, without pyplot), making its folder; ExportError if not.

    ``data``, what the figure draws, goes beside it as ``<figure>.csv``.
    """
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        FigureCanvasAgg(figure)  # attaches itself: savefig renders with Agg, not pyplot
        figure.savefig(path, format="png", dpi=DPI)
        if data is not None:
            data.to_csv(path.with_suffix(".csv"), index=False)
    except OSError as error:
        raise ExportError(f"{path}: cannot write: {error.strerror or error}") from None
    return path


def caption(figure: Figure, title: str, note: str) -> None:
    """The figure's title, and under it ``note``: what the band is and its n."""
    figure.suptitle(f"{title}\n{note}", fontsize=10)


def value_label(value: object) -> str:
    """A grid value as ticks and legends show it (floats without trailing zeros)."""
    return f"{value:g}" if isinstance(value, float | np.floating) else str(value)


def levels(series: pd.Series) -> list[object]:
    """Distinct values but nulls: numbers and booleans ascending, others as they appear."""
    values = series.dropna().drop_duplicates()
    return list(values.sort_values() if pd.api.types.is_numeric_dtype(series) else values)
