"""What every figure of a run shares: robot colours (physical red, virtual never), PNG files."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib import colormaps
from matplotlib.figure import Figure

import cosim
from cosim.core.errors import ExportError
from cosim.plotting import timeline, trajectories
from cosim.plotting.canvas import (
    PHYSICAL_COLOR,
    fleet_colors,
    robot_colors,
    run_colors,
    save_png,
    short_label,
)
from cosim.plotting.rundata import load_run
from tests.cosim.plotting.conftest import PNG_MAGIC, TASKS


def test_the_physical_robot_is_red_and_every_virtual_robot_has_its_own_colour() -> None:
    robots = [f"robot_{i}" for i in range(1, 5)]
    colors = fleet_colors(robots, ("robot_1",))
    assert colors[0] == PHYSICAL_COLOR
    assert len(set(colors)) == 4


@settings(max_examples=30, deadline=None)
@given(count=st.integers(1, 60), physical=st.sets(st.integers(0, 59), max_size=3))
def test_no_virtual_robot_is_ever_red(count: int, physical: set[int]) -> None:
    robots = [f"robot_{i + 1}" for i in range(count)]
    chosen = tuple(robots[i] for i in physical if i < count)
    colors = fleet_colors(robots, chosen)
    red = np.array(PHYSICAL_COLOR[:3])
    for robot, color in zip(robots, colors, strict=True):
        if robot in chosen:
            assert color == PHYSICAL_COLOR
        else:
            assert np.linalg.norm(np.array(color[:3]) - red) > 0.3, (robot, color)
    assert len(set(colors[i] for i in range(count) if robots[i] not in chosen)) == count - len(
        chosen
    )


def _drawn(monkeypatch: pytest.MonkeyPatch, module: Any) -> list[Figure]:
    figures: list[Figure] = []
    monkeypatch.setattr(module, "save_png", lambda figure, path: figures.append(figure) or path)
    return figures


def test_a_robot_has_the_same_colour_in_the_trajectories_and_the_task_timeline(
    task_run: Path, monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    run = load_run(task_run)
    overrides = {**TASKS, "physical.robots": ["robot_2"]}
    run = dataclasses.replace(
        run, scenario=cosim.load_scenario("warehouse-random", overrides=overrides)
    )
    drawn_paths = _drawn(monkeypatch, trajectories)
    drawn_lanes = _drawn(monkeypatch, timeline)
    trajectories.trajectories_figure(run, tmp_path / "t.png")
    timeline.timeline_figure(run, tmp_path / "k.png")
    legend = drawn_paths[0].legends[0]
    in_paths = {
        h.get_label().split(" ")[0]: h.get_color()
        for h in legend.legend_handles
        if h.get_label().startswith("robot_")
    }
    lanes = drawn_lanes[0].axes[0].get_yticklabels()
    in_lanes = {t.get_text().split(" ")[0]: t.get_color() for t in lanes}
    assert set(in_paths) == set(run.track.robots)
    for robot, color in in_paths.items():
        assert np.allclose(np.array(color)[:3], np.array(in_lanes[robot])[:3]), robot
    assert np.allclose(in_paths["robot_2"], PHYSICAL_COLOR)


def test_small_fleets_take_tableau_10_then_tableau_20_without_red_then_a_wheel_of_hues():
    tab10, tab20 = colormaps["tab10"], colormaps["tab20"]
    assert robot_colors(3) == [tab10(0), tab10(1), tab10(2)]  # blue, orange, green
    assert tab10(3) not in robot_colors(9)  # Tableau's red
    assert robot_colors(9)[-1] == tab10(7)  # grey last
    assert robot_colors(10)[0] == tab20(0) and tab20(6) not in robot_colors(18)
    wheel = robot_colors(40)
    assert len(set(wheel)) == 40 and all(len(c) == 4 and c[3] == 1.0 for c in wheel)
    assert robot_colors(0) == []


def test_a_robot_s_colour_depends_only_on_the_fleet_and_which_robots_are_physical():
    robots = ["robot_1", "robot_2", "robot_3"]
    assert fleet_colors(robots, ("robot_2",)) == fleet_colors(list(robots), ["robot_2"])
    # the virtual robots keep their order of colours around the physical one
    assert fleet_colors(robots, ("robot_2",))[2] == fleet_colors(robots)[1]


def test_a_run_s_colours_follow_its_scenario_s_physical_robots(task_run: Path):
    run = load_run(task_run)
    assert run_colors(run) == fleet_colors(list(run.track.robots))
    physical = cosim.load_scenario("warehouse-random", {**TASKS, "physical.robots": ["robot_3"]})
    assert run_colors(dataclasses.replace(run, scenario=physical))[2] == PHYSICAL_COLOR


@pytest.mark.parametrize(
    ("robot", "label"),
    [("robot_12", "12"), ("robot_1", "1"), ("base", "base"), ("robot_x", "robot_x")],
)
def test_a_robot_s_short_label_is_its_number(robot, label):
    assert short_label(robot) == label


def test_a_figure_is_written_as_a_png_into_a_folder_made_for_it(tmp_path: Path):
    figure = Figure(figsize=(2.0, 1.0))
    figure.add_subplot().plot([0, 1], [0, 1])
    path = save_png(figure, tmp_path / "new" / "line.png", dpi=50)
    assert path == tmp_path / "new" / "line.png"
    assert path.read_bytes().startswith(PNG_MAGIC)


def test_a_png_that_cannot_be_written_is_an_export_error_naming_the_path(tmp_path: Path):
    blocker = tmp_path / "figures"
    blocker.write_text("a file in the way", encoding="utf-8")
    with pytest.raises(ExportError) as refused:
        save_png(Figure(), blocker / "line.png")
    assert str(refused.value).startswith(f"{blocker / 'line.png'}: cannot write: ")
