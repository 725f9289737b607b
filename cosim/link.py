"""The link between hosts: decides if and when a message reaches another host.

The bus hands every inter-host transmission to a :class:`Link`. The ideal link delivers
at once; the network model (``adapters.network.link``) decides with latency, loss, bandwidth,
range and partitions.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from enum import StrEnum
from typing import Protocol

from cosim.hosts import HostId


class DeliveryStatus(StrEnum):
    """Fate of one message towards one destination host."""

    DELIVERED = "delivered"
    LOST = "lost"
    QUEUE_FULL = "queue_full"
    OUT_OF_RANGE = "out_of_range"
    PARTITIONED = "partitioned"


@dataclass(frozen=True, slots=True)
class Transfer:
    """Outcome of a transmission towards one host.

    Attributes:
        dst: destination host.
        status: delivered or why not.
        t_recv_ns: arrival time (ns) when delivered, else ``None``.
    """

    dst: HostId
    status: DeliveryStatus
    t_recv_ns: int | None


class Link(Protocol):
    """Decides the fate of messages between hosts."""

    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> Sequence[Transfer]:
        """Send one message of ``nbytes`` from ``src`` at ``t_ns`` to every host in ``dsts``.

        One call is one transmission: a broadcast reaches several hosts with independent
        fates. Arrival times must not lie before ``t_ns``.
        """
        ...


class IdealLink:
    """A link that delivers every message instantly."""

    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> Sequence[Transfer]:
        """Deliver to every destination at ``t_ns``."""
        return [Transfer(dst, DeliveryStatus.DELIVERED, t_ns) for dst in dsts]
