"""The navigation goals of a run without tasks: every goal numbered, each robot's current one."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure
from matplotlib.text import Annotation

import cosim
from cosim.plotting import trajectories
from cosim.plotting.canvas import fleet_colors
from cosim.plotting.goals import (
    GOAL_IDS_MAX,
    GoalLayer,
    distinct_goals,
    draw_goals,
    goal_events,
    goal_handles,
)
from cosim.plotting.rundata import RunData, load_run
from tests.conftest import SMALL


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


def _navigation(*rows: tuple[float, str, str, float, float]) -> pd.DataFrame:
    """Navigation events: (t_s, robot, event, goal_x_m, goal_y_m) each."""
    return pd.DataFrame(rows, columns=["t_s", "robot", "event", "goal_x_m", "goal_y_m"])


SENT = _navigation(
    (4.0, "robot_2", "goal", 9.0, 9.0),
    (1.0, "robot_1", "goal", 2.0, 2.0),
    (2.0, "robot_1", "arrived", 2.0, 2.0),
    (3.0, "robot_1", "goal", 9.0004, 9.0),  # the same goal as robot_2's, within 1 mm
    (5.0, "robot_3", "goal", 2.0, 9.0),
)


@pytest.fixture(scope="module")
def goals_run(waypoint_run: Path) -> RunData:
    """The waypoint run (3 robots, no task) with the goals of :data:`SENT`."""
    return dataclasses.replace(load_run(waypoint_run), navigation=SENT)


def test_the_goals_sent_are_the_goal_events_in_time_order(goals_run: RunData):
    events = goal_events(goals_run)
    assert list(events.columns) == ["t_s", "robot", "goal_x_m", "goal_y_m"]
    assert events["t_s"].tolist() == [1.0, 3.0, 4.0, 5.0]


def test_a_run_with_tasks_or_without_navigation_has_no_goals_to_draw(goals_run: RunData):
    with_tasks = dataclasses.replace(goals_run, tasks=pd.DataFrame({"task": [0.0]}))
    assert goal_events(with_tasks).empty
    without = dataclasses.replace(goals_run, navigation=None)
    assert goal_events(without).empty and distinct_goals(without) == []
    assert draw_goals(Figure().add_subplot(), without, []) is None
    assert goal_handles(without) == []


def test_goals_closer_than_a_millimetre_are_one_in_the_order_first_sent(goals_run: RunData):
    assert distinct_goals(goals_run) == [
        (2.0, 2.0, "robot_1"),
        (9.0004, 9.0, "robot_1"),  # robot_1 was sent there before robot_2
        (2.0, 9.0, "robot_3"),
    ]


def test_each_goal_is_a_star_edged_in_its_first_robot_s_colour_numbered_in_order(
    goals_run: RunData,
):
    ax = Figure().add_subplot()
    colors = fleet_colors(list(goals_run.track.robots))
    markers = draw_goals(ax, goals_run, colors)
    assert markers is not None
    np.testing.assert_allclose(markers.get_offsets(), [[2.0, 2.0], [9.0004, 9.0], [2.0, 9.0]])
    np.testing.assert_allclose(markers.get_edgecolor(), [colors[0], colors[0], colors[2]])
    numbers = [t.get_text() for t in ax.texts if isinstance(t, Annotation)]
    assert numbers == ["g1", "g2", "g3"]
    (handle,) = goal_handles(goals_run)
    assert handle.get_label() == "goal (g1, g2...: order sent)"


def test_goals_are_not_numbered_beyond_the_most_a_map_can_hold(goals_run: RunData):
    many = _navigation(
        *[(float(k), "robot_1", "goal", float(k), 1.0) for k in range(GOAL_IDS_MAX + 1)]
    )
    ax = Figure().add_subplot()
    markers = draw_goals(
        ax,
        dataclasses.replace(goals_run, navigation=many),
        fleet_colors(list(goals_run.track.robots)),
    )
    assert markers is not None and len(markers.get_offsets()) == GOAL_IDS_MAX + 1
    assert len(ax.texts) == 0


def test_each_robot_s_current_goal_is_the_last_sent_by_then_with_a_line_from_the_robot(
    goals_run: RunData,
):
    colors = fleet_colors(list(goals_run.track.robots))
    layer = GoalLayer(Figure().add_subplot(), goals_run, colors)
    assert layer.current(0.5) == {}
    assert layer.current(3.0) == {"robot_1": (9.0004, 9.0)}
    assert layer.current(10.0) == {
        "robot_1": (9.0004, 9.0),
        "robot_2": (9.0, 9.0),
        "robot_3": (2.0, 9.0),
    }
    x, y = np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 0.0])
    layer.show(4.5, x, y)  # robot_1 and robot_2 have goals, robot_3 not yet
    np.testing.assert_allclose(layer.markers.get_offsets(), [[9.0004, 9.0], [9.0, 9.0]])
    links = layer.links.get_segments()
    np.testing.assert_allclose(links[0], [[1.0, 0.0], [9.0004, 9.0]])
    np.testing.assert_allclose(links[1], [[2.0, 0.0], [9.0, 9.0]])
    np.testing.assert_allclose(layer.links.get_colors(), [colors[0], colors[1]])
    layer.show(0.0, x, y)
    assert len(layer.markers.get_offsets()) == 0 and layer.links.get_segments() == []
