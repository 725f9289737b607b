"""The recorder's NumPy columns as pandas DataFrames: categories, exact and nullable times."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.core.hosts import HostId
from cosim.core.recorder import EVENTS, MESSAGES, Recorder
from cosim.core.table import Table, TableSpec
from cosim.recording.dataframes import events_frame, messages_frame, run_frames, table_frame

A, B, C = HostId("robot_1"), HostId("robot_2"), HostId("base")


def _recorder() -> Recorder:
    """A delivered copy, a dropped one and a copy to the sender's own host."""
    recorder = Recorder()
    recorder.on_transfer(1_000_000_001, 1_250_000_001, A, B, "/tasks", 120, "delivered")
    recorder.on_transfer(1_000_000_001, None, A, C, "/tasks", 120, "lost")
    recorder.on_transfer(2_000_000_000, 2_000_000_000, B, B, "/robot_2/odom", 60, "delivered")
    return recorder


def test_the_messages_table_has_the_declared_columns_in_order():
    assert list(messages_frame(_recorder()).columns) == list(MESSAGES.columns)
    assert list(messages_frame(Recorder()).columns) == list(MESSAGES.columns)


def test_a_dropped_copy_has_no_receive_time_in_seconds_or_nanoseconds():
    frame = messages_frame(_recorder())
    assert list(frame["status"]) == ["delivered", "lost", "delivered"]
    assert frame["t_recv_ns"].dtype == pd.Int64Dtype()
    assert frame["t_recv_ns"].isna().tolist() == [False, True, False]
    assert frame["t_recv_ns"][0] == 1_250_000_001
    assert np.isnan(frame["t_recv_s"][1])
    assert frame["t_recv_s"][0] == pytest.approx(1.250000001, abs=1e-12)


def test_the_seconds_come_from_the_exact_nanoseconds():
    frame = messages_frame(_recorder())
    assert frame["t_sent_ns"].dtype == np.int64
    assert frame["t_sent_ns"].tolist() == [1_000_000_001, 1_000_000_001, 2_000_000_000]
    assert frame["t_sent_s"].tolist() == pytest.approx([1.000000001, 1.000000001, 2.0], abs=1e-12)
    assert frame["bytes"].tolist() == [120, 120, 60]


def test_hosts_topics_and_statuses_are_categories_of_the_names_recorded():
    frame = messages_frame(_recorder())
    for column in MESSAGES.categorical:
        assert isinstance(frame[column].dtype, pd.CategoricalDtype), column
    assert frame["src_host"].tolist() == ["robot_1", "robot_1", "robot_2"]
    assert frame["dst_host"].tolist() == ["robot_2", "base", "robot_2"]
    assert set(frame["dst_host"].cat.categories) == {"robot_1", "robot_2", "base"}
    assert frame["topic"].tolist() == ["/tasks", "/tasks", "/robot_2/odom"]


def test_a_run_without_messages_recorded_has_an_empty_messages_table():
    recorder = Recorder(record_messages=False)
    recorder.on_transfer(0, 5, A, B, "/tasks", 10, "delivered")
    frame = messages_frame(recorder)
    assert frame.empty and list(frame.columns) == list(MESSAGES.columns)
    assert recorder.counts["delivered"] == 1  # counted, not tabulated


@settings(max_examples=40, deadline=None)
@given(
    copies=st.lists(
        st.tuples(
            st.integers(0, 10**15),
            st.one_of(st.none(), st.integers(0, 10**9)),
            st.sampled_from(["delivered", "lost", "queue_full"]),
        ),
        max_size=20,
    )
)
def test_every_copy_is_a_row_whose_times_match_what_was_recorded(copies):
    recorder = Recorder()
    for t_sent, delay, status in copies:
        t_recv = None if delay is None else t_sent + delay
        recorder.on_transfer(t_sent, t_recv, A, B, "/t", 8, status)
    frame = messages_frame(recorder)
    assert len(frame) == len(copies)
    for row, (t_sent, delay, _) in zip(frame.itertuples(), copies, strict=True):
        assert row.t_sent_ns == t_sent
        assert row.t_sent_s == pytest.approx(t_sent / 1e9, rel=1e-15, abs=1e-15)
        if delay is None:
            assert pd.isna(row.t_recv_ns) and np.isnan(row.t_recv_s)
        else:
            assert row.t_recv_ns == t_sent + delay
            assert row.t_recv_s == pytest.approx((t_sent + delay) / 1e9, rel=1e-15)


def test_events_have_seconds_from_their_nanoseconds_and_categorical_sources_and_kinds():
    recorder = Recorder()
    recorder.event(1_500_000_000, "tasks", "created", "task 1 at (2, 3)")
    recorder.event(2_000_000_001, "robot_1", "release", "task 1: stuck")
    frame = events_frame(recorder)
    assert list(frame.columns) == list(EVENTS.columns)
    assert frame["t_s"].tolist() == pytest.approx([1.5, 2.000000001], abs=1e-12)
    assert frame["t_ns"].tolist() == [1_500_000_000, 2_000_000_001]
    assert frame["t_ns"].dtype == np.int64
    assert isinstance(frame["source"].dtype, pd.CategoricalDtype)
    assert isinstance(frame["kind"].dtype, pd.CategoricalDtype)
    assert frame["detail"].tolist() == ["task 1 at (2, 3)", "task 1: stuck"]


def test_a_run_without_events_has_an_empty_events_table_with_its_columns():
    frame = events_frame(Recorder())
    assert frame.empty and list(frame.columns) == list(EVENTS.columns)


def test_a_table_s_categorical_columns_become_categories_and_the_rest_keep_their_type():
    table = Table(("t_s", "robot", "x_m"), categorical=("robot",))
    table.append(t_s=0.0, robot="robot_1", x_m=1.5)
    table.extend(t_s=np.array([0.1, 0.1]), robot=np.array(["robot_1", "robot_2"]), x_m=2.0)
    frame = table_frame(table)
    assert list(frame.columns) == ["t_s", "robot", "x_m"]
    assert isinstance(frame["robot"].dtype, pd.CategoricalDtype)
    assert frame["robot"].tolist() == ["robot_1", "robot_1", "robot_2"]
    assert frame["x_m"].dtype == np.float64 and frame["x_m"].tolist() == [1.5, 2.0, 2.0]


def test_an_empty_table_is_an_empty_frame_with_its_columns():
    frame = table_frame(Table(("t_s", "robot"), categorical=("robot",)))
    assert frame.empty and list(frame.columns) == ["t_s", "robot"]


def test_a_run_s_frames_are_its_messages_events_and_every_table_by_name():
    recorder = _recorder()
    spec = TableSpec("poses", "a pose per robot and sample", {"t_s": "time", "robot": "who"},
                     categorical=("robot",))  # fmt: skip
    recorder.table(spec).append(t_s=0.0, robot="robot_1")
    recorder.table("arrivals", ("t_s",)).append(t_s=3.0)
    frames = run_frames(recorder)
    assert list(frames) == ["messages", "events", "poses", "arrivals"]
    assert len(frames["messages"]) == 3 and frames["events"].empty
    assert isinstance(frames["poses"]["robot"].dtype, pd.CategoricalDtype)
    assert frames["arrivals"]["t_s"].tolist() == [3.0]
