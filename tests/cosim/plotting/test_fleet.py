"""The fleet at one instant: robots with heading ticks, their recent trails, open tasks."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.figure import Figure

import cosim
from cosim.plotting.canvas import LEGEND_ROBOTS_MAX, fleet_colors
from cosim.plotting.fleet import (
    TRAIL_S,
    WAITING_COLOR,
    FleetLayer,
    TaskTimes,
    fleet_handles,
    robot_label,
)
from cosim.plotting.ownership import task_holds
from cosim.plotting.rundata import RunData, load_run
from tests.cosim.plotting.conftest import TASKS
from tests.cosim.plotting.holdings import (
    FLEET,
    STATION,
    events_table,
    navigation_table,
    tasks_table,
)


def _synthetic(run: RunData) -> RunData:
    """``run`` with the synthetic tasks of ``holdings`` and its samples spread over 0-30 s."""
    tasks, nav, events = tasks_table(), navigation_table(), events_table()
    track = dataclasses.replace(run.track, t_s=np.linspace(0.0, 30.0, len(run.track.t_s)))
    return dataclasses.replace(
        run,
        track=track,
        tasks=tasks,
        holds=task_holds(tasks, nav, events, robots=FLEET),
        navigation=nav,
    )


def test_a_released_task_is_drawn_waiting_in_a_snapshot_not_held(task_run: Path) -> None:
    run = load_run(task_run)
    synthetic = _synthetic(run)
    track = synthetic.track
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


def test_a_task_is_open_from_its_creation_until_its_completion(task_run: Path):
    times = TaskTimes.of(_synthetic(load_run(task_run)))
    assert times.open_at(0.0).tolist() == [True, True]
    assert times.open_at(20.0).tolist() == [False, True]  # task 0 completed at 20 s
    assert times.served_by.tolist() == [1, -1]  # robot_2 served task 0, no one task 1
    np.testing.assert_array_equal(times.xy, [STATION, (5.0, 5.0)])


def test_holders_follow_the_holdings_none_between_a_release_and_the_next_claim(task_run: Path):
    times = TaskTimes.of(_synthetic(load_run(task_run)))
    assert times.holders_at(5.0).tolist() == [0, 0]  # robot_1 holds both
    assert times.holders_at(11.0).tolist() == [-1, 0]
    assert times.holders_at(13.0).tolist() == [1, 0]
    assert times.holders_at(16.0).tolist() == [1, -1]
    assert times.holders_at(25.0).tolist() == [-1, -1]


def test_a_run_without_tasks_has_no_task_times(waypoint_run: Path):
    times = TaskTimes.of(load_run(waypoint_run))
    assert times.xy.shape == (0, 2) and not times.open_at(1.0).any()
    assert times.holders_at(1.0).shape == (0,)


@pytest.fixture(scope="module")
def waypoints(waypoint_run: Path) -> RunData:
    return load_run(waypoint_run)


def test_each_robot_is_a_disc_at_its_pose_with_a_heading_tick_of_its_radius(waypoints: RunData):
    track = waypoints.track
    layer = FleetLayer(Figure().add_subplot(), waypoints, fleet_colors(list(track.robots)))
    i = len(track.t_s) // 2
    artists = layer.show(i)
    assert artists[:5] == [layer.trails, layer.links, layer.stations, layer.discs, layer.headings]
    np.testing.assert_allclose(
        layer.discs.get_offsets(), np.column_stack([track.x_m[i], track.y_m[i]])
    )
    radius = waypoints.scenario.robots.radius_m
    for r, tick in enumerate(layer.headings.get_segments()):
        yaw = track.yaw_rad[i, r]
        np.testing.assert_allclose(tick[0], [track.x_m[i, r], track.y_m[i, r]])
        np.testing.assert_allclose(tick[1] - tick[0], radius * np.array([np.cos(yaw), np.sin(yaw)]))
    assert len(layer.stations.get_offsets()) == 0  # no task in this run


def test_a_trail_holds_the_poses_of_the_last_trail_seconds_in_the_robot_s_colour(
    waypoints: RunData,
):
    track = waypoints.track
    colors = fleet_colors(list(track.robots))
    last = len(track.t_s) - 1
    layer = FleetLayer(Figure().add_subplot(), waypoints, colors, trail_s=1.0)
    layer.show(last)
    first = int(np.searchsorted(track.t_s, track.t_s[last] - 1.0 - 1e-9))
    for r, trail in enumerate(layer.trails.get_segments()):
        assert len(trail) == last - first + 1
        np.testing.assert_allclose(trail[-1], [track.x_m[last, r], track.y_m[last, r]])
    np.testing.assert_allclose(layer.trails.get_colors()[:, :3], np.array(colors)[:, :3])
    assert TRAIL_S == 10.0


def test_robots_are_numbered_on_the_map_only_when_asked_or_too_many_for_a_legend(
    waypoints: RunData,
):
    colors = fleet_colors(list(waypoints.track.robots))
    assert FleetLayer(Figure().add_subplot(), waypoints, colors).labels == []
    labelled = FleetLayer(Figure().add_subplot(), waypoints, colors, label_robots=True)
    labelled.show(0)
    assert [t.get_text() for t in labelled.labels] == ["1", "2", "3"]
    radius = waypoints.scenario.robots.radius_m
    x, y = waypoints.track.x_m[0, 0], waypoints.track.y_m[0, 0]
    assert labelled.labels[0].get_position() == pytest.approx((x + radius, y + radius))


def test_the_legend_has_a_robot_per_colour_and_the_task_markers_of_a_task_run(task_run: Path):
    run = load_run(task_run)
    physical = cosim.load_scenario("warehouse-random", {**TASKS, "physical.robots": ["robot_1"]})
    run = dataclasses.replace(run, scenario=physical)
    colors = fleet_colors(list(run.track.robots), ["robot_1"])
    labels = [h.get_label() for h in fleet_handles(run, colors)]
    assert labels == [
        "robot_1 (physical)", "robot_2", "robot_3", "task, waiting", "task, held (robot's colour)",
    ]  # fmt: skip
    assert robot_label(run, "robot_2") == "robot_2"


def test_a_fleet_too_large_for_a_legend_entry_per_robot_gets_one_entry(waypoints: RunData):
    robots = tuple(f"robot_{k}" for k in range(1, LEGEND_ROBOTS_MAX + 2))
    run = SimpleNamespace(
        track=SimpleNamespace(robots=robots), scenario=waypoints.scenario, tasks=None
    )
    handles = fleet_handles(run, fleet_colors(list(robots)))  # type: ignore[arg-type]
    assert [h.get_label() for h in handles] == [f"{len(robots)} robots, a colour each"]
