import pytest

from adapters.mocap.source import MocapAdapter
from adapters.mocap.tables import EVENTS, MOCAP, MOCAP_COLUMNS, MocapRecords
from cosim.core.adapter import RunContext
from cosim.core.bus import Bus
from cosim.core.kernel import Kernel
from cosim.core.recorder import Recorder
from cosim.core.rng import RngStreams
from cosim.recording.dataframes import table_frame

SUMMARY_KEYS = {
    "mocap_poses",
    "mocap_dropouts",
    "mocap_rejected_jumps",
    "mocap_rejected_out_of_order",
    "mocap_invalid",
    "mocap_rejected_off_map",
    "mocap_stale_stops",
}


def bare_run() -> RunContext:
    kernel = Kernel()
    recorder = Recorder()
    return RunContext(None, kernel, Bus(kernel, tap=recorder), RngStreams(1), recorder)  # type: ignore[arg-type]


def test_the_mocap_table_has_a_row_per_exception_with_time_in_seconds():
    assert MOCAP.name == "mocap"
    assert MOCAP_COLUMNS == ("t_s", "robot", "event", "detail")
    assert MOCAP.columns["t_s"].endswith("(s)")


def test_the_categorical_columns_are_columns_of_the_table():
    assert set(MOCAP.categorical) == {"robot", "event"}
    assert set(MOCAP.categorical) <= set(MOCAP.columns)
    assert set(MOCAP.volatile) <= set(MOCAP.columns)


def test_the_event_column_documents_every_event():
    meaning = MOCAP.columns["event"]
    for event in EVENTS:
        assert event in meaning


def test_the_mocap_adapter_declares_the_table_it_writes():
    assert MocapAdapter.tables == (MOCAP,)


def test_the_records_are_created_once_per_run_and_shared():
    run = bare_run()
    records = MocapRecords.of(run)
    assert MocapRecords.of(run) is records
    assert run.recorder.tables["mocap"] is records.table
    assert run.recorder.specs["mocap"] is MOCAP


def test_a_row_is_recorded_in_seconds_and_counted_by_event():
    records = MocapRecords.of(bare_run())
    records.row(1_500_000_000, "robot_2", "jump", "2.000 m in 0.010 s")
    records.row(2_000_000_000, "robot_1", "stale")
    records.row(2_250_000_000, "robot_1", "stale", "pose 0.3 s old")
    frame = table_frame(records.table)
    assert list(frame.t_s) == [1.5, 2.0, 2.25]
    assert list(frame.robot) == ["robot_2", "robot_1", "robot_1"]
    assert list(frame.detail) == ["2.000 m in 0.010 s", "", "pose 0.3 s old"]
    assert records.counts["stale"] == 2 and records.counts["jump"] == 1


def test_an_unknown_event_is_refused_naming_it_and_the_known_ones():
    records = MocapRecords.of(bare_run())
    with pytest.raises(ValueError) as refused:
        records.row(0, "robot_1", "teleported")
    assert str(refused.value) == f"unknown mocap event 'teleported'; expected one of {EVENTS}"
    assert len(records.table) == 0


def test_the_summary_counts_rows_and_uncounted_things_and_goes_to_the_first_who_asks():
    records = MocapRecords.of(bare_run())
    records.count("poses", 40)
    records.count("poses")
    records.count("dropouts", 3)
    records.count("off_map_poses", 5)
    for event in ("jump", "jump", "out_of_order", "invalid", "off_map", "stale"):
        records.row(0, "robot_1", event)
    summary = records.summary()
    assert set(summary) == SUMMARY_KEYS
    assert summary == {
        "mocap_poses": 41,
        "mocap_dropouts": 3,
        "mocap_rejected_jumps": 2,
        "mocap_rejected_out_of_order": 1,
        "mocap_invalid": 1,
        "mocap_rejected_off_map": 5,
        "mocap_stale_stops": 1,
    }
    assert records.summary() == {}  # shared by the source and the robots: reported once


def test_a_run_without_exceptions_sums_to_zero():
    summary = MocapRecords.of(bare_run()).summary()
    assert summary == dict.fromkeys(SUMMARY_KEYS, 0)
