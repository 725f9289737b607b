"""How the fleet converged on each assignment epoch: time to decide, rounds, messages.

From ``tables/assignments`` (a row per protocol round of a robot) and, when the run has
it, the message table: an epoch starts when the task source announces it (the send time
of the earliest announcement copy that a robot acted on), so network latency counts, as
in the run's ``mean_convergence_time_s``; without messages it starts at its first round.
The fleet decided when every robot that ran rounds in the epoch had converged; an epoch
superseded before that (a newer task set arrived) has no decision.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from adapters.tasks.topics import TASKS
from cosim.plotting.canvas import save_png
from cosim.plotting.rundata import RunData

"""Topic of the task source's task sets (adapters.assignment.topics.TASKS)."""
DECIDED = "#1f77b4"
SUPERSEDED = "0.75"


@dataclass(frozen=True)
class EpochStats:
    """Per epoch, in epoch order (arrays of equal length).

    Attributes:
        epoch: epoch numbers.
        start_s: announcement (or first round) time (s).
        decision_s: time from start to the fleet's decision (s); for epochs without a
            decision, to their last round.
        decided: whether every robot of the epoch converged.
        rounds: most rounds a robot ran before it converged (or in all, if it did not).
        messages: protocol messages the robots sent in the epoch.
        announced: whether ``start_s`` is the announcement (False: the first round).
    """

    epoch: np.ndarray
    start_s: np.ndarray
    decision_s: np.ndarray
    decided: np.ndarray
    rounds: np.ndarray
    messages: np.ndarray
    announced: bool


def epoch_stats(run: RunData) -> EpochStats:
    """The convergence of every epoch of a run that has an assignments table."""
    rounds = run.assignments
    if rounds is None:
        raise ValueError("epoch_stats needs a run with assignment rounds")  # callers check
    rows = []
    announced = _announcements(run)
    for epoch, group in rounds.groupby("epoch", sort=True):
        first = group.groupby("robot")["t_s"].min()
        converged = group[group["converged"]].groupby("robot")
        decided = converged.ngroups == group["robot"].nunique()
        end = float(converged["t_s"].min().max()) if decided else float(group["t_s"].max())
        at_decision = converged["round"].min() if decided else group.groupby("robot")["round"].max()
        start = _start(announced, first) if announced is not None else float(first.min())
        rows.append(
            (
                epoch,
                start,
                end - start,
                decided,
                float(at_decision.max()),
                float(group.groupby("robot")["messages"].max().sum()),
            )
        )
    table = np.array(rows, dtype=np.float64).reshape(-1, 6)
    return EpochStats(
        epoch=table[:, 0],
        start_s=table[:, 1],
        decision_s=table[:, 2],
        decided=table[:, 3].astype(bool),
        rounds=table[:, 4],
        messages=table[:, 5],
        announced=announced is not None,
    )


def assignment_figure(run: RunData, png_path: Path) -> Path:
    """Draw the convergence of every epoch (run with an assignments table) to ``png_path``.

    Three panels over the epochs: time from the epoch's start to the fleet's decision (s),
    rounds, and protocol messages sent; epochs superseded before a decision in grey.

    Raises:
        ExportError: naming the path if the file cannot be written.
    """
    stats = epoch_stats(run)
    colors = np.where(stats.decided, DECIDED, SUPERSEDED)
    figure = Figure(
        figsize=(max(7.0, min(14.0, 4.0 + 0.12 * len(stats.epoch))), 6.5), layout="constrained"
    )
    axes = figure.subplots(3, 1, sharex=True)
    since = "announcement" if stats.announced else "first round"
    panels = (
        (stats.decision_s, f"time to decide (s)\nfrom {since}"),
        (stats.rounds, "rounds to decide\n(slowest robot)"),
        (stats.messages, "protocol messages\nsent (all robots)"),
    )
    for ax, (values, label) in zip(axes, panels, strict=True):
        ax.bar(stats.epoch, values, color=colors, width=0.8)
        ax.set_ylabel(label)
        ax.grid(True, axis="y", alpha=0.3)
    decided = stats.decision_s[stats.decided]
    if len(decided):
        mean = float(decided.mean())
        axes[0].axhline(mean, color="0.2", lw=0.8, ls="--")
        axes[0].annotate(
            f"mean {mean:.3g} s",
            (1.0, mean),
            xycoords=("axes fraction", "data"),
            xytext=(-2, 2),
            textcoords="offset points",
            ha="right",
            va="bottom",
            fontsize=8,
        )
    axes[-1].set_xlabel("epoch")
    if len(stats.epoch) <= 30:
        axes[-1].set_xticks(stats.epoch)
    protocol = run.scenario.assignment.protocol
    figure.suptitle(f"{run.title}: assignment ({protocol}), {len(stats.epoch)} epochs", fontsize=11)
    axes[0].legend(
        handles=[
            Patch(color=DECIDED, label="decided"),
            Patch(color=SUPERSEDED, label="superseded before a decision"),
        ],
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
        fontsize=8,
    )
    return save_png(figure, png_path)


def _announcements(run: RunData) -> pd.DataFrame | None:
    """Copies of the task sets delivered to robots: (robot, t_recv_s, t_sent_s), or None."""
    messages = run.messages
    if messages is None:
        return None
    copies = messages[(messages["topic"] == TASKS) & (messages["status"] == "delivered")]
    if copies.empty:
        return None
    return copies[["dst_host", "t_recv_s", "t_sent_s"]].sort_values("t_recv_s")


def _start(copies: pd.DataFrame, first_round: pd.Series) -> float:
    """Earliest send time of the copies each robot acted on: its last before its first round."""
    starts = []
    for robot, t_round in first_round.items():
        mine = copies[(copies["dst_host"] == robot) & (copies["t_recv_s"] <= t_round)]
        if len(mine):
            starts.append(float(mine["t_sent_s"].iloc[-1]))
    return min(starts) if starts else float(first_round.min())
