"""The world on an axes (walls, shelves, obstacles in ``map``, m) and ``cosim world --png``."""

from __future__ import annotations

import math

import numpy as np
import pytest
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure
from matplotlib.patches import Circle

import cosim
from adapters.world.warehouse import scenario_warehouse
from cosim.plotting import world
from cosim.plotting.world import (
    MARGIN_M,
    OBSTACLE_COLOR,
    ROBOT_COLOR,
    SHELF_COLOR,
    SHELF_MUTED,
    WALL_COLOR,
    draw_world,
    world_figure,
    world_handles,
    world_inches,
)
from models.world.warehouse import Warehouse
from tests.cosim.plotting.conftest import PNG_MAGIC


def _warehouse(**overrides: object) -> Warehouse:
    base = {"world.size_m": [16.0, 12.0], "world.shelf_count": 4, "robots.count": 3}
    return scenario_warehouse(cosim.load_scenario("warehouse-random", {**base, **overrides}))


@pytest.fixture(scope="module")
def hall() -> Warehouse:
    """16 m x 12 m, 4 shelves, an extra obstacle, 3 robots."""
    return _warehouse(**{"world.obstacles": [[5.0, 5.0, 6.0, 6.5]]})


def test_walls_shelves_and_obstacles_are_drawn_as_boxes_in_their_colours(hall: Warehouse):
    ax = Figure().add_subplot()
    draw_world(ax, hall)
    walls, shelves, obstacles = ax.collections
    assert len(walls.get_paths()) == 4
    assert len(shelves.get_paths()) == len(hall.shelves) == 4
    assert len(obstacles.get_paths()) == 1
    assert tuple(walls.get_facecolor()[0]) == pytest.approx(to_rgba(WALL_COLOR))
    assert tuple(shelves.get_facecolor()[0]) == pytest.approx(to_rgba(SHELF_COLOR))
    assert tuple(obstacles.get_facecolor()[0]) == pytest.approx(to_rgba(OBSTACLE_COLOR))
    corners = obstacles.get_paths()[0].vertices
    assert corners.min(axis=0) == pytest.approx([5.0, 5.0])
    assert corners.max(axis=0) == pytest.approx([6.0, 6.5])


def test_the_axes_are_the_world_and_a_margin_in_equal_metres_of_frame_map(hall: Warehouse):
    ax = Figure().add_subplot()
    draw_world(ax, hall)
    xmin, ymin, xmax, ymax = hall.bounds
    assert ax.get_xlim() == pytest.approx((xmin - MARGIN_M, xmax + MARGIN_M))
    assert ax.get_ylim() == pytest.approx((ymin - MARGIN_M, ymax + MARGIN_M))
    assert ax.get_aspect() == 1.0
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x (m, map)", "y (m, map)")
    bare = Figure().add_subplot()
    draw_world(bare, hall, shelf_color=SHELF_MUTED, labels=False)
    assert (bare.get_xlabel(), bare.get_ylabel()) == ("", "")
    assert tuple(bare.collections[1].get_facecolor()[0]) == pytest.approx(to_rgba(SHELF_MUTED))


def test_the_legend_names_only_what_the_world_has(hall: Warehouse):
    assert [h.get_label() for h in world_handles(hall)] == ["walls", "shelves", "obstacles"]
    empty = _warehouse(**{"world.shelf_count": 0})
    assert [h.get_label() for h in world_handles(empty)] == ["walls"]


@pytest.mark.parametrize("longer_in", [4.0, 8.0])
def test_a_world_figure_keeps_the_world_s_aspect_with_its_longer_side_given(hall, longer_in):
    width, height = world_inches(hall, longer_in)
    assert max(width, height) == pytest.approx(longer_in)
    assert width / height == pytest.approx((16.4 + 2 * MARGIN_M) / (12.4 + 2 * MARGIN_M))


def test_cosim_world_png_draws_each_start_pose_as_a_circle_with_a_heading_tick(
    hall: Warehouse, tmp_path, monkeypatch
):
    figures: list[Figure] = []
    original = world.save_png
    monkeypatch.setattr(
        world, "save_png", lambda figure, path: figures.append(figure) or original(figure, path)
    )
    path = world_figure(hall, tmp_path / "w" / "world.png", title="hall", robot_radius_m=0.4)
    assert path.read_bytes().startswith(PNG_MAGIC)
    ax = figures[0].axes[0]
    assert ax.get_title() == "hall"
    circles = [p for p in ax.patches if isinstance(p, Circle)]
    assert len(circles) == len(hall.starts) == 3
    for circle, (x, y, _yaw) in zip(circles, hall.starts, strict=True):
        assert circle.center == pytest.approx((x, y)) and circle.radius == 0.4
    ticks = [line.get_xydata() for line in ax.get_lines()]
    for tick, (x, y, yaw) in zip(ticks, hall.starts, strict=True):
        np.testing.assert_allclose(
            tick[1] - tick[0], 0.4 * np.array([math.cos(yaw), math.sin(yaw)]), atol=1e-12
        )
        assert tick[0] == pytest.approx((x, y))
    assert [t.get_text() for t in ax.texts] == ["robot_1", "robot_2", "robot_3"]
    assert all(t.get_rotation() == 90 for t in ax.texts)
    legend = ax.get_legend()
    assert [t.get_text() for t in legend.get_texts()] == [
        "walls", "shelves", "obstacles", "robot starts",
    ]  # fmt: skip
    assert to_rgba(circles[0].get_edgecolor()) == pytest.approx(to_rgba(ROBOT_COLOR))


def test_start_labels_shrink_for_fleets_of_more_than_ten(tmp_path, monkeypatch):
    figures: list[Figure] = []
    monkeypatch.setattr(world, "save_png", lambda figure, path: figures.append(figure) or path)
    world_figure(
        _warehouse(**{"robots.count": 11, "world.size_m": [20.0, 20.0]}),
        tmp_path / "w.png",
        title="t",
    )
    sizes = {t.get_fontsize() for t in figures[0].axes[0].texts}
    assert sizes == {3.5}
