"""The kit's timing assertions: latency percentiles, the order of events, deadlines."""

from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.testing.timing import (
    assert_epochs_decided_within,
    assert_latency,
    assert_order,
    assert_tasks_assigned_within,
)
from tests.cosim.testing.conftest import made_run


def messages(latencies_ns: list[int], *, topic: str = "/fleet/claims") -> pd.DataFrame:
    """Messages robot_1 -> base sent 1 s apart, each taking its latency (-1: lost)."""
    sent = np.arange(len(latencies_ns), dtype=np.int64) * 1_000_000_000
    lost = np.array([lat < 0 for lat in latencies_ns], dtype=bool)
    received = sent + np.maximum(np.array(latencies_ns, dtype=np.int64), 0)
    return pd.DataFrame(
        {
            "t_sent_s": sent / 1e9,
            "t_recv_s": np.where(lost, np.nan, received / 1e9),
            "src_host": pd.Categorical(["robot_1"] * len(sent)),
            "dst_host": pd.Categorical(["base"] * len(sent)),
            "topic": pd.Categorical([topic] * len(sent)),
            "bytes": np.full(len(sent), 40),
            "status": pd.Categorical(["lost" if x else "delivered" for x in lost]),
            "t_sent_ns": sent,
            "t_recv_ns": pd.arrays.IntegerArray(np.where(lost, 0, received), lost),
        }
    )


def test_the_latency_of_a_topic_in_a_run_is_its_networks_exact_5_ms(simplex_run):
    found = assert_latency(simplex_run, topic="/fleet/claims", p95_ms=5.0, max_ms=5.0)
    assert (found.p50_ms, found.p95_ms, found.max_ms) == (5.0, 5.0, 5.0)
    assert found.delivered > 0 and found.dropped == 0


def test_a_latency_bound_below_the_networks_fails_naming_the_percentile_and_the_figures(
    simplex_run,
):
    with pytest.raises(AssertionError) as failed:
        assert_latency(simplex_run, topic="/fleet/*", p95_ms=4.5)
    said = str(failed.value)
    assert said.startswith("latency on /fleet/* between hosts: p95 = 5 ms > 4.5 ms (over ")
    assert "p50 = 5 ms" in said and "0 not delivered" in said


def test_latency_percentiles_are_numpys_over_delivered_copies_and_lost_ones_are_counted():
    run = made_run({"messages": messages([1_000_000, 2_000_000, 3_000_000, -1, 10_000_000])})
    found = assert_latency(run, topic="/fleet/claims", max_ms=10.0)
    assert found.delivered == 4 and found.dropped == 1
    assert found.p50_ms == pytest.approx(2.5) and found.max_ms == 10.0
    with pytest.raises(AssertionError, match=r"max = 10 ms > 9\.5 ms .* 1 not delivered"):
        assert_latency(run, topic="/fleet/claims", max_ms=9.5)


@settings(max_examples=60, deadline=None)
@given(
    latencies=st.lists(st.integers(0, 50_000_000), min_size=1, max_size=40),
    bound_ms=st.floats(0.0, 60.0, allow_nan=False),
)
def test_a_p95_bound_fails_exactly_when_numpys_95th_percentile_exceeds_it(latencies, bound_ms):
    run = made_run({"messages": messages(latencies)})
    p95 = float(np.percentile(np.array(latencies) / 1e6, 95))
    if p95 > bound_ms:
        with pytest.raises(AssertionError, match="p95 = "):
            assert_latency(run, topic="/fleet/claims", p95_ms=bound_ms)
    else:
        assert assert_latency(run, topic="/fleet/claims", p95_ms=bound_ms).p95_ms == p95


def test_latency_on_a_topic_the_run_never_sent_fails_listing_its_topics():
    run = made_run({"messages": messages([1_000_000])})
    with pytest.raises(AssertionError, match=r"no message on /fleet/bids between hosts .*"
                       r"\(its topics: /fleet/claims\)"):  # fmt: skip
        assert_latency(run, topic="/fleet/bids", p95_ms=20)
    with pytest.raises(AssertionError, match=r"none of the 2 messages .* \(lost: 2\)"):
        assert_latency(made_run({"messages": messages([-1, -1])}), topic="/fleet/*", max_ms=1)


def test_latency_needs_a_bound_and_a_messages_table():
    with pytest.raises(ValueError, match="needs a bound"):
        assert_latency(made_run({"messages": messages([1])}), topic="/fleet/claims")
    with pytest.raises(AssertionError, match=r"no tables/messages \(written by the recorder, "
                       r"unless record.messages = false\)"):  # fmt: skip
        assert_latency(made_run({}), topic="/fleet/claims", p95_ms=1)


def events(*rows: tuple[int, str, str, str]) -> pd.DataFrame:
    """An events table of (t_ns, source, kind, detail) rows."""
    t_ns = np.array([r[0] for r in rows], dtype=np.int64)
    return pd.DataFrame(
        {
            "t_s": t_ns / 1e9,
            "source": pd.Categorical([r[1] for r in rows]),
            "kind": pd.Categorical([r[2] for r in rows]),
            "detail": [r[3] for r in rows],
            "t_ns": t_ns,
        }
    )


TIMELINE = events(
    (0, "task_source", "task", "task 0"),
    (52_666_367, "task_source", "conflict", "task 0: robot_1 rejected"),
    (8_806_359_972, "task_source", "done", "task 0 by robot_3"),
    (8_806_359_972, "task_source", "task", "task 3"),  # the same instant, recorded after
)


def test_events_in_order_pass_and_give_their_exact_times():
    run = made_run({"events": TIMELINE})
    times = assert_order(run, ["task", ("done", {"detail": "task 0 by robot_3"}), "task"])
    assert times == [0.0, 8.806359972, 8.806359972]
    assert assert_order(run, [("conflict", {"detail": re.compile(r"robot_\d rejected")})]) == [
        0.052666367
    ]


def test_an_event_that_comes_only_earlier_fails_naming_the_step_and_the_times():
    run = made_run({"events": TIMELINE})
    with pytest.raises(AssertionError) as failed:
        assert_order(run, ["done", "conflict"])
    assert str(failed.value) == (
        "step 2 'conflict' does not come after step 1 (step 1 matched at t = 8.806359972 s): "
        "it matches only earlier, at t = 0.052666367 s"
    )
    with pytest.raises(AssertionError, match=r"step 1 \('done', \{'source': 'robot_1'\}\): "
                       r"no row of tables/events matches it"):  # fmt: skip
        assert_order(run, [("done", {"source": "robot_1"})])


@settings(max_examples=50, deadline=None)
@given(st.lists(st.sampled_from(["task", "claim", "done", "release"]), min_size=2, max_size=12))
def test_any_events_pass_in_their_own_order_and_two_distinct_ones_fail_reversed(kinds):
    run = made_run({"events": events(*[(k * 1000, "x", kind, "") for k, kind in enumerate(kinds)])})
    assert len(assert_order(run, kinds)) == len(kinds)
    first, last = kinds[0], kinds[-1]
    if first != last and last not in kinds[:-1] and first not in kinds[1:]:
        with pytest.raises(AssertionError, match="does not come after step 1"):
            assert_order(run, [last, first])


def test_the_order_of_messages_is_by_send_time_and_topic(simplex_run):
    tasks_first, claims_then = assert_order(simplex_run, ["/fleet/tasks", "/fleet/claims"],
                                            table="messages")  # fmt: skip
    assert tasks_first < claims_then
    with pytest.raises(ValueError, match="has no column 'robot'"):
        assert_order(simplex_run, [("task", {"robot": "robot_1"})])
    with pytest.raises(ValueError, match="give key= and time="):
        assert_order(simplex_run, ["x"], table="tasks")


def tasks(*rows: tuple[int, float, float]) -> pd.DataFrame:
    """A tasks table of (task, t_created_s, t_assigned_s) rows (nan: never claimed)."""
    return pd.DataFrame(
        {
            "task": [r[0] for r in rows],
            "t_created_s": [r[1] for r in rows],
            "t_assigned_s": [r[2] for r in rows],
        }
    )


def test_every_task_of_a_simplex_run_is_claimed_within_a_second(simplex_run):
    assert 0.0 < assert_tasks_assigned_within(simplex_run, 1.0) < 1.0


def test_a_late_or_never_claimed_task_fails_naming_it_and_its_times():
    run = made_run({"tasks": tasks((0, 0.0, 0.4), (1, 0.0, 9.006), (2, 8.8, np.nan))})
    with pytest.raises(AssertionError) as failed:
        assert_tasks_assigned_within(run, 5.0)
    assert str(failed.value) == (
        "2 of 3 tasks not claimed within 5 s of appearing: task 1 (appeared at 0 s, claimed at "
        "9.006 s, after 9.006 s); task 2 (appeared at 8.8 s, never claimed by the end at 20 s)"
    )


def test_a_task_that_appeared_too_late_to_tell_is_not_judged_and_nothing_to_judge_fails():
    early_and_late = made_run({"tasks": tasks((0, 0.0, 0.5), (1, 18.0, np.nan))})
    assert assert_tasks_assigned_within(early_and_late, 5.0) == 0.5
    with pytest.raises(AssertionError, match=r"no task to judge: .* run longer"):
        assert_tasks_assigned_within(made_run({"tasks": tasks((0, 18.0, np.nan))}), 5.0)
    with pytest.raises(AssertionError, match=r"no tables/tasks \(written by the task source"):
        assert_tasks_assigned_within(made_run({}), 5.0)


def rounds(*rows: tuple[int, float, str, bool]) -> pd.DataFrame:
    """An assignments table of (epoch, t_s, robot, converged) rows."""
    return pd.DataFrame(
        {
            "epoch": [r[0] for r in rows],
            "t_s": [r[1] for r in rows],
            "robot": pd.Categorical([r[2] for r in rows]),
            "converged": [r[3] for r in rows],
        }
    )


def test_every_robot_of_a_simplex_run_decides_each_epoch_within_a_second(simplex_run):
    assert 0.0 < assert_epochs_decided_within(simplex_run, 1.0) < 1.0


def test_a_robot_deciding_late_or_never_fails_unless_its_epoch_was_over_before_the_deadline():
    run = made_run({"assignments": rounds(
        (1, 0.0, "robot_1", False), (1, 0.1, "robot_1", True),
        (1, 0.0, "robot_2", False), (1, 2.5, "robot_2", True),
        (2, 3.0, "robot_1", False),  # superseded by epoch 3 within the deadline
        (3, 3.5, "robot_1", False),  # never decides: the run goes on to 20 s
    )})  # fmt: skip
    with pytest.raises(AssertionError) as failed:
        assert_epochs_decided_within(run, 2.0)
    assert str(failed.value) == (
        "2 robots' protocols did not decide within 2 s of their epoch's first round: "
        "epoch 1: robot_2 decided after 2.5 s; epoch 3: robot_1 never decided (epoch started "
        "at 3.5 s, lasted 16.5 s)"
    )


def test_a_protocol_without_rounds_is_sent_to_the_tasks():
    empty = made_run({"assignments": rounds()})
    with pytest.raises(AssertionError, match="assert_tasks_assigned_within"):
        assert_epochs_decided_within(empty, 1.0)
