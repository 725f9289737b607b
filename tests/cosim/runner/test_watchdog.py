"""The watchdog stops code that goes past its deadline without a beat, and nothing else."""

import threading
import time

import pytest

from cosim.runner.faults import Hung
from cosim.runner.watchdog import Watchdog


def test_code_asleep_on_the_main_thread_is_stopped_at_the_deadline():
    start = time.monotonic()
    with pytest.raises(Hung) as caught, Watchdog(0.3):
        time.sleep(30)
    waited = time.monotonic() - start
    assert 0.3 <= waited < 2.0
    assert caught.value.timeout_s == 0.3 and "did not return within 0.3 s" in str(caught.value)


def test_a_busy_loop_that_swallows_exceptions_is_stopped_too():
    with pytest.raises(Hung), Watchdog(0.3):
        while True:
            try:  # a plugin's catch-all does not catch it
                sum(range(1000))
            except Exception:
                continue


def test_beats_keep_slow_but_living_code_going():
    with Watchdog(0.3) as watchdog:
        for _ in range(8):
            time.sleep(0.1)
            watchdog.beat()
    assert not watchdog.fired


def test_time_spent_compiling_does_not_count():
    compiling = [True]
    with Watchdog(0.2, busy=lambda: compiling[0]) as watchdog:
        time.sleep(0.6)
        compiling[0] = False
        watchdog.beat()
    assert not watchdog.fired


def test_a_deadline_of_zero_watches_nothing():
    watchdog = Watchdog(0)
    with watchdog:
        time.sleep(0.05)
    assert not watchdog.active and not watchdog.fired


def test_on_another_thread_python_code_is_stopped_by_an_asynchronous_exception():
    outcome = []

    def worker():
        try:
            with Watchdog(0.3):
                while True:
                    sum(range(1000))
        except Hung as hung:
            outcome.append(hung.timeout_s)

    thread = threading.Thread(target=worker)
    thread.start()
    thread.join(timeout=10)
    assert not thread.is_alive() and outcome == [0.3]


def test_the_signal_handler_in_place_before_is_put_back():
    import signal

    before = signal.getsignal(signal.SIGALRM)
    with Watchdog(5):
        assert signal.getsignal(signal.SIGALRM) is not before
    assert signal.getsignal(signal.SIGALRM) == before
