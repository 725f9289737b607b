"""The topic bus: ROS-like topics carrying immutable messages between adapters.

Subscribers live on hosts. A message published on host A reaches a subscriber on A at
once (synchronously, in subscription order) and a subscriber on host B through the
:class:`~cosim.link.Link` of the run, which decides if and when it arrives. A message
crosses the link once per destination host, however many subscribers that host has.
Every local delivery, remote delivery and drop is reported to the bus's tap (the
recorder).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple, Protocol

import simpy

from cosim.hosts import HostId
from cosim.kernel import Kernel, Stage
from cosim.link import DeliveryStatus, IdealLink, Link, Transfer
from cosim.messages import Message


class Envelope(NamedTuple):
    """What a subscriber learns about a message besides its content (immutable).

    Attributes:
        topic: topic name.
        src: publishing host.
        t_sent_ns: publication time (ns).
        t_recv_ns: delivery time (ns).
    """

    topic: str
    src: HostId
    t_sent_ns: int
    t_recv_ns: int


Callback = Callable[[Message, Envelope], None]


class BusTap(Protocol):
    """Observer of everything that crosses the bus."""

    def on_transfer(
        self,
        t_sent_ns: int,
        t_recv_ns: int | None,
        src: HostId,
        dst: HostId,
        topic: str,
        nbytes: int,
        status: DeliveryStatus,
    ) -> None:
        """Record one message towards one destination host."""
        ...


Route = tuple[tuple[Callback, ...], tuple[HostId, ...]]
"""For one topic and publishing host: the local callbacks and the remote hosts."""


class Bus:
    """Publish/subscribe between adapters on hosts.

    Args:
        kernel: the run's kernel (deliveries are scheduled on it, stage DELIVERY).
        link: decides inter-host deliveries; defaults to :class:`~cosim.link.IdealLink`.
        tap: observer of every transfer (the recorder), optional.
    """

    def __init__(self, kernel: Kernel, link: Link | None = None, tap: BusTap | None = None):
        self.kernel = kernel
        self.link: Link = link if link is not None else IdealLink()
        self.tap = tap
        self._topics: dict[str, dict[HostId, list[Callback]]] = {}
        self._routes: dict[tuple[str, HostId], Route] = {}
        self.published = 0

    def subscribe(self, topic: str, host: HostId, callback: Callback) -> None:
        """Call ``callback(message, envelope)`` for every message on ``topic`` reaching ``host``."""
        self._topics.setdefault(topic, {}).setdefault(host, []).append(callback)
        self._routes.clear()

    def subscribers(self, topic: str) -> list[HostId]:
        """Hosts with at least one subscriber on ``topic``, in subscription order."""
        return list(self._topics.get(topic, {}))

    def _route(self, topic: str, src: HostId) -> Route:
        by_host = self._topics.get(topic, {})
        local = tuple(by_host.get(src, ()))
        remote = tuple(host for host in by_host if host != src)
        route = (local, remote)
        self._routes[(topic, src)] = route
        return route

    def publish(self, topic: str, message: Message, src: HostId) -> None:
        """Publish ``message`` on ``topic`` from host ``src`` at the current time.

        Remote hosts are handed to the link first (their deliveries are scheduled), then
        local subscribers are called at once, in subscription order.
        """
        self.published += 1
        route = self._routes.get((topic, src))
        if route is None:
            route = self._route(topic, src)
        local, remote = route
        if not local and not remote:
            return
        now = int(self.kernel.env.now)
        nbytes = message.size_bytes()
        if remote:
            for transfer in self.link.transmit(now, src, remote, nbytes, topic):
                self._dispatch(topic, message, src, now, nbytes, transfer)
        if local:
            if self.tap is not None:
                self.tap.on_transfer(now, now, src, src, topic, nbytes, DeliveryStatus.DELIVERED)
            envelope = Envelope(topic, src, now, now)
            for callback in local:
                callback(message, envelope)

    def _dispatch(
        self,
        topic: str,
        message: Message,
        src: HostId,
        t_sent_ns: int,
        nbytes: int,
        transfer: Transfer,
    ) -> None:
        if self.tap is not None:
            self.tap.on_transfer(
                t_sent_ns, transfer.t_recv_ns, src, transfer.dst, topic, nbytes, transfer.status
            )
        if transfer.status is not DeliveryStatus.DELIVERED or transfer.t_recv_ns is None:
            return
        envelope = Envelope(topic, src, t_sent_ns, transfer.t_recv_ns)
        by_host = self._topics[topic]
        dst = transfer.dst

        def deliver(_event: simpy.Event) -> None:
            # subscribers as they are on arrival, as a ROS subscription would be
            for callback in tuple(by_host.get(dst, ())):
                callback(message, envelope)

        delay = transfer.t_recv_ns - t_sent_ns
        if delay < 0:
            raise ValueError(f"link delivered {topic} before it was sent ({delay} ns)")
        self.kernel.timeout(delay, Stage.DELIVERY).callbacks.append(deliver)
