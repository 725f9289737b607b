"""A run asked to stop ends between two events and keeps what ran."""

import json
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


@pytest.fixture
def sighup_at_its_default():
    """SIGHUP as a terminal leaves it (the tests may run under ``nohup``, which ignores it)."""
    previous = signal.signal(signal.SIGHUP, signal.SIG_DFL)
    yield
    signal.signal(signal.SIGHUP, previous)


def test_sigterm_and_sighup_reach_the_request_and_the_handlers_are_restored(sighup_at_its_default):
    before = {sig: signal.getsignal(sig) for sig in (signal.SIGTERM, signal.SIGHUP)}
    with stop_on_signals() as request, request.deferred():
        signal.raise_signal(signal.SIGTERM)
        assert request.signum == signal.SIGTERM
    with pytest.raises(RunStopped) as stopped, stop_on_signals():
        signal.raise_signal(signal.SIGHUP)
    assert stopped.value.signum == signal.SIGHUP
    assert {sig: signal.getsignal(sig) for sig in before} == before


def test_a_signal_the_process_ignores_stays_ignored():
    previous = signal.signal(signal.SIGHUP, signal.SIG_IGN)
    try:
        with stop_on_signals() as request, request.deferred():
            signal.raise_signal(signal.SIGHUP)
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


class Halt(KeyboardInterrupt):
    """Another stop than a run's (a study's stop is one)."""

    def __init__(self, signum: int) -> None:
        self.signum = signum
        super().__init__(f"halted by {signum}")


def test_a_request_raises_the_stop_it_was_made_with():
    request = StopRequest(Halt)
    with pytest.raises(Halt, match="halted by 15"):
        request.handle(signal.SIGTERM)
    with pytest.raises(Halt), request.immediate():
        pass


def test_a_deferred_stop_is_raised_where_the_code_looks_for_it_and_not_before():
    request = StopRequest(Halt)
    request.raise_if_requested()  # nothing asked: nothing happens
    with request.deferred():
        request.handle(signal.SIGHUP)  # only noted, as inside a run
    with pytest.raises(Halt) as halted:
        request.raise_if_requested()
    assert halted.value.signum == signal.SIGHUP


def test_signals_reach_the_request_given_to_stop_on_signals():
    given = StopRequest(Halt)
    with stop_on_signals(request=given) as request, request.deferred():
        assert request is given
        signal.raise_signal(signal.SIGTERM)
        assert given.signum == signal.SIGTERM
