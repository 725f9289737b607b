"""The run's worker threads: results in order, failures on the run's thread, every row once."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.core.workers import MAX_THREADS, Workers, available_cores
from models.sensing.raycast import _cast  # a nogil kernel


@given(
    items=st.lists(st.integers(0, 1000), max_size=40),
    threads=st.integers(1, 4),
)
@settings(max_examples=60, deadline=None)
def test_results_come_back_in_the_items_order_for_any_number_of_threads(
    items: list[int], threads: int
) -> None:
    workers = Workers(threads)
    try:

        def slow_for_small(item: int) -> int:
            # later items finish first: order must come from the items, not from finishing
            for _ in range(1000 - item):
                pass
            return item * item

        assert workers.map(slow_for_small, items) == [i * i for i in items]
    finally:
        workers.close()


def test_two_threads_run_items_at_the_same_time() -> None:
    # each item waits for the other at a barrier: one thread alone would never pass it
    workers = Workers(2)
    barrier = threading.Barrier(2, timeout=30)
    try:
        idents = workers.map(lambda _: (barrier.wait(), threading.get_ident())[1], [0, 1])
    finally:
        workers.close()
    assert len(set(idents)) == 2
    assert threading.get_ident() in idents  # the run's own thread is worker 0


def test_one_thread_runs_every_item_inline_on_the_calling_thread() -> None:
    workers = Workers(1)
    idents = workers.map(lambda _: threading.get_ident(), list(range(5)))
    assert set(idents) == {threading.get_ident()}
    assert workers.batches == 0


def test_the_first_failure_in_item_order_is_raised_once_every_item_has_finished() -> None:
    workers = Workers(2)
    finished: list[int] = []

    def work(item: int) -> int:
        if item == 1:
            time.sleep(0.01)  # fails late: the failure of item 3 must not be the one raised
            raise ValueError("item 1")
        if item == 3:
            raise KeyError("item 3")
        finished.append(item)
        return item

    try:
        with pytest.raises(ValueError, match="item 1"):
            workers.map(work, [0, 1, 2, 3, 4])
    finally:
        workers.close()
    assert sorted(finished) == [0, 2, 4]


@given(count=st.integers(0, 200), threads=st.integers(1, 6), minimum=st.integers(1, 30))
@settings(max_examples=80, deadline=None)
def test_chunks_cover_every_row_exactly_once(count: int, threads: int, minimum: int) -> None:
    workers = Workers(threads)
    seen = np.zeros(count, dtype=int)
    lock = threading.Lock()

    def rows(start: int, stop: int) -> None:
        with lock:
            seen[start:stop] += 1

    try:
        workers.chunks(count, rows, minimum=minimum)
    finally:
        workers.close()
    assert (seen == 1).all()


def test_the_summary_says_how_busy_each_thread_was() -> None:
    workers = Workers(2)
    try:
        workers.map(lambda _: sum(range(400_000)), list(range(8)))
        summary = workers.summary(wall_s=10.0)
    finally:
        workers.close()
    assert summary["threads"] == 2
    busy = summary["thread_busy"]
    assert len(busy["busy_s"]) == len(busy["share_of_wall"]) == 2
    assert busy["busy_s"][0] > 0
    assert busy["share_of_wall"][0] == round(busy["busy_s"][0] / 10.0, 3)
    assert busy["batches"] == 1


@pytest.mark.parametrize("threads", [0, -1, MAX_THREADS + 1, True, 1.5, "2"])
def test_a_thread_count_out_of_bounds_or_no_int_is_refused(threads: object) -> None:
    with pytest.raises(ValueError, match="threads must be"):
        Workers(threads)  # type: ignore[arg-type]


def test_the_cores_available_are_at_least_one() -> None:
    assert available_cores() >= 1


def test_the_compiled_kernels_release_the_interpreter_lock() -> None:
    # nogil=True is what lets two threads cast at once; a kernel compiled without it
    # would still be correct, only serial: said by numba's own flag
    assert _cast.targetoptions.get("nogil") is True


def test_an_interrupt_on_the_run_s_thread_leaves_the_batch_at_once() -> None:
    workers = Workers(2)

    def work(item: int) -> int:
        if threading.current_thread() is threading.main_thread():
            raise KeyboardInterrupt  # Ctrl-C, or the watchdog, while the run's thread works
        time.sleep(0.001)
        return item

    try:
        with pytest.raises(KeyboardInterrupt):
            # with 200 short items the run's thread surely takes one
            workers.map(work, list(range(200)))
    finally:
        workers.close()


def test_an_item_that_spreads_work_of_its_own_runs_it_inline_without_waiting_for_itself() -> None:
    workers = Workers(2)
    try:
        nested = workers.map(lambda i: sum(workers.map(lambda j: i * j, [1, 2, 3])), [1, 2, 3, 4])
        again = workers.map(lambda i: i + 1, [1, 2])  # the run's thread spreads again after
    finally:
        workers.close()
    assert nested == [6, 12, 18, 24]
    assert again == [2, 3]
    assert workers.batches == 2
