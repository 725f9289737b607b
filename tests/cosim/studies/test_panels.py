"""The panels of a study figure: a facet grid, labels in words, a caption, PNG and CSV out."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from cosim.core.errors import ExportError
from cosim.studies.panels import (
    PANELS_PER_ROW,
    caption,
    label_axes,
    levels,
    panels,
    save_figure,
    value_label,
)

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
FACET = "network.loss_prob"


def _stats(values: list[object]) -> pd.DataFrame:
    return pd.DataFrame({FACET: values, "mean": range(len(values))})


@pytest.mark.parametrize(("count", "rows", "cols"), [(1, 1, 1), (3, 1, 3), (4, 2, 3), (7, 3, 3)])
def test_a_panel_per_facet_value_wrapped_after_three_with_no_empty_cell(count, rows, cols):
    facets, figure, axes = panels(_stats([0.1 * k for k in range(count)]), FACET, width_in=4.0)
    assert len(facets) == len(axes) == len(figure.axes) == count
    cells = [
        (ax.get_subplotspec().rowspan.start, ax.get_subplotspec().colspan.start) for ax in axes
    ]
    assert cells == [(k // PANELS_PER_ROW, k % PANELS_PER_ROW) for k in range(count)]
    assert max(r for r, _ in cells) + 1 == rows and max(c for _, c in cells) + 1 == cols
    assert figure.get_size_inches()[0] == pytest.approx(4.0 * cols + 1.0)


def test_each_panel_is_titled_with_its_facet_in_words_and_the_panels_share_y():
    facets, _, axes = panels(_stats([0.3, 0.0, 0.3, 0.15]), FACET, width_in=4.0)
    assert facets == [0.0, 0.15, 0.3]
    assert [ax.get_title() for ax in axes] == [
        "Message loss probability = 0",
        "Message loss probability = 0.15",
        "Message loss probability = 0.3",
    ]
    assert axes[0].get_shared_y_axes().joined(axes[0], axes[2])


def test_without_a_facet_there_is_one_untitled_panel():
    facets, _, axes = panels(_stats([1, 2]), None, width_in=5.0)
    assert facets == [None] and len(axes) == 1 and axes[0].get_title() == ""


def test_x_is_labelled_under_the_bottom_panels_and_y_left_of_each_row():
    _, _, axes = panels(_stats([0.1 * k for k in range(5)]), FACET, width_in=4.0)
    label_axes(axes, "network.latency_ms", "tasks_per_min")
    x = "Network latency (ms)"
    assert [ax.get_xlabel() for ax in axes] == ["", "", x, x, x]  # the third: none below it
    assert [ax.get_ylabel() for ax in axes] == ["Tasks per minute", "", "", "Tasks per minute", ""]


def test_values_are_shown_as_ticks_show_them():
    assert value_label(0.5) == "0.5" and value_label(100.0) == "100"
    assert value_label(np.float32(0.25)) == "0.25"
    assert value_label(3) == "3" and value_label("cbba") == "cbba" and value_label(True) == "True"


def test_levels_are_distinct_non_null_values_numbers_ascending_others_as_they_appear():
    assert levels(pd.Series([3.0, None, 1.0, 3.0, 2.0])) == [1.0, 2.0, 3.0]
    assert levels(pd.Series(["simplex", "cbba", None, "simplex"])) == ["simplex", "cbba"]
    assert levels(pd.Series([True, False, True])) == [False, True]
    assert levels(pd.Series([], dtype=float)) == []


def test_a_figure_is_written_as_png_with_the_data_it_draws_beside_it(tmp_path):
    _, figure, _ = panels(_stats([1, 2]), FACET, width_in=3.0)
    caption(figure, "Tasks per minute", "mean and 95 % interval, n = 3 seeds")
    assert figure.get_suptitle() == "Tasks per minute\nmean and 95 % interval, n = 3 seeds"
    data = pd.DataFrame({FACET: [1, 2], "mean": [0.5, 0.75]})
    path = save_figure(figure, tmp_path / "figures" / "tasks.png", data=data)
    assert path == tmp_path / "figures" / "tasks.png"
    assert path.read_bytes().startswith(PNG_MAGIC)
    pd.testing.assert_frame_equal(pd.read_csv(path.with_suffix(".csv")), data)


def test_a_figure_without_data_has_no_csv(tmp_path):
    _, figure, _ = panels(_stats([1]), None, width_in=3.0)
    save_figure(figure, tmp_path / "plain.png")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plain.png"]


def test_a_figure_that_cannot_be_written_is_an_export_error_naming_the_path(tmp_path):
    blocker = tmp_path / "figures"
    blocker.write_text("a file in the way", encoding="utf-8")
    _, figure, _ = panels(_stats([1]), None, width_in=3.0)
    with pytest.raises(ExportError) as refused:
        save_figure(figure, blocker / "tasks.png")
    assert str(refused.value).startswith(f"{blocker / 'tasks.png'}: cannot write: ")
