"""A run asked to stop ends between two events and keeps what ran."""

import json
import os
import signal
from collections.abc import Mapping
from typing import Any, ClassVar

import pandas as pd
import pytest

import cosim
from adapters.bags.reader import bag_info
from cosim.core.adapter import RunContext
from cosim.runner.stopping import RunStopped, StopRequest, stop_on_signals

STOP_AT_NS = 2_000_000_000
"""When the probe asks the run to stop (simulated ns)."""


def _stopper(request: StopRequest, signum: int) -> type:
    """An adapter that, at STOP_AT_NS, does what a signal's handler does."""

    class Stopper:
        name: ClassVar[str] = "stopper"
        requires: ClassVar[tuple[str, ...]] = ()

        def __init__(self, run: RunContext) -> None:
            pass

        def start(self, run: RunContext) -> None:
            run.kernel.at(STOP_AT_NS, lambda: request.handle(signum))

        def finish(self, run: RunContext) -> Mapping[str, Any]:
            return {}

    return Stopper


@pytest.mark.slow
def test_a_run_asked_to_stop_keeps_its_bag_tables_and_a_summary_saying_so(small_scenario, tmp_path):
    request = StopRequest()
    out = tmp_path / "run"
    with pytest.raises(RunStopped) as stopped:
        cosim.run(
            small_scenario,
            duration_s=1e6,
            out=out,
            adapters=[_stopper(request, signal.SIGTERM)],
            stop=request,
        )
    assert stopped.value.exit_status == 128 + signal.SIGTERM
    result = stopped.value.result
    assert result is not None and result.stopped == signal.SIGTERM
    summary = json.loads((out / "summary.json").read_text())
    assert summary["stopped"] == "SIGTERM"
    assert summary["planned_duration_s"] == 1e6
    reached = summary["sim_time_s"]
    assert STOP_AT_NS / 1e9 <= reached < 1e6
    poses = pd.read_parquet(out / "tables" / "poses.parquet")
    # sampled at 10 Hz up to the stop (4.2 - 0.1 is a hair above 4.1 in floating point)
    assert reached - 0.1 - 1e-9 <= poses.t_s.max() <= reached
    info = bag_info(out / "bag")
    assert (out / "bag" / "metadata.yaml").is_file()
    assert info.messages > 0 and info.end_ns <= reached * 1e9


def test_a_request_made_outside_the_kernel_stops_at_once_and_keeps_nothing(small_scenario):
    request = StopRequest()
    with pytest.raises(RunStopped) as stopped, request.deferred():
        request.handle(signal.SIGINT)  # noted: the run will not start
        cosim.run(small_scenario, stop=request)
    assert stopped.value.result is None
    assert stopped.value.exit_status == 130


def test_a_signal_while_deferring_is_noted_and_a_second_one_stops_at_once():
    request = StopRequest()
    with request.deferred():
        request.handle(signal.SIGTERM)
        assert request.signum == signal.SIGTERM
        with pytest.raises(RunStopped, match="stopped by SIGHUP"):
            request.handle(signal.SIGHUP)


def test_sigterm_and_sighup_reach_the_request_and_the_handlers_are_restored():
    before = {sig: signal.getsignal(sig) for sig in (signal.SIGTERM, signal.SIGHUP)}
    with stop_on_signals() as request, request.deferred():
        os.kill(os.getpid(), signal.SIGTERM)
        assert request.signum == signal.SIGTERM
    with pytest.raises(RunStopped) as stopped, stop_on_signals():
        os.kill(os.getpid(), signal.SIGHUP)
    assert stopped.value.signum == signal.SIGHUP
    assert {sig: signal.getsignal(sig) for sig in before} == before


def test_a_signal_the_process_ignores_stays_ignored():
    previous = signal.signal(signal.SIGHUP, signal.SIG_IGN)
    try:
        with stop_on_signals() as request, request.deferred():
            os.kill(os.getpid(), signal.SIGHUP)
            assert request.signum is None
        assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGHUP, previous)


def test_a_real_time_run_stopped_mid_batch_keeps_a_consistent_realtime_table(small_scenario):
    from cosim.recording.foxglove import LiveOptions

    request = StopRequest()
    with pytest.raises(RunStopped) as stopped:
        cosim.run(
            small_scenario,
            duration_s=1e6,
            live=LiveOptions(port=0, rate=1000.0),
            adapters=[_stopper(request, signal.SIGINT)],
            stop=request,
        )
    result = stopped.value.result
    assert result is not None and result.summary["stopped"] == "SIGINT"
    realtime = result.tables["realtime"]
    assert len(realtime) > 0 and realtime.t_s.max() <= result.summary["sim_time_s"]
