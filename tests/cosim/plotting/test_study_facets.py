"""The facet grid of the study figures (cosim.studies.analysis), which wraps after 3 panels."""

import pandas as pd
import pytest

from cosim.studies.analysis import metric_figure

X, HUE, FACET = "network.latency_ms", "assignment.protocol", "network.loss_prob"


def _results(facets: int) -> pd.DataFrame:
    rows = [
        {
            "run_id": f"{loss}-{latency}-{protocol}-{seed}",
            "seed": seed,
            X: latency,
            HUE: protocol,
            FACET: loss,
            "tasks_per_min": 10.0 - loss - 0.01 * latency + 0.1 * seed,
            "status": "ok",
        }
        for loss in [0.1 * k for k in range(facets)]
        for latency in (0, 50, 200)
        for protocol in ("simplex", "cbba")
        for seed in (1, 2)
    ]
    return pd.DataFrame(rows)


def _grid(figure) -> list[tuple[int, int]]:
    """(row, column) of each panel, leaving out colour bars."""
    cells = []
    for ax in figure.axes:
        spec = ax.get_subplotspec()
        cells.append((spec.rowspan.start, spec.colspan.start))
    return cells


def test_a_facet_grid_with_six_values_has_two_rows_of_three():
    figure = metric_figure(_results(6), X, "tasks_per_min", hue=HUE, facet=FACET)
    assert _grid(figure) == [(0, 0), (0, 1), (0, 2), (1, 0), (1, 1), (1, 2)]
    y, x = "Tasks per minute", "Network latency (ms)"
    assert [ax.get_ylabel() for ax in figure.axes] == [y, "", "", y, "", ""]
    assert [ax.get_xlabel() for ax in figure.axes] == ["", "", "", x, x, x]
    assert figure.axes[0].get_shared_y_axes().joined(figure.axes[0], figure.axes[5])


@pytest.mark.parametrize(("facets", "rows"), [(1, 1), (3, 1), (4, 2), (7, 3)])
def test_facets_wrap_after_three_panels_and_leave_no_empty_panel(facets, rows):
    figure = metric_figure(_results(facets), X, "tasks_per_min", hue=HUE, facet=FACET)
    cells = _grid(figure)
    assert len(cells) == facets
    assert max(r for r, _ in cells) + 1 == rows
    assert max(c for _, c in cells) + 1 == min(facets, 3)


def test_the_hue_legend_sits_beside_the_first_row_outside_the_panels():
    figure = metric_figure(_results(6), X, "tasks_per_min", hue=HUE, facet=FACET)
    legends = [ax for ax in figure.axes if ax.get_legend() is not None]
    assert legends == [figure.axes[2]]
    assert legends[0].get_legend().get_bbox_to_anchor().x0 > figure.axes[2].bbox.x1
