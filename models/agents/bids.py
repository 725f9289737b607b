"""A learning agent's bids turned into a task choice (pure)."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from models.arrays import FloatArray


def highest_bid(bids: FloatArray, cost_row: FloatArray, free: Iterable[int]) -> int | None:
    """The free task the agent bids highest for, among those it may serve and bids for.

    Args:
        bids: the agent's bid for each task slot (task ``k`` of its epoch is slot ``k``);
            a bid of 0 or less declines the task; tasks past the last slot get no bid.
        cost_row: the agent's travel cost to each task of the epoch (m), ``inf`` where it
            may not or cannot serve it.
        free: indices of the tasks nobody else holds or claims.

    Returns:
        The index of the task with the highest bid (ties: the lowest index), or None when
        no slot holds a free task the agent may serve and bids for.
    """
    slots = min(len(bids), len(cost_row))
    candidates = sorted(
        {j for j in free if 0 <= j < slots and np.isfinite(cost_row[j]) and bids[j] > 0}
    )
    if not candidates:
        return None
    values = np.asarray(bids, dtype=float)[candidates]
    return candidates[int(np.argmax(values))]
