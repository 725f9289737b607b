"""How the fleet converged on each assignment epoch: time to decide, rounds, messages."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure

from adapters.tasks.topics import TASKS
from cosim.plotting import assignment
from cosim.plotting.assignment import DECIDED, SUPERSEDED, assignment_figure, epoch_stats
from cosim.plotting.rundata import RunData, load_run


def test_decided_epochs_take_as_long_as_the_run_summary_says(task_run):
    stats = epoch_stats(load_run(task_run))
    summary = json.loads((task_run / "summary.json").read_text())
    assert stats.announced
    assert stats.decided.any()
    mean = stats.decision_s[stats.decided].mean()
    assert mean == pytest.approx(summary["mean_convergence_time_s"], abs=1e-6)
    assert (stats.rounds >= 1).all() and (stats.messages >= 1).all()


def _rounds(*rows: tuple[int, float, str, int, bool, int]) -> pd.DataFrame:
    """Rounds: (epoch, t_s, robot, round, converged, messages sent so far) each."""
    return pd.DataFrame(rows, columns=["epoch", "t_s", "robot", "round", "converged", "messages"])


# epoch 1: robot_1 converges at 1.1 s (round 2), robot_2 at 1.3 s (round 3): decided;
# epoch 2: robot_2 converges, robot_1 never does before the next task set: superseded
ROUNDS = _rounds(
    (1, 1.0, "robot_1", 1, False, 2),
    (1, 1.05, "robot_2", 1, False, 2),
    (1, 1.1, "robot_1", 2, True, 4),
    (1, 1.2, "robot_2", 2, False, 4),
    (1, 1.3, "robot_2", 3, True, 6),
    (2, 5.0, "robot_1", 1, False, 1),
    (2, 5.05, "robot_2", 1, True, 1),
    (2, 5.1, "robot_1", 2, False, 3),
)


def _copies(*rows: tuple[float, float, str]) -> pd.DataFrame:
    """Task sets from the base: (t_sent_s, t_recv_s, dst_host) each, delivered."""
    frame = pd.DataFrame(rows, columns=["t_sent_s", "t_recv_s", "dst_host"])
    return frame.assign(src_host="base", topic=TASKS, status="delivered")


@pytest.fixture(scope="module")
def rounds_run(waypoint_run: Path) -> RunData:
    """The waypoint run with the rounds of :data:`ROUNDS` and no message table."""
    return dataclasses.replace(load_run(waypoint_run), assignments=ROUNDS, messages=None)


def test_without_messages_an_epoch_starts_at_its_first_round(rounds_run: RunData):
    stats = epoch_stats(rounds_run)
    assert not stats.announced
    assert stats.epoch.tolist() == [1.0, 2.0]
    assert stats.start_s.tolist() == [1.0, 5.0]
    assert stats.decided.tolist() == [True, False]
    # decided when the last robot converged; superseded: to its last round
    assert stats.decision_s == pytest.approx([0.3, 0.1])
    assert stats.rounds.tolist() == [3.0, 2.0]  # the slowest robot's rounds
    assert stats.messages.tolist() == [10.0, 4.0]  # each robot's count, summed


def test_with_messages_an_epoch_starts_when_the_task_set_a_robot_acted_on_was_sent(
    rounds_run: RunData,
):
    copies = _copies(
        (0.8, 0.9, "robot_1"),
        (0.85, 0.95, "robot_2"),
        (0.95, 1.5, "robot_1"),  # arrived after robot_1's first round: not what it acted on
        (4.0, 4.9, "robot_2"),  # the next task set
        (4.1, 4.8, "robot_1"),
    )
    lost = copies.iloc[:1].assign(t_sent_s=0.1, status="lost")
    other = copies.iloc[:1].assign(t_sent_s=0.2, topic="/fleet/other")
    run = dataclasses.replace(rounds_run, messages=pd.concat([copies, lost, other]))
    stats = epoch_stats(run)
    assert stats.announced
    assert stats.start_s.tolist() == [0.8, 4.0]
    assert stats.decision_s == pytest.approx([0.5, 1.1])


def test_a_run_without_assignment_rounds_has_no_epochs(waypoint_run: Path):
    with pytest.raises(ValueError, match="needs a run with assignment rounds"):
        epoch_stats(load_run(waypoint_run))


@pytest.fixture
def drawn(monkeypatch: pytest.MonkeyPatch) -> list[Figure]:
    figures: list[Figure] = []
    monkeypatch.setattr(assignment, "save_png", lambda figure, path: figures.append(figure) or path)
    return figures


def test_three_panels_of_a_bar_per_epoch_decided_blue_superseded_grey(
    rounds_run: RunData, drawn, tmp_path
):
    assignment_figure(rounds_run, tmp_path / "a.png")
    axes = drawn[0].axes
    assert [ax.get_ylabel() for ax in axes] == [
        "time to decide (s)\nfrom first round",
        "rounds to decide\n(slowest robot)",
        "protocol messages\nsent (all robots)",
    ]
    assert axes[-1].get_xlabel() == "epoch"
    heights = [[bar.get_height() for bar in ax.patches] for ax in axes]
    assert heights[0] == pytest.approx([0.3, 0.1])
    assert heights[1:] == [[3.0, 2.0], [10.0, 4.0]]
    faces = [bar.get_facecolor() for bar in axes[0].patches]
    assert faces == [to_rgba(DECIDED), to_rgba(SUPERSEDED)]
    legend = axes[0].get_legend()
    assert legend is not None
    assert [t.get_text() for t in legend.get_texts()] == [
        "decided", "superseded before a decision",
    ]  # fmt: skip
    assert (
        drawn[0]
        .get_suptitle()
        .endswith(f"assignment ({rounds_run.scenario.assignment.protocol}), 2 epochs")
    )


def test_the_mean_time_to_decide_of_the_decided_epochs_is_a_dashed_line(
    rounds_run: RunData, drawn, tmp_path
):
    assignment_figure(rounds_run, tmp_path / "a.png")
    (mean,) = drawn[0].axes[0].get_lines()
    assert np.allclose(mean.get_ydata(), 0.3) and mean.get_linestyle() == "--"
    assert [t.get_text() for t in drawn[0].axes[0].texts] == ["mean 0.3 s"]
    superseded = dataclasses.replace(rounds_run, assignments=ROUNDS[ROUNDS["epoch"] == 2])
    assignment_figure(superseded, tmp_path / "b.png")
    assert len(drawn[1].axes[0].get_lines()) == 0 and len(drawn[1].axes[0].texts) == 0


def test_the_assignment_figure_of_a_task_run_is_written(task_run: Path, tmp_path: Path):
    path = assignment_figure(load_run(task_run), tmp_path / "assignment.png")
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
