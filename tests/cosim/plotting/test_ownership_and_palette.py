"""Who holds a task when, one colour per robot, the paper's snapshot times and goals."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.figure import Figure

import cosim
from cosim.plotting import timeline, trajectories
from cosim.plotting.canvas import PHYSICAL_COLOR, fleet_colors
from cosim.plotting.command import snapshot_times
from cosim.plotting.fleet import WAITING_COLOR, FleetLayer
from cosim.plotting.goals import GoalLayer, distinct_goals
from cosim.plotting.ownership import holder_at, task_holds
from cosim.plotting.rundata import RunData, load_run
from tests.conftest import SMALL
from tests.cosim.plotting.conftest import TASKS

STATION = (2.0, 3.0)


def _tasks() -> pd.DataFrame:
    """Task 0: robot_1 claims it at 1 s, releases it at 10 s; robot_2 claims it at 12 s and
    completes it at 20 s. Task 1: robot_1 claims it at 2 s, releases it at 15 s, no one
    else takes it."""
    return pd.DataFrame(
        {
            "task": [0.0, 1.0],
            "x_m": [STATION[0], 5.0],
            "y_m": [STATION[1], 5.0],
            "t_created_s": [0.0, 0.0],
            "t_assigned_s": [1.0, 2.0],
            "robot": ["robot_2", ""],
            "t_started_s": [18.0, np.nan],
            "t_completed_s": [20.0, np.nan],
        }
    )


def _navigation() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "t_s": [1.0, 2.0, 12.0],
            "robot": ["robot_1", "robot_1", "robot_2"],
            "event": ["goal", "goal", "goal"],
            "goal_x_m": [STATION[0], 5.0, STATION[0]],
            "goal_y_m": [STATION[1], 5.0, STATION[1]],
        }
    )


def _events() -> pd.DataFrame:
    return pd.DataFrame(
        {
            "t_s": [10.0, 15.0],
            "source": ["robot_1", "robot_1"],
            "kind": ["release", "release"],
            "detail": ["task 0: stuck", "task 1: stuck"],
        }
    )


def test_a_released_task_passes_to_its_next_claimer_and_is_held_by_no_one_in_between() -> None:
    holds = task_holds(_tasks(), _navigation(), _events())
    assert holder_at(holds, 5.0) == {0.0: "robot_1", 1.0: "robot_1"}
    assert holder_at(holds, 11.0) == {1.0: "robot_1"}  # task 0 released, not yet claimed
    assert holder_at(holds, 13.0) == {0.0: "robot_2", 1.0: "robot_1"}
    assert holder_at(holds, 16.0) == {0.0: "robot_2"}  # task 1 released for good
    assert holder_at(holds, 25.0) == {}
    assert list(holds["end"]) == ["released", "completed", "released"]


def test_a_released_task_is_drawn_waiting_in_a_snapshot_not_held(task_run: Path) -> None:
    run = load_run(task_run)
    tasks, nav, events = _tasks(), _navigation(), _events()
    # the run's samples spread over 0-30 s, the synthetic table's times
    track = dataclasses.replace(run.track, t_s=np.linspace(0.0, 30.0, len(run.track.t_s)))
    synthetic = dataclasses.replace(
        run, track=track, tasks=tasks, holds=task_holds(tasks, nav, events), navigation=nav
    )
    ax = Figure().add_subplot()
    layer = FleetLayer(ax, synthetic, fleet_colors(list(run.track.robots)))
    layer.show(track.index_at(16.0))
    faces = layer.stations.get_facecolor()
    assert len(faces) == 2  # both open at 16 s: task 1 released, task 0 claimed again at 12 s
    assert tuple(faces[0]) == (1.0, 1.0, 1.0, 1.0)  # task 1: white, held by no one
    assert WAITING_COLOR == "white"
    assert np.allclose(faces[1], layer.colors[1])  # task 0: robot_2's colour
    (link,) = layer.links.get_segments()  # one link, from robot_2, none from robot_1
    assert np.allclose(
        link[0], [track.x_m[track.index_at(16.0), 1], track.y_m[track.index_at(16.0), 1]]
    )
    assert np.allclose(link[1], STATION)


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


def test_the_default_snapshots_of_the_paper_scenario_3_include_t_25_s() -> None:
    scenario = cosim.load_scenario("lab-mixed")
    run = SimpleNamespace(
        scenario=scenario, track=SimpleNamespace(t_s=np.arange(0.0, 59.95, 0.1)), path=Path(".")
    )
    times = snapshot_times(run, None)  # type: ignore[arg-type]
    assert 25.0 in times
    assert times == sorted(times) and max(times) <= 59.9 + 1e-9


def test_the_goals_of_a_goals_driver_run_are_drawn(tmp_path: Path) -> None:
    goals = [[2.0, 2.0], [9.0, 9.0], [2.0, 9.0]]
    overrides = {**SMALL, "robots.driver": "navigation", "navigation.goals": goals}
    cosim.run(cosim.load_scenario("warehouse-random", overrides=overrides), out=tmp_path / "g")
    run: RunData = load_run(tmp_path / "g")
    drawn = {(round(x, 3), round(y, 3)) for x, y, _ in distinct_goals(run)}
    assert drawn and drawn <= {(2.0, 2.0), (9.0, 9.0), (2.0, 9.0)}
    ax = Figure().add_subplot()
    trajectories.draw_goals(ax, run, fleet_colors(list(run.track.robots)))
    stars = [c for c in ax.collections if len(c.get_offsets())]
    assert {tuple(p) for p in np.round(stars[0].get_offsets(), 3)} == drawn
    layer = GoalLayer(ax, run, fleet_colors(list(run.track.robots)))
    end = len(run.track.t_s) - 1
    layer.show(float(run.track.t_s[end]), run.track.x_m[end], run.track.y_m[end])
    assert len(layer.markers.get_offsets()) == len(run.track.robots)
