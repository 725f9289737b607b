"""Network model throughput, one core: destination decisions per second of NetworkModel.transmit.

Three cases, each over 10 hosts sending in turn, 1 ms apart, 200-byte messages through a
100 Mbit/s interface (16 us each, so the queues never fill):

* ``unicast_bernoulli_normal``: one destination, Bernoulli loss 1 %, normal latency
  5 ms +- 2 ms (the target: >= 200,000 deliveries/s);
* ``broadcast10_bernoulli_normal``: the same, each transmission to 10 receivers (the 9
  other senders and one host that only listens);
* ``unicast_gilbert_elliott``: one destination, Gilbert-Elliott loss (p 1 %, r 30 %).

``outcomes_per_s`` counts every (message, destination) decision; ``deliveries_per_s``
counts the delivered ones. Run: ``.venv/bin/python bench/network_bench.py [repeat]``.
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from models.network import (
    BernoulliLoss,
    DeliveryStatus,
    GilbertElliottLoss,
    LinkParams,
    LossProcess,
    NetworkModel,
    NormalLatency,
)

Result = dict[str, Any]

SENDERS = [f"robot_{i}" for i in range(10)]
LISTENER = "base"
MESSAGES = 100_000
NBYTES = 200


def _streams(seed: int) -> Callable[[str], np.random.Generator]:
    root = np.random.SeedSequence(seed)

    def stream(name: str) -> np.random.Generator:
        key = tuple(name.encode())
        return np.random.Generator(
            np.random.PCG64(np.random.SeedSequence(root.entropy, spawn_key=key))
        )

    return stream


def _no_distance(a: str, b: str) -> float | None:
    return None


def _run(loss: Callable[[], LossProcess], broadcast: bool, seed: int) -> tuple[int, int, float]:
    params = LinkParams(latency=NormalLatency(5.0, 2.0), loss_factory=loss)
    model = NetworkModel(params, streams=_streams(seed), bandwidth_bps=100e6, queue_packets=64)
    hosts = [*SENDERS, LISTENER]
    plan = []
    for k in range(MESSAGES // (10 if broadcast else 1)):
        src = SENDERS[k % len(SENDERS)]
        if broadcast:
            dsts = [h for h in hosts if h != src]
        else:
            dsts = [SENDERS[(k * 7 + 3) % len(SENDERS)]]
            if dsts[0] == src:
                dsts = [LISTENER]
        plan.append((k * 1_000_000, src, dsts))
    transmit = model.transmit
    start = time.perf_counter()
    results = [transmit(t, src, dsts, NBYTES, _no_distance) for t, src, dsts in plan]
    wall = time.perf_counter() - start
    outcomes = sum(len(r) for r in results)
    delivered = sum(1 for r in results for _, fate, _ in r if fate is DeliveryStatus.DELIVERED)
    return outcomes, delivered, wall


def _case(loss: Callable[[], LossProcess], broadcast: bool, repeat: int) -> Result:
    outcome_rates, delivery_rates = [], []
    for seed in range(1, repeat + 1):
        outcomes, delivered, wall = _run(loss, broadcast, seed)
        outcome_rates.append(outcomes / wall)
        delivery_rates.append(delivered / wall)
    return {
        "outcomes_per_s_median": round(statistics.median(outcome_rates)),
        "deliveries_per_s_median": round(statistics.median(delivery_rates)),
        "deliveries_per_s_all": [round(r) for r in delivery_rates],
        "destinations_per_transmission": 10 if broadcast else 1,
    }


def network_deliveries_per_second(repeat: int) -> Result:
    """Medians over ``repeat`` runs of 100,000 destination decisions per case."""
    repeat = max(repeat, 3)
    return {
        "unicast_bernoulli_normal": _case(lambda: BernoulliLoss(0.01), False, repeat),
        "broadcast10_bernoulli_normal": _case(lambda: BernoulliLoss(0.01), True, repeat),
        "unicast_gilbert_elliott": _case(lambda: GilbertElliottLoss(0.01, 0.3), False, repeat),
        "target_unicast_deliveries_per_s": 200_000,
        "repeat": repeat,
    }


if __name__ == "__main__":
    print(
        json.dumps(
            network_deliveries_per_second(int(sys.argv[1]) if len(sys.argv) > 1 else 5), indent=2
        )
    )
