"""The network model: latency, loss, radio range, interface queues, topologies, partitions.

Pure: no kernel time, no SimPy. Times are integer nanoseconds; user parameters are in
ms, Mbit/s and probabilities. Randomness comes from ``numpy.random.Generator`` objects
handed in by the caller, one per directed link, so adding a host never changes the
numbers of another link.
"""

from __future__ import annotations

from models.network.delivery import DeliveryStatus
from models.network.interface import InterfaceQueue
from models.network.latency import (
    ConstantLatency,
    EmpiricalLatency,
    LatencyModel,
    LognormalLatency,
    NormalLatency,
    load_delay_csv,
)
from models.network.loss import BernoulliLoss, GilbertElliottLoss, LossProcess, NoLoss
from models.network.model import LinkParams, NetworkModel, Partition
from models.network.radio import PathLoss

__all__ = [
    "BernoulliLoss",
    "ConstantLatency",
    "DeliveryStatus",
    "EmpiricalLatency",
    "GilbertElliottLoss",
    "InterfaceQueue",
    "LatencyModel",
    "LinkParams",
    "LognormalLatency",
    "LossProcess",
    "NetworkModel",
    "NoLoss",
    "NormalLatency",
    "Partition",
    "PathLoss",
    "load_delay_csv",
]
