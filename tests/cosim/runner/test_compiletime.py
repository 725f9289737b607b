"""A first run's numba compiling is said apart from the run loop's real-time factor."""

import time
from collections.abc import Mapping
from typing import Any, ClassVar

import pytest
from numba.core import event

import cosim
from cosim.core.adapter import RunContext
from cosim.runner import compiletime
from cosim.runner.compiletime import CompileClock, speed_phrase

COMPILE_AT_NS = 1_000_000_000
"""When the probe adapter "compiles" (simulated ns)."""
COMPILE_S = 0.3
"""How long its compile lasts (wall s)."""


def test_the_speed_line_says_the_compile_time_apart_from_the_real_time_factor():
    assert speed_phrase(60.0, 0.9, 12.94) == (
        "60 s simulated in 0.90 s (66.7x real time), "
        "plus 12.9 s compiling kernels on this first run (cached now)"
    )


def test_a_run_whose_kernels_came_from_the_cache_says_no_compile_time():
    assert speed_phrase(120.0, 1.02, 0.01) == "120 s simulated in 1.02 s (118x real time)"
    assert speed_phrase(120.0, 1.02) == "120 s simulated in 1.02 s (118x real time)"


def test_a_run_of_no_measurable_wall_time_says_its_factor_is_unknown():
    assert speed_phrase(0.0, 0.0, 0.0) == "0 s simulated in 0.00 s (real-time factor unknown)"


def test_the_clock_counts_nested_compiles_once_and_only_while_installed(monkeypatch):
    now = [100.0]
    monkeypatch.setattr(compiletime.time, "perf_counter", lambda: now[0])
    with event.trigger_event(compiletime.COMPILE_EVENT):  # before: not counted
        now[0] += 5.0
    with CompileClock() as clock:
        with event.trigger_event(compiletime.COMPILE_EVENT):
            now[0] += 1.0
            with event.trigger_event(compiletime.COMPILE_EVENT):  # a callee compiled inside
                now[0] += 2.0
            assert clock.seconds == 3.0  # a compile under way counts up to now
            now[0] += 0.5
        now[0] += 10.0  # running, not compiling
        with event.trigger_event(compiletime.COMPILE_EVENT):
            now[0] += 0.25
    with event.trigger_event(compiletime.COMPILE_EVENT):  # after: not counted
        now[0] += 7.0
    assert clock.seconds == 3.75


@pytest.mark.slow  # numba compiles a kernel (about 0.5 s)
def test_the_clock_times_a_real_numba_compile_and_not_the_calls_after_it():
    import numba

    def triple(x: float) -> float:
        return 3.0 * x

    kernel = numba.njit(triple)  # no cache: compiled here, whatever ran before
    with CompileClock() as clock:
        assert kernel(2.0) == 6.0
        compiled_s = clock.seconds
        for _ in range(1000):
            kernel(1.0)
    assert compiled_s > 0.0
    assert clock.seconds == compiled_s


class _Compiler:
    """An adapter that, at COMPILE_AT_NS, spends COMPILE_S inside numba's compile event."""

    name: ClassVar[str] = "compiler"
    requires: ClassVar[tuple[str, ...]] = ()

    def __init__(self, run: RunContext) -> None:
        pass

    def start(self, run: RunContext) -> None:
        run.kernel.at(COMPILE_AT_NS, self._compile)

    def _compile(self) -> None:
        with event.trigger_event(compiletime.COMPILE_EVENT):
            time.sleep(COMPILE_S)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        return {}


@pytest.mark.slow  # sleeps COMPILE_S inside a run
def test_a_run_that_compiles_reports_the_loops_speed_without_the_compile_time(small_scenario):
    start = time.perf_counter()
    result = cosim.run(small_scenario, adapters=[_Compiler])
    elapsed_s = time.perf_counter() - start
    assert COMPILE_S <= result.compile_time_s < COMPILE_S + 0.5
    wall_s = result.summary["wall_time_s"]
    assert 0.0 < wall_s <= elapsed_s - COMPILE_S
    assert result.summary["real_time_factor"] == pytest.approx(3.0 / wall_s, rel=0.01)
