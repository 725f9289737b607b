"""The topic bus: ROS-like topics carrying immutable messages between adapters.

Subscribers live on hosts. A message published on host A reaches a subscriber on A at
once (synchronously, in subscription order) and a subscriber on host B through the
:class:`~cosim.core.link.Link` of the run, which decides if and when it arrives. A message
crosses the link once per destination host, however many subscribers that host has.
Every local delivery, remote delivery and drop is reported to the bus's tap (the
recorder).

Publishers *advertise* their topics with the message type and QoS, as a ROS 2 node
creates a publisher; recorders and the live view learn from the advertisements what a
run will publish before it starts. A message published on an advertised topic must be
exactly of the advertised type (one identity comparison per message): another type is
refused at publication (:class:`~cosim.core.plugins.PluginError`), before any monitor,
link or subscriber sees it, as it would be recorded under the wrong type and filtered out
before every inbox. A *monitor* sees every publication on a topic as it
is published, like a bag recorder on the publishing host: it is neither a subscriber nor
a host, so it adds no delivery, no network traffic and no row to any table.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from enum import StrEnum
from typing import NamedTuple, Protocol

import simpy

from cosim.core.hosts import HostId
from cosim.core.kernel import Kernel, Stage
from cosim.core.link import DELIVERED, AllDelivered, IdealLink, Later, Link, Transfer
from cosim.core.messages import Message
from cosim.core.plugins import PluginError


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
Monitor = Callable[[str, Message, HostId, int], None]
"""Sees a publication: (topic, message, publishing host, publication time in ns)."""


class TopicQos(StrEnum):
    """The quality of service a topic is offered with (ROS 2's profiles for such topics).

    The bag records it (rosbag2's ``offered_qos_profiles``); the live view re-sends the
    last message of a latched topic to a viewer that subscribes late.
    """

    DEFAULT = "default"
    """Reliable, volatile, keep last 10 (rclcpp's default profile)."""
    SENSOR = "sensor"
    """Best effort, volatile, keep last 5 (``rmw_qos_profile_sensor_data``)."""
    LATCHED = "latched"
    """Reliable, transient local, keep last 1 (``/tf_static``, ``/map``)."""


class Advertisement(NamedTuple):
    """What is published on a topic.

    Attributes:
        topic: topic name.
        message_type: the message class published on it.
        qos: how it is offered.
    """

    topic: str
    message_type: type[Message]
    qos: TopicQos


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
        status: str,
    ) -> None:
        """Record one message towards one destination host."""
        ...

    def on_transmission(
        self, t_sent_ns: int, src: HostId, topic: str, nbytes: int, transfers: Sequence[Transfer]
    ) -> None:
        """Record one transmission's transfers, in order: :meth:`on_transfer` for each."""
        ...

    def on_all_delivered(
        self,
        t_sent_ns: int,
        src: HostId,
        topic: str,
        nbytes: int,
        dsts: Sequence[HostId],
        t_recv_ns: int,
    ) -> None:
        """Record one transmission delivered to every host in ``dsts`` at ``t_recv_ns``.

        The same as :meth:`on_transmission` with a delivered :class:`Transfer` per host.
        """
        ...


Route = tuple[tuple[Callback, ...], tuple[HostId, ...], tuple[Monitor, ...], type[Message] | None]
"""For one topic and publishing host: the local callbacks, the remote hosts, the monitors,
and the advertised message type (None: the topic is not advertised)."""


class Bus:
    """Publish/subscribe between adapters on hosts.

    Args:
        kernel: the run's kernel (deliveries are scheduled on it, stage DELIVERY).
        link: decides inter-host deliveries; defaults to :class:`~cosim.core.link.IdealLink`.
        tap: observer of every transfer (the recorder), optional.
    """

    def __init__(self, kernel: Kernel, link: Link | None = None, tap: BusTap | None = None):
        self.kernel = kernel
        self.link: Link = link if link is not None else IdealLink()
        self.tap = tap
        self._topics: dict[str, dict[HostId, list[Callback]]] = {}
        self._routes: dict[tuple[str, HostId], Route] = {}
        self._monitors: dict[str, list[Monitor]] = {}
        self._advertised: dict[str, Advertisement] = {}
        self._later: dict[int, tuple[str, Message, HostId, int, int, tuple[HostId, ...]]] = {}
        """Transmissions whose fate the link tells later, by ticket."""
        self.published = 0

    def advertise(
        self, topic: str, message_type: type[Message], qos: TopicQos = TopicQos.DEFAULT
    ) -> None:
        """Declare that ``message_type`` messages are published on ``topic``.

        Several publishers may advertise one topic (every robot's claims) with the same
        type and QoS.

        Raises:
            ValueError: if ``topic`` is advertised already with another type or QoS.
            PluginError: ``message_type`` inherits a declared message without being
                declared itself (its size and bytes would be its parent's).
        """
        if hasattr(message_type, "wire") and "wire" not in vars(message_type):
            parent = next(c for c in message_type.__mro__[1:] if "wire" in vars(c))
            raise PluginError(
                None,
                f"advertised {topic!r} as {_name(message_type)}, a subclass of the declared "
                f"{_name(parent)} that is not declared itself; expected a message declared "
                "with cosim.core.messages.ros_message (its size and bytes come from it)",
                doing=f"advertising {topic!r}",
            )
        ad = Advertisement(topic, message_type, qos)
        known = self._advertised.setdefault(topic, ad)
        if known is ad:
            self._routes.clear()  # publications on it are checked from now on
        elif known != ad:
            raise ValueError(
                f"topic {topic!r} is advertised as {known.message_type.__name__} ({known.qos}); "
                f"cannot advertise it as {message_type.__name__} ({qos})"
            )

    def advertised(self) -> Mapping[str, Advertisement]:
        """Advertised topics, in advertisement order."""
        return dict(self._advertised)

    def monitor(self, topic: str, monitor: Monitor) -> None:
        """Call ``monitor(topic, message, src, t_ns)`` for every publication on ``topic``.

        Monitors run at publication, before any subscriber on the publishing host; they
        see messages whether or not anything subscribes, and change nothing.
        """
        self._monitors.setdefault(topic, []).append(monitor)
        self._routes.clear()

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
        ad = self._advertised.get(topic)
        declared = ad.message_type if ad is not None else None
        route = (local, remote, tuple(self._monitors.get(topic, ())), declared)
        self._routes[(topic, src)] = route
        return route

    def publish(self, topic: str, message: Message, src: HostId) -> None:
        """Publish ``message`` on ``topic`` from host ``src`` at the current time.

        Monitors see it first; remote hosts are handed to the link next (their deliveries
        are scheduled), then local subscribers are called at once, in subscription order.

        Raises:
            PluginError: ``topic`` is advertised with another message type (nothing is
                published; the plugin is the code that called, named by the runner).
        """
        self.publish_many((topic,), (message,), (src,))

    def publish_many(
        self, topics: Sequence[str], messages: Sequence[Message], sources: Sequence[HostId]
    ) -> None:
        """Publish ``messages[k]`` on ``topics[k]`` from ``sources[k]``, for k in order.

        The same as :meth:`publish` for each in turn (same monitors, deliveries, records
        and order), with the per-call work done once: a fleet's odometry, scans and
        commands are one call per tick instead of one per robot.

        Raises:
            ValueError: when the three sequences differ in length (nothing is published).
            PluginError: a message is not of its topic's advertised type (the messages
                before it are published).
        """
        if not len(topics) == len(messages) == len(sources):
            raise ValueError(
                f"publish_many needs one topic and one source per message: got "
                f"{len(topics)} topics, {len(messages)} messages, {len(sources)} sources"
            )
        routes, tap = self._routes, self.tap
        now = int(self.kernel.env.now)
        delivered = DELIVERED
        for topic, message, src in zip(topics, messages, sources, strict=True):
            self.published += 1
            route = routes.get((topic, src))
            if route is None:
                route = self._route(topic, src)
            local, remote, monitors, declared = route
            if declared is not None and type(message) is not declared:
                raise _wrong_type(topic, message, declared)
            for monitor in monitors:
                monitor(topic, message, src, now)
            if not local and not remote:
                continue
            nbytes = message.size_bytes()
            if remote:
                self._dispatch(topic, message, src, now, nbytes, remote)
            if local:
                if tap is not None:
                    tap.on_transfer(now, now, src, src, topic, nbytes, delivered)
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
        remote: tuple[HostId, ...],
    ) -> None:
        """Hand ``message`` to the link for ``remote`` and schedule what it delivers.

        Deliveries that arrive at the same instant share one kernel event (a broadcast on
        an ideal link: one event for 49 neighbours instead of 49), delivered in the link's
        order. The order of everything is as with an event each: events of one instant and
        stage run in scheduling order, and these were scheduled back to back.
        """
        outcome = self.link.transmit(t_sent_ns, src, remote, nbytes, topic)
        arrivals: dict[int, list[HostId]]
        if isinstance(outcome, Later):
            if outcome.ticket in self._later:
                raise ValueError(f"link gave ticket {outcome.ticket} to two transmissions")
            self._later[outcome.ticket] = (topic, message, src, t_sent_ns, nbytes, remote)
            return
        if isinstance(outcome, AllDelivered):
            # every copy at one instant: the transfers it stands for, without building them
            t_recv_ns = outcome.t_recv_ns
            if self.tap is not None:
                self.tap.on_all_delivered(t_sent_ns, src, topic, nbytes, remote, t_recv_ns)
            if t_recv_ns < t_sent_ns:
                delay = t_recv_ns - t_sent_ns
                raise ValueError(f"link delivered {topic} before it was sent ({delay} ns)")
            arrivals = {t_recv_ns: list(remote)}
        else:
            arrivals = self._arrivals(t_sent_ns, src, topic, nbytes, outcome)
        self._schedule(topic, message, src, t_sent_ns, arrivals)

    def settle(self, ticket: int, transfers: Sequence[Transfer]) -> None:
        """The fate of a transmission the link answered :class:`~cosim.core.link.Later` to.

        One :class:`Transfer` per destination host, in the order the link was given them.
        Copies whose arrival time is already past are delivered now, the others when they
        arrive; the tap records the link's arrival times.

        Raises:
            ValueError: for a ticket not pending, or transfers that do not match its hosts.
        """
        pending = self._later.pop(ticket, None)
        if pending is None:
            raise ValueError(f"no transmission is waiting for ticket {ticket}")
        topic, message, src, t_sent_ns, nbytes, remote = pending
        if tuple(t.dst for t in transfers) != remote:
            raise ValueError(
                f"ticket {ticket} ({topic}) went to {list(remote)}; the link settled it for "
                f"{[t.dst for t in transfers]}"
            )
        now = int(self.kernel.env.now)
        arrivals = self._arrivals(t_sent_ns, src, topic, nbytes, transfers)
        due: dict[int, list[HostId]] = {}
        for t_recv_ns, hosts in arrivals.items():
            due.setdefault(max(t_recv_ns, now), []).extend(hosts)
        self._schedule(topic, message, src, t_sent_ns, due)

    def unsettled(self) -> int:
        """How many transmissions still wait for the link to tell their fate."""
        return len(self._later)

    def _schedule(
        self,
        topic: str,
        message: Message,
        src: HostId,
        t_sent_ns: int,
        arrivals: dict[int, list[HostId]],
    ) -> None:
        """Deliver ``message`` to each host at its arrival time (ns), one event per instant."""
        by_host = self._topics[topic]
        now = int(self.kernel.env.now)
        for t_recv_ns, hosts in arrivals.items():
            envelope = Envelope(topic, src, t_sent_ns, t_recv_ns)

            def deliver(
                _event: simpy.Event, hosts: list[HostId] = hosts, envelope: Envelope = envelope
            ) -> None:
                for dst in hosts:
                    # subscribers as they are on arrival, as a ROS subscription would be
                    for callback in tuple(by_host.get(dst, ())):
                        callback(message, envelope)

            self.kernel.timeout(t_recv_ns - now, Stage.DELIVERY).callbacks.append(deliver)

    def _arrivals(
        self,
        t_sent_ns: int,
        src: HostId,
        topic: str,
        nbytes: int,
        transfers: Sequence[Transfer],
    ) -> dict[int, list[HostId]]:
        """The hosts each delivered transfer reaches, by arrival time (ns), in order."""
        if self.tap is not None:
            self.tap.on_transmission(t_sent_ns, src, topic, nbytes, transfers)
        arrivals: dict[int, list[HostId]] = {}
        for transfer in transfers:
            if transfer.status != DELIVERED or transfer.t_recv_ns is None:
                continue
            if transfer.t_recv_ns < t_sent_ns:
                delay = transfer.t_recv_ns - t_sent_ns
                raise ValueError(f"link delivered {topic} before it was sent ({delay} ns)")
            arrivals.setdefault(transfer.t_recv_ns, []).append(transfer.dst)
        return arrivals


def _wrong_type(topic: str, message: object, declared: type[Message]) -> PluginError:
    """The error for a message of another type than its topic's advertised one.

    The bus does not know whose code published: the runner names the plugin from the
    calling frames.
    """
    return PluginError(
        None,
        f"published a message of type {_name(type(message))} on {topic!r}, advertised as "
        f"{_name(declared)}; expected {declared.__qualname__} messages only (a topic carries "
        "the one type it was advertised with)",
        doing=f"publishing on {topic!r}",
    )


def _name(cls: type) -> str:
    return f"{cls.__module__}.{cls.__qualname__}"
