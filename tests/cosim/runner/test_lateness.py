"""A real-time run's lateness: one row per event batch, and its summary keys."""

from array import array

import pytest

from cosim.core.kernel import Lateness
from cosim.core.recorder import Recorder
from cosim.runner.lateness import REALTIME, record_lateness


def test_each_batch_is_a_row_and_the_summary_says_the_worst_the_p99_and_how_many_were_late():
    lateness = Lateness(
        t_ns=array("q", [0, 100_000_000, 200_000_000]),
        late_ns=array("q", [0, 2_500_000, 400_000]),
        events=array("q", [3, 1, 2]),
    )
    recorder = Recorder()
    summary = record_lateness(lateness, recorder)
    columns = recorder.tables[REALTIME.name].columns()
    assert list(columns["t_s"]) == [0.0, 0.1, 0.2]
    assert list(columns["lateness_ms"]) == [0.0, 2.5, 0.4]
    assert list(columns["events"]) == [3, 1, 2]
    assert summary["max_lateness_ms"] == 2.5
    assert summary["p99_lateness_ms"] == pytest.approx(2.458, abs=1e-3)
    assert summary["late_batches"] == 1  # only the batch more than 1 ms late


def test_a_batch_a_stop_cut_short_is_left_out_and_no_batch_gives_no_figures():
    cut = Lateness(t_ns=array("q", [0, 5]), late_ns=array("q", [0]), events=array("q", [1]))
    recorder = Recorder()
    record_lateness(cut, recorder)
    assert len(recorder.tables[REALTIME.name]) == 1
    assert record_lateness(Lateness(), Recorder()) == {
        "max_lateness_ms": None,
        "p99_lateness_ms": None,
        "late_batches": 0,
    }
