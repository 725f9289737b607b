import traceback

import pytest
import simpy

from cosim.core.kernel import Kernel, Stage
from cosim.core.timebase import period_ns


def test_a_10_hz_callback_fires_at_exact_multiples_of_100_ms():
    kernel = Kernel()
    times: list[int] = []
    kernel.every(period_ns(10.0), times.append, stage=Stage.SENSING)
    kernel.run(1_000_000_000)
    assert times == [k * 100_000_000 for k in range(10)]


def test_periodic_times_do_not_drift_over_an_hour():
    kernel = Kernel()
    times: list[int] = []
    kernel.every(period_ns(50.0), times.append, stage=Stage.PHYSICS)
    kernel.run(3600 * 1_000_000_000 + 1)
    assert len(times) == 3600 * 50 + 1
    assert times[-1] == 3600 * 1_000_000_000


def test_same_instant_events_run_in_stage_order_then_in_scheduling_order():
    kernel = Kernel()
    order: list[str] = []
    kernel.at(5, lambda: order.append("record"), Stage.RECORD)
    kernel.at(5, lambda: order.append("control-1"), Stage.CONTROL)
    kernel.at(5, lambda: order.append("physics"), Stage.PHYSICS)
    kernel.at(5, lambda: order.append("control-2"), Stage.CONTROL)
    kernel.at(5, lambda: order.append("sensing"), Stage.SENSING)
    kernel.at(5, lambda: order.append("delivery"), Stage.DELIVERY)
    kernel.run(10)
    assert order == ["physics", "delivery", "sensing", "control-1", "control-2", "record"]


def test_plain_simpy_timeouts_run_before_every_stage_at_the_same_instant():
    kernel = Kernel()
    order: list[str] = []
    kernel.at(7, lambda: order.append("physics"), Stage.PHYSICS)
    kernel.env.timeout(7).callbacks.append(lambda _e: order.append("simpy"))
    kernel.run(8)
    assert order == ["simpy", "physics"]


def test_run_leaves_events_due_at_until_unprocessed_and_ends_there():
    kernel = Kernel()
    fired: list[int] = []
    kernel.at(10, lambda: fired.append(10))
    kernel.at(20, lambda: fired.append(20))
    processed = kernel.run(20)
    assert fired == [10]
    assert processed == 1
    assert kernel.now_ns == 20
    kernel.run(21)
    assert fired == [10, 20]


def test_cancelled_periodic_callback_stops():
    kernel = Kernel()
    times: list[int] = []
    handle = kernel.every(10, times.append, stage=Stage.CONTROL)
    kernel.at(25, handle.cancel, Stage.PHYSICS)
    kernel.run(100)
    assert times == [0, 10, 20]


def test_a_failing_process_is_reraised_by_the_run():
    kernel = Kernel()

    def broken():
        yield kernel.timeout(5)
        raise RuntimeError("sensor exploded")

    kernel.process(broken())
    with pytest.raises(RuntimeError, match="sensor exploded"):
        kernel.run(10)


def test_the_run_raises_the_very_exception_a_process_raised_with_its_frames():
    kernel = Kernel()
    raised = RuntimeError("sensor exploded")

    def broken():
        yield kernel.timeout(5)
        raise raised

    kernel.process(broken())
    with pytest.raises(RuntimeError) as caught:
        kernel.run(10)
    assert caught.value is raised  # not SimPy's copy
    assert "broken" in [f.name for f in traceback.extract_tb(caught.value.__traceback__)]


class TwoArgsError(Exception):
    def __init__(self, code, text):
        super().__init__(f"{code}: {text}")


@pytest.mark.parametrize("realtime", [False, True])
def test_an_exception_simpy_cannot_copy_still_leaves_the_run_as_raised(realtime):
    kernel = Kernel(realtime=realtime, speed=1000.0) if realtime else Kernel()

    def broken():
        yield kernel.timeout(5)
        raise TwoArgsError(7, "unplugged")

    kernel.process(broken())
    with pytest.raises(TwoArgsError, match="7: unplugged"):
        kernel.run(10)
    assert kernel.events_processed >= 1


def test_staged_timeout_rejects_a_negative_delay():
    kernel = Kernel()
    with pytest.raises(ValueError, match="negative delay"):
        kernel.timeout(-1)


def test_processes_can_yield_staged_timeouts_with_integer_time():
    kernel = Kernel()
    seen: list[int] = []

    def proc():
        for _ in range(3):
            yield kernel.timeout(3_000_000, Stage.CONTROL)
            seen.append(kernel.now_ns)

    kernel.process(proc())
    kernel.run(10_000_000)
    assert seen == [3_000_000, 6_000_000, 9_000_000]
    assert all(isinstance(t, int) for t in seen)


def test_realtime_kernel_uses_a_simpy_realtime_environment():
    kernel = Kernel(realtime=True)
    assert isinstance(kernel.env, simpy.rt.RealtimeEnvironment)
    kernel.every(1_000_000, lambda now: None, stage=Stage.CONTROL)
    kernel.run(5_000_000)
    assert kernel.now_ns == 5_000_000


def test_progress_is_reported_at_the_end_of_a_run():
    kernel = Kernel()
    kernel.every(1000, lambda now: None, stage=Stage.CONTROL)
    reports: list[tuple[int, int]] = []
    kernel.run(1_000_000, progress=lambda now, n: reports.append((now, n)))
    assert reports[-1] == (1_000_000, 1000)


def test_a_realtime_kernel_records_one_lateness_entry_per_event_batch():
    kernel = Kernel(realtime=True, speed=10.0)
    seen = []
    kernel.every(period_ns(100.0), seen.append, stage=Stage.CONTROL)
    kernel.every(period_ns(100.0), seen.append, stage=Stage.SENSING)
    kernel.run(50_000_000)  # 50 ms simulated = 5 ms of wall clock at speed 10
    lateness = kernel.lateness
    assert lateness is not None
    assert list(lateness.t_ns) == [k * 10_000_000 for k in range(5)]
    assert list(lateness.events) == [2] * 5  # two callbacks at every instant, one batch
    assert all(late >= 0 for late in lateness.late_ns)


def test_a_batch_that_overruns_makes_the_next_batch_late_by_that_much():
    import time

    kernel = Kernel(realtime=True)
    kernel.at(0, lambda: time.sleep(0.05))  # 50 ms of work at t = 0
    kernel.at(10_000_000, lambda: None)  # due 10 ms later
    kernel.run(20_000_000)
    lateness = kernel.lateness
    assert lateness is not None
    late_ms = [late / 1e6 for late in lateness.late_ns]
    assert late_ms[0] < 20
    assert 35 <= late_ms[1] < 200  # about 40 ms behind: recorded, not absorbed


def test_a_kernel_that_is_not_realtime_measures_no_lateness():
    kernel = Kernel()
    kernel.run(1_000_000)
    assert kernel.lateness is None
    assert not kernel.realtime


def test_wall_and_simulated_clocks_map_onto_each_other_at_the_kernel_speed():
    kernel = Kernel(realtime=True, speed=2.0)
    wall = kernel.wall_ns(4_000_000_000)
    assert kernel.sim_ns(wall) == 4_000_000_000
    assert kernel.wall_ns(4_000_000_000) - kernel.wall_ns(0) == 2_000_000_000


@pytest.mark.parametrize("realtime", [False, True])
def test_after_event_runs_once_the_event_is_done_before_any_other(realtime):
    kernel = Kernel(realtime=True, speed=1e6) if realtime else Kernel()
    log = []

    def first():
        kernel.after_event(lambda: log.append("after first"))
        kernel.after_event(lambda: kernel.after_event(lambda: log.append("after after")))
        log.append("first")

    kernel.after_event(lambda: log.append("asked before the run"))
    kernel.at(10, first, stage=Stage.CONTROL)
    kernel.at(10, lambda: log.append("second"), stage=Stage.CONTROL)
    kernel.run(100)
    assert log == ["asked before the run", "first", "after first", "after after", "second"]


def test_advance_stops_after_the_whole_instant_that_woke_it():
    kernel = Kernel()
    order: list[tuple[int, str]] = []
    woke = [False]

    def wake() -> None:
        order.append((kernel.now_ns, "wake"))
        woke[0] = True

    kernel.at(30, wake, Stage.DELIVERY)
    kernel.at(30, lambda: order.append((30, "control")), Stage.CONTROL)
    kernel.at(40, lambda: order.append((40, "later")), Stage.CONTROL)
    processed = kernel.advance(100, lambda: woke[0])
    assert kernel.now_ns == 30
    assert order == [(30, "wake"), (30, "control")]
    assert processed == 2
    woke[0] = False
    kernel.advance(100, lambda: woke[0])
    assert kernel.now_ns == 100
    assert order[-1] == (40, "later")


def test_advance_refuses_a_real_time_kernel():
    with pytest.raises(ValueError, match="real time"):
        Kernel(realtime=True).advance(10, lambda: False)
