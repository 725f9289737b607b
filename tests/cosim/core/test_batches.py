"""Work one event hands over, computed together on the run's threads, applied in order."""

from __future__ import annotations

import threading

import pytest

from cosim.core.batches import InstantBatch
from cosim.core.kernel import Kernel, Stage
from cosim.core.workers import Workers


def _batch(
    kernel: Kernel, workers: Workers, log: list[tuple[str, int, int]]
) -> InstantBatch[int, int]:
    return InstantBatch(
        kernel,
        workers,
        lambda item: item * 10,
        lambda item, result: log.append(("applied", item, result)),
    )


@pytest.mark.parametrize("threads", [1, 2])
def test_items_of_one_event_are_applied_in_arrival_order_once_it_is_done(threads: int) -> None:
    kernel, workers = Kernel(), Workers(threads)
    log: list[tuple[str, int, int]] = []
    batch = _batch(kernel, workers, log)

    def arrive(now: int) -> None:
        for item in (3, 1, 2):
            batch.add(item)
        log.append(("handed over", now, 0))

    kernel.every(1_000, arrive, stage=Stage.SENSING)
    kernel.run(2_500)
    workers.close()
    # three events (0, 1000, 2000 ns), each batch applied once after its event
    one = [("applied", 3, 30), ("applied", 1, 10), ("applied", 2, 20)]
    assert log == [
        ("handed over", 0, 0),
        *one,
        ("handed over", 1000, 0),
        *one,
        ("handed over", 2000, 0),
        *one,
    ]
    assert batch.closed == 3
    assert len(batch) == 0


def test_the_batch_closes_before_any_other_event_of_the_same_instant_and_stage() -> None:
    kernel, workers = Kernel(), Workers(2)
    log: list[tuple[str, int, int]] = []
    batch = _batch(kernel, workers, log)
    kernel.at(500, lambda: batch.add(7), stage=Stage.CONTROL)
    kernel.at(500, lambda: log.append(("next event", kernel.now_ns, 0)), stage=Stage.CONTROL)
    kernel.run(1_000)
    workers.close()
    assert log == [("applied", 7, 70), ("next event", 500, 0)]


def test_compute_may_run_on_another_thread_and_apply_runs_on_the_kernels() -> None:
    kernel, workers = Kernel(), Workers(2)
    applied_on: list[int] = []
    barrier = threading.Barrier(2, timeout=30)
    batch: InstantBatch[int, int] = InstantBatch(
        kernel,
        workers,
        lambda item: (barrier.wait(), threading.get_ident())[1],
        lambda item, ident: applied_on.append(threading.get_ident()),
    )
    kernel.at(0, lambda: [batch.add(i) for i in range(2)] and None, stage=Stage.CONTROL)
    kernel.run(1)
    workers.close()
    assert applied_on == [threading.get_ident()] * 2
