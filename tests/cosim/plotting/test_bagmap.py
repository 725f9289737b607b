"""The picture of a mapped recording: the map, then the estimated, odometry and reference paths."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.figure import Figure

from cosim.plotting import bagmap
from cosim.plotting.bagmap import bag_map_figure
from models.mapping.grid import LogOddsMap, MapGeometry
from tests.cosim.plotting.conftest import PNG_MAGIC

RESOLUTION_M = 0.5
ORIGIN = (-2.0, -1.0)


def _grid() -> LogOddsMap:
    """A 10 m x 5 m grid: free cells in x 0-4 m, y 0-2 m (its rows 2-5, columns 4-11), an
    occupied row along y = 2 m, everything else unknown."""
    grid = LogOddsMap(MapGeometry(ORIGIN, RESOLUTION_M, width=20, height=10))
    grid.logodds[2:6, 4:12] = -2.0  # free
    grid.logodds[6, 4:12] = 3.0  # occupied
    return grid


PATH = np.array([[0.0, 0.0], [2.0, 0.5], [4.0, 1.0]])


@pytest.fixture
def drawn(monkeypatch: pytest.MonkeyPatch) -> list[Figure]:
    """The figures drawn, not rendered to files."""
    figures: list[Figure] = []
    monkeypatch.setattr(bagmap, "save_png", lambda figure, path: figures.append(figure) or path)
    return figures


def test_the_map_is_black_occupied_white_free_grey_unknown_placed_in_frame_map(drawn, tmp_path):
    bag_map_figure(_grid(), PATH, PATH + 0.2, None, tmp_path / "map.png", "hall")
    ax = drawn[0].axes[0]
    (image,) = ax.get_images()
    shade = np.asarray(image.get_array())
    assert shade[6, 4] == 0.0 and shade[3, 5] == 1.0 and shade[0, 0] == 0.8
    assert image.origin == "lower"
    assert image.get_extent() == pytest.approx([-2.0, 8.0, -1.0, 4.0])
    assert (ax.get_xlabel(), ax.get_ylabel(), ax.get_title()) == (
        "x (m, map)",
        "y (m, map)",
        "hall",
    )


def test_the_view_is_the_known_cells_and_a_metre_around_them(drawn, tmp_path):
    bag_map_figure(_grid(), PATH, PATH, None, tmp_path / "map.png", "hall")
    ax = drawn[0].axes[0]
    # known: columns 4-11 (x 0 to 4 m), rows 2-6 (y 0 to 2.5 m)
    assert ax.get_xlim() == pytest.approx((-1.0, 5.0))
    assert ax.get_ylim() == pytest.approx((-1.0, 3.5))
    assert ax.get_aspect() == 1.0


def test_odometry_dashed_reference_if_given_then_the_estimate_on_top(drawn, tmp_path):
    reference = PATH - 0.1
    bag_map_figure(_grid(), PATH, PATH + 0.2, reference, tmp_path / "a.png", "with")
    bag_map_figure(_grid(), PATH, PATH + 0.2, None, tmp_path / "b.png", "without")
    lines = drawn[0].axes[0].get_lines()
    assert [line.get_label() for line in lines] == ["odometry", "reference (aligned)", "estimate"]
    odometry, aligned, estimate = lines
    assert odometry.get_linestyle() == "--"
    np.testing.assert_allclose(odometry.get_xydata(), PATH + 0.2)
    np.testing.assert_allclose(aligned.get_xydata(), reference)
    np.testing.assert_allclose(estimate.get_xydata(), PATH)
    legend = drawn[0].axes[0].get_legend()
    assert [t.get_text() for t in legend.get_texts()] == [line.get_label() for line in lines]
    assert [line.get_label() for line in drawn[1].axes[0].get_lines()] == ["odometry", "estimate"]


def test_a_map_with_nothing_known_keeps_the_view_of_the_paths(drawn, tmp_path):
    empty = LogOddsMap(MapGeometry(ORIGIN, RESOLUTION_M, width=20, height=10))
    bag_map_figure(empty, PATH, PATH, None, tmp_path / "map.png", "nothing seen")
    ax = drawn[0].axes[0]
    x0, x1 = ax.get_xlim()
    assert x0 <= 0.0 and x1 >= 4.0  # the paths stay in view


def test_the_picture_is_written_as_a_png(tmp_path):
    path = bag_map_figure(_grid(), PATH, PATH, PATH, tmp_path / "maps" / "map.png", "hall")
    assert path == tmp_path / "maps" / "map.png"
    assert path.read_bytes().startswith(PNG_MAGIC)
