"""Who served which task when: a lane per robot, travel then service bars, a cross per release."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure

from cosim.plotting import timeline
from cosim.plotting.canvas import run_colors
from cosim.plotting.ownership import task_holds
from cosim.plotting.rundata import RunData, load_run
from cosim.plotting.timeline import BAR_HEIGHT, UNHELD, timeline_figure
from tests.conftest import cosim_main
from tests.cosim.plotting.holdings import FLEET, events_table, navigation_table, tasks_table

END_S = 30.0


def _with_tasks(run: RunData, tasks: pd.DataFrame) -> RunData:
    """``run`` over 0-30 s with ``tasks``, held as the synthetic navigation and events say."""
    nav, events = navigation_table(), events_table()
    track = dataclasses.replace(run.track, t_s=np.linspace(0.0, END_S, len(run.track.t_s)))
    holds = task_holds(tasks, nav, events, robots=FLEET)
    return dataclasses.replace(run, track=track, tasks=tasks, holds=holds, navigation=nav)


NEVER_CLAIMED = pd.DataFrame(
    {"task": [2.0], "x_m": [7.0], "y_m": [7.0], "t_created_s": [3.0], "t_assigned_s": [np.nan],
     "robot": [""], "t_started_s": [np.nan], "t_completed_s": [np.nan]}
)  # fmt: skip


@pytest.fixture(scope="module")
def lanes_run(waypoint_run: Path) -> RunData:
    """3 robots; task 0 released by robot_1 then served by robot_2, task 1 released for good,
    task 2 never claimed."""
    return _with_tasks(load_run(waypoint_run), pd.concat([tasks_table(), NEVER_CLAIMED]))


@pytest.fixture
def drawn(monkeypatch: pytest.MonkeyPatch) -> list[Figure]:
    figures: list[Figure] = []
    monkeypatch.setattr(timeline, "save_png", lambda figure, path: figures.append(figure) or path)
    return figures


def _bars(figure: Figure) -> list[tuple[float, float, float, float, str | None]]:
    """(lane, start s, end s, alpha, hatch) of each bar."""
    ax = figure.axes[0]
    return [
        (round(p.get_y() + BAR_HEIGHT / 2, 6), p.get_x(), p.get_x() + p.get_width(),
         p.get_alpha(), p.get_hatch())
        for p in ax.patches
    ]  # fmt: skip


def test_a_lane_per_robot_in_fleet_order_and_one_for_tasks_no_robot_held(
    lanes_run, drawn, tmp_path
):
    timeline_figure(lanes_run, tmp_path / "tasks.png")
    ax = drawn[0].axes[0]
    labels = ax.get_yticklabels()
    assert [t.get_text() for t in labels] == ["robot_1", "robot_2", "robot_3", UNHELD]
    colors = run_colors(lanes_run)
    for label, color in zip(labels[:3], colors, strict=True):
        assert to_rgba(label.get_color()) == pytest.approx(color)
        assert label.get_fontweight() == "bold"
    assert labels[3].get_fontweight() != "bold"
    assert ax.get_ylim()[0] > ax.get_ylim()[1]  # the first robot on top
    assert ax.get_xlabel() == "time (s)"
    assert ax.get_xlim() == pytest.approx((0.0, END_S * 1.01))


def test_each_holding_is_a_pale_travel_bar_then_a_full_service_bar_in_its_robot_s_lane(
    lanes_run, drawn, tmp_path
):
    timeline_figure(lanes_run, tmp_path / "tasks.png")
    assert _bars(drawn[0]) == [
        (0.0, 1.0, 10.0, 0.35, None),  # task 0: robot_1 travels, releases at 10 s
        (1.0, 12.0, 18.0, 0.35, None),  # robot_2 claims at 12 s, travels to 18 s
        (1.0, 18.0, 20.0, 0.95, None),  # and serves it until 20 s
        (0.0, 2.0, 15.0, 0.35, None),  # task 1: robot_1, released at 15 s
    ]


def test_a_release_ends_in_a_cross_and_waits_are_dotted_from_creation_to_first_claim(
    lanes_run, drawn, tmp_path
):
    timeline_figure(lanes_run, tmp_path / "tasks.png")
    lines = drawn[0].axes[0].get_lines()
    crosses = [
        (line.get_xdata()[0], line.get_ydata()[0]) for line in lines if line.get_marker() == "x"
    ]
    assert crosses == [(10.0, 0), (15.0, 0)]
    waits = [line for line in lines if line.get_linestyle() == ":"]
    spans = sorted((line.get_xdata()[0], line.get_xdata()[-1]) for line in waits)
    # task 0 and 1 wait from 0 s to their first claim; task 2 to the end of the run
    assert spans == [(0.0, 1.0), (0.0, 2.0), (3.0, END_S)]


def test_the_title_counts_the_tasks_completed_and_the_claims_given_up(lanes_run, drawn, tmp_path):
    timeline_figure(lanes_run, tmp_path / "tasks.png")
    assert drawn[0].axes[0].get_title().endswith("tasks, 1 of 3 completed, 2 claims given up")
    labels = [t.get_text() for t in drawn[0].legends[0].get_texts()]
    assert labels == [
        "waiting (created to assigned)",
        "travel (assigned to started)",
        "service (started to completed)",
        "not finished at the end",
        "claim given up (released)",
    ]


def test_a_task_unfinished_at_the_end_is_hatched_to_the_last_pose(waypoint_run, drawn, tmp_path):
    serving = tasks_table().iloc[:1].assign(t_completed_s=np.nan)  # robot_2 still at it
    travelling = tasks_table().iloc[:1].assign(t_started_s=np.nan, t_completed_s=np.nan)
    timeline_figure(_with_tasks(load_run(waypoint_run), serving), tmp_path / "a.png")
    timeline_figure(_with_tasks(load_run(waypoint_run), travelling), tmp_path / "b.png")
    assert _bars(drawn[0])[-1] == (1.0, 18.0, END_S, 0.95, "///")  # service to the end
    assert _bars(drawn[1])[-1] == (1.0, 12.0, END_S, 0.35, "///")  # still on its way


def test_a_run_without_tasks_has_no_timeline(waypoint_run: Path, tmp_path: Path):
    with pytest.raises(ValueError, match="needs a run with tasks"):
        timeline_figure(load_run(waypoint_run), tmp_path / "tasks.png")


def test_the_timeline_of_a_task_run_is_written(task_run: Path, tmp_path: Path):
    path = timeline_figure(load_run(task_run), tmp_path / "tasks.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow
def test_a_run_whose_task_source_settled_conflicting_claims_draws_its_figures(tmp_path: Path):
    # the getting-started run (6 robots in the rows hall on a degraded network), shortened:
    # seed 2 gives, within 30 s, claims the task source rejected and one it let replace
    # another; those rows name the task source, which is no robot and holds no task
    out = tmp_path / "rows"
    done = cosim_main(
        "run", "warehouse-rows", "--out", str(out), "--seed", "2", "--duration-s", "30",
        "--set", "robots.count=6", "--set", "network.profile=wifi_degraded", "--figures",
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    events = pd.read_parquet(out / "tables" / "events.parquet")
    settled = events[(events["source"] == "task_source") & (events["kind"] == "conflict")]
    assert {str(d).split()[-1] for d in settled["detail"]} == {"rejected", "replaced"}
    assert (out / "figures" / "tasks.png").is_file()
    run = load_run(out)
    assert run.holds is not None and set(run.holds["robot"]) <= set(run.track.robots)
    redrawn = cosim_main("plot", str(out))
    assert redrawn.returncode == 0, redrawn.stderr
