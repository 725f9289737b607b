"""The recorder: every copy on the bus as a row, counts by status, the run's tables and files."""

import numpy as np
import pandas as pd
import pytest

from cosim.core.hosts import HostId
from cosim.core.link import DELIVERED, Transfer
from cosim.core.recorder import (
    EVENT_COLUMNS,
    EVENTS,
    MESSAGE_COLUMNS,
    MESSAGES,
    Recorder,
    merge_counts,
)
from cosim.core.table import TableSpec
from cosim.recording.dataframes import messages_frame
from models.network.delivery import DeliveryStatus

A, B, C = HostId("a"), HostId("b"), HostId("c")


def test_the_recorder_codes_hosts_topics_and_statuses_as_plain_strings_in_order_of_arrival():
    recorder = Recorder()
    rows = [
        (B, A, "/y", DeliveryStatus.LOST, None),
        (A, C, "/x", DeliveryStatus.DELIVERED, 7),
        (B, B, "/y", DeliveryStatus.DELIVERED, 3),
    ]
    for src, dst, topic, status, t_recv in rows:
        recorder.on_transfer(1, t_recv, src, dst, topic, 10, status)
    frame = messages_frame(recorder)
    assert list(frame["src_host"]) == ["b", "a", "b"]
    assert list(frame["dst_host"]) == ["a", "c", "b"]
    assert list(frame["topic"]) == ["/y", "/x", "/y"]
    assert list(frame["status"]) == ["lost", "delivered", "delivered"]
    categories = list(frame["status"].cat.categories)
    assert categories == ["lost", "delivered"]
    assert all(type(c) is str for c in categories)


def _recorded(batched: bool) -> Recorder:
    """Broadcasts, a lost copy, a local delivery; chunks of 2 rows cut through broadcasts."""
    d, g, h, z = HostId("d"), HostId("g"), HostId("h"), HostId("z")
    sends = [
        (
            A,
            "/x",
            [Transfer(z, DeliveryStatus.DELIVERED, 5), Transfer(B, DeliveryStatus.LOST, None)],
        ),
        (A, "/y", [Transfer(d, DeliveryStatus.DELIVERED, 6)]),
        (
            C,
            "/x",
            [Transfer(A, DeliveryStatus.DELIVERED, 7), Transfer(g, DeliveryStatus.DELIVERED, 9)],
        ),
        (h, "/z", [Transfer(h, DeliveryStatus.DELIVERED, 3)]),  # h first as a source
        (z, "/y", [Transfer(A, DeliveryStatus.QUEUE_FULL, None)] * 3),
    ]
    recorder = Recorder()
    for k, (src, topic, transfers) in enumerate(sends):
        if batched:
            recorder.on_transmission(k, src, topic, 10 + k, transfers)
        else:
            for t in transfers:
                recorder.on_transfer(k, t.t_recv_ns, src, t.dst, topic, 10 + k, t.status)
    return recorder


def test_a_transmission_recorded_at_once_gives_the_rows_codes_and_counts_of_each_in_turn(
    monkeypatch,
):
    """Hosts are coded per chunk, sources first: the chunks must be cut where they were.

    Rows 4 and 5 share a chunk: h (source of row 5) is coded before g (destination of row 4).
    """
    monkeypatch.setattr("cosim.core.recorder._FLUSH_ROWS", 2)
    batched, one_by_one = _recorded(batched=True), _recorded(batched=False)
    frame, expected = messages_frame(batched), messages_frame(one_by_one)
    pd.testing.assert_frame_equal(frame, expected)
    hosts = list(frame["src_host"].cat.categories)
    assert hosts == list(expected["src_host"].cat.categories) == ["a", "z", "b", "c", "d", "h", "g"]
    assert len(frame) == 9 and batched.counts == one_by_one.counts
    assert (batched.network_messages, batched.network_bytes) == (8, 97)
    assert (one_by_one.network_messages, one_by_one.network_bytes) == (8, 97)


def test_a_transmission_delivered_at_once_is_recorded_as_its_transfers(monkeypatch):
    monkeypatch.setattr("cosim.core.recorder._FLUSH_ROWS", 2)
    a, b = Recorder(), Recorder()
    sends = [(A, "/x", (B, C), 5), (C, "/y", (A,), 7), (B, "/x", (B, A, C), 9)]
    for k, (src, topic, dsts, t_recv) in enumerate(sends):
        a.on_all_delivered(k, src, topic, 10 + k, dsts, t_recv)
        b.on_transmission(
            k, src, topic, 10 + k, [Transfer(d, DeliveryStatus.DELIVERED, t_recv) for d in dsts]
        )
    pd.testing.assert_frame_equal(messages_frame(a), messages_frame(b))
    assert a.counts == b.counts and len(messages_frame(a)) == 6
    assert (
        (a.network_messages, a.network_bytes)
        == (b.network_messages, b.network_bytes)
        == (
            5,
            10 * 2 + 11 + 12 * 2,
        )
    )


def test_copies_are_counted_by_status_and_only_those_between_hosts_as_network_traffic():
    recorder = Recorder()
    recorder.on_transfer(0, 5, A, B, "/x", 100, DELIVERED)
    recorder.on_transfer(0, None, A, C, "/x", 100, "lost")
    recorder.on_transfer(0, 0, A, A, "/x", 100, DELIVERED)  # on its own host
    recorder.on_all_delivered(1, B, "/y", 7, [A, B, C], 9)
    assert recorder.counts == {DELIVERED: 5, "lost": 1}
    assert (recorder.network_messages, recorder.network_bytes) == (4, 2 * 100 + 2 * 7)


def test_a_recorder_not_keeping_messages_still_counts_them():
    recorder = Recorder(record_messages=False)
    recorder.on_transfer(0, 5, A, B, "/x", 100, DELIVERED)
    recorder.on_transmission(1, A, "/x", 10, [Transfer(B, "queue_full", None)])
    recorder.on_all_delivered(2, A, "/x", 10, [B, C], 3)
    assert recorder.counts == {DELIVERED: 3, "queue_full": 1}
    assert recorder.network_messages == 4
    assert all(len(column) == 0 for column in recorder.message_columns().values())


def test_an_empty_transmission_records_nothing():
    recorder = Recorder()
    recorder.on_transmission(0, A, "/x", 10, [])
    recorder.on_all_delivered(0, A, "/x", 10, [], 5)
    assert recorder.counts == {DELIVERED: 0} and recorder.network_messages == 0


def test_message_columns_hold_times_in_ns_minus_one_when_dropped_and_coded_strings():
    recorder = Recorder()
    recorder.on_transfer(1_000, None, A, B, "/x", 12, "lost")
    recorder.on_transfer(2_000, 2_500, B, A, "/y", 13, DELIVERED)
    columns = recorder.message_columns()
    assert columns["t_sent"].tolist() == [1_000, 2_000]
    assert columns["t_recv"].tolist() == [-1, 2_500]
    assert columns["bytes"].tolist() == [12, 13]
    assert [recorder.hosts.values[c] for c in columns["src"]] == ["a", "b"]
    assert [recorder.topics.values[c] for c in columns["topic"]] == ["/x", "/y"]
    assert [recorder.statuses.values[c] for c in columns["status"]] == ["lost", DELIVERED]


def test_no_messages_give_empty_columns_of_their_types():
    columns = Recorder().message_columns()
    assert list(columns) == ["t_sent", "t_recv", "src", "dst", "topic", "bytes", "status"]
    assert columns["t_sent"].dtype == np.int64 and columns["src"].dtype == np.int32
    assert all(len(c) == 0 for c in columns.values())


def test_events_are_rows_of_time_source_kind_and_detail():
    recorder = Recorder()
    recorder.event(5, "tasks", "done", "task 3 by robot_1")
    recorder.event(6, "fleet", "built")
    columns = recorder.events.columns()
    assert columns["t_ns"].tolist() == [5, 6]
    assert columns["detail"].tolist() == ["task 3 by robot_1", ""]


SPEC = TableSpec(
    "plans",
    "One row per plan.",
    {"t_s": "when (s)", "robot": "who", "planning_ms": "wall time (ms)"},
    categorical=("robot",),
    volatile=("planning_ms",),
)


def test_a_table_declared_by_its_spec_takes_its_columns_categories_and_volatile_columns():
    recorder = Recorder()
    table = recorder.table(SPEC)
    assert table.names == ["t_s", "robot", "planning_ms"]
    assert table.categorical == frozenset({"robot"})
    assert recorder.tables["plans"] is table and recorder.specs["plans"] is SPEC
    assert recorder.volatile["plans"] == ("planning_ms",)


def test_a_table_by_name_has_no_spec_and_no_volatile_columns_unless_given():
    recorder = Recorder()
    recorder.table("extra", ("a", "b"), categorical=("b",))
    assert "extra" not in recorder.specs and recorder.volatile["extra"] == ()


@pytest.mark.parametrize("name", ["plans", "messages", "events"])
def test_a_table_is_created_once_and_the_messages_and_events_names_are_taken(name):
    recorder = Recorder()
    recorder.table(SPEC)
    with pytest.raises(ValueError, match=rf"table '{name}' exists already"):
        recorder.table(name, ("a",))


def test_a_volatile_column_that_is_not_a_column_is_refused_naming_both():
    with pytest.raises(ValueError, match=r"volatile column 'ms' is not a column of 'x'"):
        Recorder().table("x", ("a",), volatile=("ms",))


def test_maps_and_files_are_kept_once_each():
    recorder = Recorder()
    recorder.add_file("sumo/aisles.net.xml", b"<net/>")
    recorder.add_map("final", object())  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"file 'sumo/aisles.net.xml' exists already"):
        recorder.add_file("sumo/aisles.net.xml", b"")
    with pytest.raises(ValueError, match=r"map 'final' exists already"):
        recorder.add_map("final", object())  # type: ignore[arg-type]
    assert recorder.files == {"sumo/aisles.net.xml": b"<net/>"}


def test_summaries_merge_without_overwriting_a_key():
    into = {"collisions": 0}
    merge_counts(into, {"tasks_done": 3})
    assert into == {"collisions": 0, "tasks_done": 3}
    with pytest.raises(ValueError, match=r"summary key 'collisions' reported twice"):
        merge_counts(into, {"collisions": 1})


@pytest.mark.parametrize("spec", [MESSAGES, EVENTS], ids=lambda s: s.name)
def test_the_recorders_own_tables_document_every_column_with_exact_ns_beside_seconds(spec):
    assert all(meaning for meaning in spec.columns.values())
    assert set(spec.categorical) <= set(spec.columns)
    for column in spec.columns:
        if column.endswith("_s"):
            assert column.removesuffix("_s") + "_ns" in spec.columns


def test_the_column_lists_are_the_specs_columns_in_order():
    assert tuple(MESSAGES.columns) == MESSAGE_COLUMNS
    assert EVENT_COLUMNS == ("t_s", "source", "kind", "detail", "t_ns")
    statuses = MESSAGES.columns["status"]
    assert all(status.value in statuses for status in DeliveryStatus)


class Scribbler:
    """A plugin adapter whose table row misspells a column of its TableSpec at 0.5 s."""

    name = "scribbler"
    requires = ("fleet",)
    tables = (TableSpec("scribbles", "One row per scribble.", {"t_s": "when", "robot": "who"}),)

    def __init__(self, run) -> None:
        self.table = run.recorder.table(self.tables[0])

    def start(self, run) -> None:
        run.kernel.at(500_000_000, lambda: self.table.append(t_s=0.5, robots="robot_1"))

    def finish(self, run) -> dict[str, float]:
        return {}


def test_a_plugins_row_that_does_not_match_its_table_spec_ends_the_run_naming_table_and_column():
    import traceback

    import cosim
    from cosim.core.plugins import PluginError
    from cosim.core.registry import registered
    from tests.conftest import SMALL

    overrides = {**SMALL, "scenario.adapters": [Scribbler.name]}
    with (
        registered("cosim.adapters", Scribbler.name, Scribbler),
        pytest.raises(PluginError) as caught,
    ):
        cosim.run(cosim.load_scenario("warehouse-random", overrides))
    assert str(caught.value).startswith(
        f"adapter 'scribbler' ({__name__}:Scribbler, given in code) wrote a row to table "
        "'scribbles' with unknown column 'robots' and no column "
        "'robot'; expected the columns of its TableSpec: t_s, robot while recording table "
        "'scribbles' at t = 0.5 s simulated"
    )
    # the runner names the plugin from the frames the error came through: its own is there,
    # right above the table
    frames = [frame for frame, _ in traceback.walk_tb(caught.value.__cause__.__traceback__)]
    assert frames[-1].f_code.co_name == "append"
    assert frames[-2].f_globals["__name__"] == __name__
