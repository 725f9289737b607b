"""Work that arrives robot by robot within one instant, done at once on the run's threads.

A bus subscriber is called once per message: every robot's scan of a scan instant, every
robot's map of a map update. Where each message starts independent per-robot work (match
a scan against that robot's map, inflate that robot's costmap), an :class:`InstantBatch`
keeps the messages that one event hands over (one publication of every robot's scan, one
tick's maps) and, once that event is done and before any other runs, computes them all on
the run's threads (:class:`cosim.core.workers.Workers`) and applies the results one by one
in arrival order. What the results cause (messages, table rows) thus comes in the same
order for any number of threads, and nothing else in the run sees the difference from
taking each message up on arrival: the event that delivered them does nothing with them
after handing them over.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Generic, TypeVar

from cosim.core.kernel import Kernel
from cosim.core.workers import Workers

T = TypeVar("T")
R = TypeVar("R")


class InstantBatch(Generic[T, R]):
    """Items of one event, computed together, applied in order.

    Args:
        kernel: the run's kernel (the batch closes when the event that added its first
            item is done).
        workers: the run's threads.
        compute: the per-item work; runs on any thread, so it must read only what no
            other item of the batch writes, and write only the item's own state.
        apply: takes each item and its result, in arrival order, on the kernel's thread.
    """

    def __init__(
        self,
        kernel: Kernel,
        workers: Workers,
        compute: Callable[[T], R],
        apply: Callable[[T, R], None],
    ) -> None:
        self.kernel = kernel
        self.workers = workers
        self.compute = compute
        self.apply = apply
        self._items: list[T] = []
        self.closed = 0
        """Batches closed so far."""

    def add(self, item: T) -> None:
        """Keep ``item`` for this event's batch (the first one has the batch close after it)."""
        if not self._items:
            self.kernel.after_event(self._close)
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
