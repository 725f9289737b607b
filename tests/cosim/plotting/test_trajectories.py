"""Where the robots went: every trajectory over the world, and snapshots at chosen times."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure

from cosim.plotting import trajectories
from cosim.plotting.canvas import fleet_colors
from cosim.plotting.fleet import TaskTimes
from cosim.plotting.rundata import RunData, load_run
from cosim.plotting.trajectories import (
    default_times,
    snapshots_figure,
    station_summary,
    trajectories_figure,
)
from tests.cosim.plotting.conftest import PNG_MAGIC


def _tasks(
    xy: list[tuple[float, float]], completed: list[float], served_by: list[int]
) -> TaskTimes:
    none = np.zeros(0, dtype=np.int64)
    return TaskTimes(
        xy=np.array(xy, dtype=float), created=np.zeros(len(xy)),
        completed=np.array(completed, dtype=float), served_by=np.array(served_by, dtype=np.int64),
        hold_task=none, hold_robot=none, hold_from=np.zeros(0), hold_to=np.zeros(0),
    )  # fmt: skip


def test_a_station_is_coloured_by_the_robot_of_its_last_completed_task_and_lists_its_tasks():
    tasks = _tasks(
        [(1.0, 1.0), (4.0, 2.0), (1.0004, 1.0), (1.0, 1.0), (4.0, 2.0)],
        completed=[5.0, np.nan, 9.0, np.nan, np.nan],
        served_by=[0, -1, 2, 1, -1],
    )
    stations = station_summary(tasks, ["10", "11", "12", "13", "14"])
    assert [(s.xy, s.robot, s.done, s.label) for s in stations] == [
        ((1.0, 1.0), 2, 2, "10,12,(13)"),  # robot 2 completed task 12 there last
        ((4.0, 2.0), -1, 0, "(11),(14)"),  # nothing done there: no robot
    ]


def test_default_snapshot_times_are_evenly_spaced_up_to_the_last_pose(waypoint_run: Path):
    run = load_run(waypoint_run)
    last = float(run.track.t_s[-1])
    assert default_times(run) == pytest.approx([last / 4, last / 2, 3 * last / 4, last])
    assert default_times(run, 1) == pytest.approx([last])


@pytest.fixture(scope="module")
def tasks(task_run: Path) -> RunData:
    return load_run(task_run)


@pytest.fixture
def drawn(monkeypatch: pytest.MonkeyPatch) -> list[Figure]:
    figures: list[Figure] = []
    original = trajectories.save_png
    monkeypatch.setattr(
        trajectories,
        "save_png",
        lambda figure, path: figures.append(figure) or original(figure, path),
    )
    return figures


def test_every_robot_s_whole_trajectory_is_a_line_in_its_colour_from_a_start_square(
    tasks: RunData, drawn, tmp_path
):
    trajectories_figure(tasks, tmp_path / "trajectories.png")
    ax = drawn[0].axes[0]
    track, colors = tasks.track, fleet_colors(list(tasks.track.robots))
    paths = [line for line in ax.get_lines() if line.get_marker() in ("None", None, "")]
    starts = [line for line in ax.get_lines() if line.get_marker() == "s"]
    assert len(paths) == len(starts) == 3
    for r, (line, start) in enumerate(zip(paths, starts, strict=True)):
        np.testing.assert_allclose(line.get_xdata(), track.x_m[:, r])
        np.testing.assert_allclose(line.get_ydata(), track.y_m[:, r])
        assert to_rgba(line.get_color())[:3] == pytest.approx(colors[r][:3])
        assert (start.get_xdata()[0], start.get_ydata()[0]) == (track.x_m[0, r], track.y_m[0, r])
    assert ax.get_title().endswith(f"trajectories, t = 0 to {track.t_s[-1]:g} s")
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x (m, map)", "y (m, map)")


def test_task_stations_are_labelled_with_their_tasks_and_the_legend_explains_them(
    tasks: RunData, drawn, tmp_path
):
    trajectories_figure(tasks, tmp_path / "trajectories.png")
    ax = drawn[0].axes[0]
    assert tasks.tasks is not None
    stations = station_summary(TaskTimes.of(tasks), [f"{k:g}" for k in tasks.tasks["task"]])
    assert [t.get_text() for t in ax.texts] == [s.label for s in stations]
    labels = [t.get_text() for t in drawn[0].legends[0].get_texts()]
    assert labels[:3] == ["robot_1", "robot_2", "robot_3"]
    assert "start" in labels and "end (heading tick)" in labels
    assert "task station: robot that did its last task" in labels
    assert labels[-2:] == ["walls", "shelves"]


def test_a_run_without_tasks_has_no_station_or_station_legend(waypoint_run, drawn, tmp_path):
    trajectories_figure(load_run(waypoint_run), tmp_path / "trajectories.png")
    labels = [t.get_text() for t in drawn[0].legends[0].get_texts()]
    assert not any("task" in label for label in labels)
    assert len(drawn[0].axes[0].texts) == 0


@pytest.mark.parametrize(("count", "grid"), [(4, (2, 2)), (5, (2, 3))])
def test_snapshots_are_a_panel_per_time_wrapping_after_three_two_for_four(
    tasks: RunData, drawn, tmp_path, count, grid
):
    times = default_times(tasks, count)
    snapshots_figure(tasks, times, tmp_path / "snapshots.png")
    axes = drawn[0].axes
    assert len(axes) == count  # unused cells removed
    spec = axes[0].get_subplotspec().get_gridspec()
    assert (spec.nrows, spec.ncols) == grid
    track = tasks.track
    assert [ax.get_title() for ax in axes] == [
        f"t = {track.t_s[track.index_at(t)]:.1f} s" for t in times
    ]
    cols = grid[1]
    assert [ax.get_ylabel() for ax in axes] == [
        "y (m, map)" if k % cols == 0 else "" for k in range(count)
    ]
    assert [ax.get_xlabel() for ax in axes] == [
        "x (m, map)" if k + cols >= count else "" for k in range(count)
    ]
    assert axes[min(cols, count) - 1].get_legend() is not None
    assert drawn[0].get_suptitle().endswith("snapshots, trails of the last 10 s")


def test_a_snapshot_shows_each_robot_at_the_pose_nearest_its_time(tasks: RunData, drawn, tmp_path):
    snapshots_figure(tasks, [7.0], tmp_path / "snapshots.png")
    i = tasks.track.index_at(7.0)
    discs = [c for c in drawn[0].axes[0].collections if c.get_offsets().shape == (3, 2)]
    expected = np.column_stack([tasks.track.x_m[i], tasks.track.y_m[i]])
    assert any(np.allclose(d.get_offsets(), expected) for d in discs)


def test_both_figures_are_written_as_pngs(tasks: RunData, tmp_path: Path):
    for path in (
        trajectories_figure(tasks, tmp_path / "trajectories.png"),
        snapshots_figure(tasks, [5.0, 10.0], tmp_path / "snapshots.png"),
    ):
        assert path.read_bytes().startswith(PNG_MAGIC)
