"""Work that arrives robot by robot within one instant, done at once on the run's threads.

A bus subscriber is called once per message: every robot's scan of a scan instant, every
robot's map of a map update. Where each message starts independent per-robot work (match
a scan against that robot's map, inflate that robot's costmap), an :class:`InstantBatch`
keeps the messages of the instant and, at the end of the stage they arrived in, computes
them all on the run's threads (:class:`cosim.core.workers.Workers`) and applies the
results one by one in arrival order. What the results cause (messages, table rows) thus
comes in the same order for any number of threads; with one thread the work is the same
as doing it on arrival, only later within the same instant and stage.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Generic, TypeVar

from cosim.core.kernel import Kernel, Stage
from cosim.core.workers import Workers

T = TypeVar("T")
R = TypeVar("R")


class InstantBatch(Generic[T, R]):
    """Items of one instant, computed together, applied in order.

    Args:
        kernel: the run's kernel (the batch closes with an event at the same instant).
        workers: the run's threads.
        compute: the per-item work; runs on any thread, so it must read only what no
            other item of the batch writes, and write only the item's own state.
        apply: takes each item and its result, in arrival order, on the kernel's thread.
        stage: the stage in which the batch closes: the one the items arrive in, so that
            what runs in later stages of the instant sees the results.
    """

    def __init__(
        self,
        kernel: Kernel,
        workers: Workers,
        compute: Callable[[T], R],
        apply: Callable[[T, R], None],
        stage: Stage,
    ) -> None:
        self.kernel = kernel
        self.workers = workers
        self.compute = compute
        self.apply = apply
        self.stage = stage
        self._items: list[T] = []
        self.closed = 0
        """Batches closed so far."""

    def add(self, item: T) -> None:
        """Keep ``item`` for this instant's batch (the first one schedules the batch's end)."""
        if not self._items:
            self.kernel.at(self.kernel.now_ns, self._close, stage=self.stage)
        self._items.append(item)

    def __len__(self) -> int:
        return len(self._items)

    def _close(self) -> None:
        items, self._items = self._items, []
        results = self.workers.map(self.compute, items)
        self.closed += 1
        for item, result in zip(items, results, strict=True):
            self.apply(item, result)


__all__ = ["InstantBatch"]
