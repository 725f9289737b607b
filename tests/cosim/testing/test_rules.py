"""The behaviour rules of ``cosim check-plugin``, on runs made by hand to break each one."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from adapters.assignment.protocols import Cbba, Greedy, Hungarian
from cosim.testing.rules import (
    assigns,
    conflicts,
    coordinated,
    delivers,
    finite,
    moves,
    tracks,
)
from tests.cosim.testing.conftest import made_run


def test_protocols_that_exchange_messages_or_decide_centrally_coordinate_and_greedy_does_not():
    assert coordinated(Cbba) and coordinated(Hungarian) and not coordinated(Greedy)


def tasks(*assigned: float) -> pd.DataFrame:
    """Tasks appearing at 0 s, claimed at these times (nan: never)."""
    return pd.DataFrame(
        {"task": range(len(assigned)), "t_created_s": 0.0, "t_assigned_s": list(assigned)}
    )


def test_a_coordinating_protocol_must_have_every_task_claimed_within_5_s():
    assert assigns(made_run({"tasks": tasks(0.4, 1.0)}), Cbba).line() == (
        "ok   assigns: every task claimed within 5 s of appearing on a network that loses "
        "nothing (the longest wait 1 s)"
    )
    late = assigns(made_run({"tasks": tasks(0.4, 6.0)}), Cbba)
    assert late.failed and late.detail.startswith("1 of 2 tasks not claimed within 5 s")


def test_a_protocol_deciding_alone_must_only_have_some_task_claimed():
    assert not assigns(made_run({"tasks": tasks(0.2, math.nan)}), Greedy).failed
    none = assigns(made_run({"tasks": tasks(math.nan, 7.0)}), Greedy)
    assert none.line() == (
        "FAIL assigns: no task of 2 claimed within 5 s of appearing (robots deciding alone must "
        "at least claim tasks)"
    )


def test_conflicts_fail_a_coordinating_protocol_and_are_allowed_to_one_deciding_alone():
    events = pd.DataFrame(
        {"t_s": [0.05], "source": ["task_source"], "kind": ["conflict"],
         "detail": ["task 0: robot_2 rejected"], "t_ns": [50_000_000]}
    )  # fmt: skip
    run = made_run({"events": events}, conflicts=1)
    assert conflicts(run, Cbba).line() == (
        "FAIL conflicts: 1 conflicts (a task claimed by two robots): task 0: robot_2 rejected "
        "at t = 0.05 s on a network that loses nothing"
    )
    assert conflicts(run, Greedy).line().startswith("skip conflicts: 1 allowed")


def poses(rows: list[tuple[float, str, float, float, float]]) -> pd.DataFrame:
    """A poses table of (t_s, robot, x_m, y_m, v_mps) rows."""
    return pd.DataFrame(
        {
            "t_s": [r[0] for r in rows],
            "robot": pd.Categorical([r[1] for r in rows]),
            "x_m": [r[2] for r in rows],
            "y_m": [r[3] for r in rows],
            "yaw_rad": 0.0,
            "v_mps": [r[4] for r in rows],
            "w_radps": 0.0,
        }
    )


def test_a_pose_that_is_not_finite_fails_naming_the_robot_the_column_and_when():
    run = made_run({"poses": poses([(0.0, "robot_1", 1.0, 1.0, 0.0), (0.1, "robot_1", 1.0, 1.0,
                                                                      math.nan)])})  # fmt: skip
    assert finite(run, None).line() == (
        "FAIL finite: robot_1's v_mps = nan at t = 0.1 s (1 of 2 pose samples not finite)"
    )


def test_robots_that_reach_no_goal_must_each_drive_half_a_metre():
    rows = [(0.0, "robot_1", 1.0, 1.0, 0.0), (1.0, "robot_1", 1.0, 2.0, 1.0),
            (0.0, "robot_2", 5.0, 1.0, 0.0), (1.0, "robot_2", 5.1, 1.0, 0.1)]  # fmt: skip
    still = moves(made_run({"poses": poses(rows)}, arrivals=0), None)
    assert still.line() == (
        "FAIL moves: no goal reached in 20 s, and 1 of 2 robots drove less than 0.5 m "
        "(robot_1 1 m, robot_2 0.1 m)"
    )
    assert not moves(made_run({"poses": poses(rows)}, arrivals=2), None).failed


def messages(statuses: list[str], delays_ns: list[int]) -> pd.DataFrame:
    """Messages robot_1 -> base sent at 1 s, each with its fate and delay."""
    received = [1_000_000_000 + d for d in delays_ns]
    return pd.DataFrame(
        {
            "src_host": ["robot_1"] * len(statuses),
            "dst_host": ["base"] * len(statuses),
            "topic": ["/fleet/claims"] * len(statuses),
            "status": statuses,
            "t_sent_s": 1.0,
            "t_sent_ns": np.full(len(statuses), 1_000_000_000),
            "t_recv_ns": received,
        }
    )


def test_a_network_that_loses_nothing_must_deliver_every_message_never_before_it_was_sent():
    delivered = made_run({"messages": messages(["delivered"] * 2, [0, 2_500_000])})
    assert delivers(delivered, None).line() == (
        "ok   delivers: all 2 messages between hosts delivered, none before it was sent "
        "(latency up to 2.5 ms)"
    )
    lost = delivers(made_run({"messages": messages(["delivered", "lost"], [0, 0])}), None)
    assert lost.line() == (
        "FAIL delivers: 1 of 2 messages between hosts not delivered on a network that loses "
        "nothing (lost 1): /fleet/claims robot_1 -> base sent at t = 1 s"
    )
    early = delivers(made_run({"messages": messages(["delivered"], [-1])}), None)
    assert early.detail == (
        "1 messages delivered before they were sent: the first /fleet/claims robot_1 -> base "
        "sent at 1000000000 ns, delivered at 999999999 ns"
    )
    assert delivers(made_run({"messages": messages([], [])}), None).detail == (
        "no message went from one host to another"
    )


def test_a_pose_source_must_hand_poses_to_the_robots():
    assert tracks(made_run({}, mocap_poses=0), None).failed
    assert tracks(made_run({}, mocap_poses=300, mocap_rejected_jumps=2), None).line() == (
        "ok   tracks: 300 poses taken in (2 refused as jumps)"
    )
