"""The link between hosts: decides if and when a message reaches another host.

The bus hands every inter-host transmission to a :class:`Link`. The ideal link delivers
at once; a run's network backend (``network.backend``: the built-in ``links`` models
latency, loss, bandwidth, range and partitions) decides otherwise.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

from cosim.core.hosts import HostId

DELIVERED = "delivered"
"""The status of a copy that arrived; any other status names why one was dropped.

A link says what happened to each copy in its own words: the built-in network model's are
those of ``models.network.delivery.DeliveryStatus`` (``lost``, ``queue_full``,
``out_of_range``, ``partitioned``); another backend may name its own."""


@dataclass(frozen=True, slots=True)
class Transfer:
    """Outcome of a transmission towards one host.

    Attributes:
        dst: destination host.
        status: :data:`DELIVERED`, or why not (the link's words).
        t_recv_ns: arrival time (ns) when delivered, else ``None``.
    """

    dst: HostId
    status: str
    t_recv_ns: int | None


@dataclass(frozen=True, slots=True)
class AllDelivered:
    """Outcome of a transmission delivered to every destination host at one instant.

    The same as a :class:`Transfer` per destination, in order, each :data:`DELIVERED` at
    ``t_recv_ns``, without building them (a broadcast on an ideal network).

    Attributes:
        t_recv_ns: arrival time (ns) of every copy.
    """

    t_recv_ns: int


@dataclass(frozen=True, slots=True)
class Later:
    """Outcome of a transmission whose fate the link tells later.

    A link that must see what else is on the air before it can tell (a radio simulator
    stepping in windows) returns this and, once it knows, calls
    :meth:`cosim.core.bus.Bus.settle` with the same ``ticket`` and a :class:`Transfer` per
    destination, in order. Copies whose arrival time has passed by then are delivered at
    once (the link's window is the most they are late by); the tap records the link's own
    arrival times.

    Attributes:
        ticket: the link's id of this transmission, unique among those not settled yet.
    """

    ticket: int


class Link(Protocol):
    """Decides the fate of messages between hosts."""

    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> Sequence[Transfer] | AllDelivered | Later:
        """Send one message of ``nbytes`` from ``src`` at ``t_ns`` to every host in ``dsts``.

        One call is one transmission: a broadcast reaches several hosts with independent
        fates, a :class:`Transfer` each in the order of ``dsts`` (or :class:`AllDelivered`
        when every copy arrives at one instant, or :class:`Later` when the link tells the
        bus afterwards). Arrival times must not lie before ``t_ns``.
        """
        ...


class IdealLink:
    """A link that delivers every message instantly."""

    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> AllDelivered:
        """Deliver to every destination at ``t_ns``."""
        return AllDelivered(t_ns)
