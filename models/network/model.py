"""The network between hosts: interface queues, partitions, topology, range, loss, latency.

One :meth:`NetworkModel.transmit` call is one transmission from one host, to one
destination or several (a broadcast). Its fate towards each destination is decided in
this order:

1. the sender's interface queue (:class:`~models.network.interface.InterfaceQueue`,
   one per sending host): the message is serialized once for all destinations; when the
   queue is full every destination gets ``QUEUE_FULL``;
2. ``PARTITIONED`` if a partition active at the send time separates the two hosts;
3. ``OUT_OF_RANGE`` if the pair is not an edge of the current topology, or the distance
   (when known) exceeds ``range_m``;
4. ``LOST`` if the link's loss process says so, or the path-loss reception draw fails;
5. else ``DELIVERED`` at ``t_leave + latency``; unless ``reorder``, never before the
   previous arrival on the same directed link (per-link FIFO).

Random numbers (the definition that fixes every result). Directed link ``a->b`` has its
own generator ``streams("network/a->b")``, asked for when the link is first used and used
for nothing else. It is read in blocks of ``BLOCK`` = 256 messages; block j is drawn as

    latency = params.latency.sample(g, 256)      # int64 ns
    u = g.random((256, 3))                       # columns: transition, loss, reception

and the k-th message offered to the link (counting every destination of every call,
whatever its fate) uses row ``k mod 256`` of block ``k // 256``. A message that ends
before a stage simply leaves that row's numbers unused, so message k of a link gets the
same numbers whatever happens to other messages or links (common random numbers across
sweeps). The loss process is advanced once for every message that reaches stage 4.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from models.errors import ModelError
from models.network.delivery import DeliveryStatus
from models.network.interface import InterfaceQueue
from models.network.latency import ConstantLatency, LatencyModel
from models.network.loss import LossProcess, NoLoss
from models.network.radio import PathLoss
from models.network.topology import Edge, Edges, edge

BLOCK = 256

Outcome = tuple[str, DeliveryStatus, int | None]

# Enum member lookup costs ~0.1 us on Python 3.11; transmit reads these constants instead.
_DELIVERED = DeliveryStatus.DELIVERED
_LOST = DeliveryStatus.LOST
_QUEUE_FULL = DeliveryStatus.QUEUE_FULL
_OUT_OF_RANGE = DeliveryStatus.OUT_OF_RANGE
_PARTITIONED = DeliveryStatus.PARTITIONED
DistanceFn = Callable[[str, str], float | None]


@dataclass(frozen=True)
class LinkParams:
    """What every directed link has in common.

    Attributes:
        latency: one-way latency distribution.
        loss_factory: makes one independent loss process per directed link.
        reorder: ``False`` keeps each directed link FIFO (a message never arrives before
            an earlier one of the same link); ``True`` lets jitter reorder.
        path_loss: distance-dependent reception, or ``None`` for none.
        range_m: hard cut-off distance (m): farther pairs are out of range; ``None`` for none.
    """

    latency: LatencyModel
    loss_factory: Callable[[], LossProcess]
    reorder: bool = False
    path_loss: PathLoss | None = None
    range_m: float | None = None

    def __post_init__(self) -> None:
        if self.range_m is not None and not self.range_m >= 0.0:
            raise ModelError("network.range_m", self.range_m, "a distance in m >= 0, or none")


@dataclass(frozen=True)
class Partition:
    """A scheduled cut of the network during ``[from_ns, to_ns)``.

    Attributes:
        from_ns: start (ns, included).
        to_ns: end (ns, excluded), >= ``from_ns``.
        hosts: an isolated group: every link between a member and a non-member is down.
        links: undirected host pairs whose link is down (stored as sorted pairs).
    """

    from_ns: int
    to_ns: int
    hosts: frozenset[str] = frozenset()
    links: frozenset[tuple[str, str]] = frozenset()

    def __post_init__(self) -> None:
        if self.to_ns < self.from_ns:
            raise ModelError(
                "network.partitions", (self.from_ns, self.to_ns), "an end at or after the start"
            )
        for pair in self.links:
            if len(pair) != 2 or pair[0] == pair[1]:
                raise ModelError("network.partitions", pair, "links as pairs of different hosts")
        object.__setattr__(self, "hosts", frozenset(self.hosts))
        object.__setattr__(self, "links", frozenset(edge(a, b) for a, b in self.links))

    def active(self, t_ns: int) -> bool:
        """Whether the partition holds at ``t_ns``."""
        return self.from_ns <= t_ns < self.to_ns

    def separates(self, a: str, b: str) -> bool:
        """Whether the partition cuts hosts ``a`` and ``b`` apart (when active)."""
        return ((a in self.hosts) != (b in self.hosts)) or edge(a, b) in self.links


class _Link:
    """State of one directed link: its stream, loss process, block of draws, FIFO time."""

    __slots__ = ("i", "last_ns", "latency_ns", "loss", "pair", "rng", "u_loss", "u_recv", "u_tr")

    def __init__(self, rng: np.random.Generator, loss: LossProcess, pair: Edge) -> None:
        self.rng = rng
        self.loss = loss
        self.pair = pair
        self.i = BLOCK
        self.last_ns = -(2**63)
        self.latency_ns: list[int] = []
        self.u_tr: list[float] = []
        self.u_loss: list[float] = []
        self.u_recv: list[float] = []

    def refill(self, latency: LatencyModel) -> None:
        self.latency_ns = latency.sample(self.rng, BLOCK).tolist()
        u = self.rng.random((BLOCK, 3))
        self.u_tr = u[:, 0].tolist()
        self.u_loss = u[:, 1].tolist()
        self.u_recv = u[:, 2].tolist()
        self.i = 0


FRAME_OVERHEAD_BYTES = 64
"""Headers a message carries on the air (bytes): 802.11 MAC header and FCS (28), LLC/SNAP
(8), IPv4 (20) and UDP (8)."""

FRAME_OVERHEAD_NS = 115_500
"""Time a frame holds the air beyond its bytes (ns), 802.11g OFDM: DIFS (28 us), the mean
backoff of an idle channel (CWmin 15 slots of 9 us, halved: 67.5 us) and the preamble and
PLCP header (20 us) (IEEE 802.11-2016, 17.4.4 and 18.4.6)."""


class NetworkModel:
    """Decides the fate and arrival time of every inter-host message.

    Args:
        params: link parameters, the same for every directed link.
        streams: gives the generator of a named random stream; called once per directed
            link, with ``"network/{src}->{dst}"``.
        bandwidth_bps: each sending host's interface rate (bit/s), ``None`` for unlimited.
        queue_packets: how many messages may wait in a host's interface (see
            :class:`~models.network.interface.InterfaceQueue`).
        partitions: scheduled partitions.
        airtime_bps: the rate of one channel every host shares (bit/s), ``None`` for none:
            each message then takes its turn on it, first come first served, for its bytes
            plus :data:`FRAME_OVERHEAD_BYTES` and :data:`FRAME_OVERHEAD_NS` (instead of each
            host's own interface: the two are not combined), so that latency grows with
            how many robots send how many bytes.

    Raises:
        ModelError: for a bad bandwidth or queue limit.
    """

    def __init__(
        self,
        params: LinkParams,
        *,
        streams: Callable[[str], np.random.Generator],
        bandwidth_bps: float | None,
        queue_packets: int,
        partitions: Sequence[Partition] = (),
        airtime_bps: float | None = None,
    ) -> None:
        InterfaceQueue(bandwidth_bps, queue_packets)  # validate now, not at the first send
        if airtime_bps is not None and bandwidth_bps is not None:
            raise ModelError(
                "network.bandwidth_mbps", bandwidth_bps / 1e6, "0 with airtime_mbps set"
            )
        self._air = None if airtime_bps is None else InterfaceQueue(airtime_bps, queue_packets)
        self._air_extra = (
            0
            if airtime_bps is None
            else (FRAME_OVERHEAD_BYTES + math.ceil(FRAME_OVERHEAD_NS * airtime_bps / 8e9))
        )
        self.params = params
        self.bandwidth_bps = bandwidth_bps
        self.queue_packets = queue_packets
        self.partitions = tuple(partitions)
        self._streams = streams
        self._edges: Edges | None = None
        self._queues: dict[str, InterfaceQueue] = {}
        self._links: dict[tuple[str, str], _Link] = {}
        self._ideal_ns = (
            _ideal_latency_ns(params, bandwidth_bps, self.partitions) if self._air is None else None
        )
        self.walls_between: Callable[[str, str], int] | None = None
        """How many walls stand between two hosts now, for the path loss's wall loss (None:
        none anywhere). Set by whoever knows where the hosts and walls are."""

    @property
    def edges(self) -> Edges | None:
        """The current topology; ``None`` when every pair is linked."""
        return self._edges

    def set_edges(self, edges: Edges | None) -> None:
        """Set the topology (sorted pairs, see ``models.network.topology``); ``None`` = all pairs.

        Range-based topologies are recomputed by the caller when hosts move.
        """
        self._edges = edges

    def queue(self, host: str) -> InterfaceQueue:
        """The interface queue of ``host``."""
        queue = self._queues.get(host)
        if queue is None:
            queue = self._queues[host] = InterfaceQueue(self.bandwidth_bps, self.queue_packets)
        return queue

    def _link(self, src: str, dst: str) -> _Link:
        if src == dst:
            raise ValueError(f"{src!r} cannot send to itself through the network")
        rng = self._streams(f"network/{src}->{dst}")
        link = _Link(rng, self.params.loss_factory(), edge(src, dst))
        self._links[(src, dst)] = link
        return link

    def transmit(
        self, t_ns: int, src: str, dsts: Sequence[str], nbytes: int, distance_m: DistanceFn
    ) -> list[Outcome]:
        """Send one message of ``nbytes`` from ``src`` at ``t_ns`` to every host in ``dsts``.

        Args:
            t_ns: send time (ns); calls come in non-decreasing time.
            src: sending host.
            dsts: destination hosts (not ``src``), decided in this order.
            nbytes: message size (bytes).
            distance_m: distance (m) between two hosts, or ``None`` when unknown (then
                range and path loss do not apply). Called only when ``range_m`` or
                ``path_loss`` is set, and only for messages that reach stage 3.

        Returns:
            ``(dst, fate, arrival_ns)`` per destination, in the order of ``dsts``;
            ``arrival_ns`` is ``None`` unless delivered.
        """
        outcome = self.transmit_all(t_ns, src, dsts, nbytes, distance_m)
        if isinstance(outcome, int):
            return [(dst, _DELIVERED, outcome) for dst in dsts]
        return outcome

    def transmit_all(
        self, t_ns: int, src: str, dsts: Sequence[str], nbytes: int, distance_m: DistanceFn
    ) -> int | list[Outcome]:
        """:meth:`transmit`, with the outcomes of an ideal network as one arrival time.

        Args:
            t_ns: send time (ns); calls come in non-decreasing time.
            src: sending host.
            dsts: destination hosts (not ``src``), decided in this order.
            nbytes: message size (bytes).
            distance_m: distance (m) between two hosts, or ``None`` when unknown.

        Returns:
            The arrival time (ns) of every copy when the network is ideal (each copy
            delivered then, as :meth:`transmit` lists them), else what :meth:`transmit`
            returns.
        """
        if self._air is not None:  # the shared channel, frame overheads included
            t_leave = self._air.enqueue(t_ns, nbytes + self._air_extra)
        else:
            queue = self._queues.get(src) or self.queue(src)
            t_leave = queue.enqueue(t_ns, nbytes)
        if self._ideal_ns is not None and self._edges is None and t_leave is not None:
            # no random number could show: every copy arrives after the constant latency,
            # in order, and the links' streams need not even be drawn
            if src in dsts:
                raise ValueError(f"{src!r} cannot send to itself through the network")
            return t_leave + self._ideal_ns
        links = self._links
        params = self.params
        latency = params.latency
        out: list[Outcome] = []
        if t_leave is None:
            for dst in dsts:
                link = links.get((src, dst)) or self._link(src, dst)
                if link.i == BLOCK:
                    link.refill(latency)
                link.i += 1
                out.append((dst, _QUEUE_FULL, None))
            return out
        partitions = self.partitions
        if partitions:
            partitions = tuple(p for p in partitions if p.from_ns <= t_ns < p.to_ns)
        edges = self._edges
        range_m = params.range_m
        path_loss = params.path_loss
        needs_distance = range_m is not None or path_loss is not None
        fifo = not params.reorder
        for dst in dsts:
            link = links.get((src, dst)) or self._link(src, dst)
            i = link.i
            if i == BLOCK:
                link.refill(latency)
                i = 0
            link.i = i + 1
            if partitions and any(p.separates(src, dst) for p in partitions):
                out.append((dst, _PARTITIONED, None))
                continue
            if edges is not None and link.pair not in edges:
                out.append((dst, _OUT_OF_RANGE, None))
                continue
            received = True
            if needs_distance:
                d = distance_m(src, dst)
                if d is not None:
                    if range_m is not None and d > range_m:
                        out.append((dst, _OUT_OF_RANGE, None))
                        continue
                    if path_loss is not None:
                        walls = 0 if self.walls_between is None else self.walls_between(src, dst)
                        received = link.u_recv[i] < path_loss.reception_probability_at(d, walls)
            if link.loss.lost(link.u_tr[i], link.u_loss[i]) or not received:
                out.append((dst, _LOST, None))
                continue
            arrival = t_leave + link.latency_ns[i]
            if fifo:
                if arrival < link.last_ns:
                    arrival = link.last_ns
                link.last_ns = arrival
            out.append((dst, _DELIVERED, arrival))
        return out


def _ideal_latency_ns(
    params: LinkParams, bandwidth_bps: float | None, partitions: Sequence[Partition]
) -> int | None:
    """The latency (ns) of a network that never drops, delays or reorders, else None.

    With a constant latency, no loss, no range, no path loss, no bandwidth limit and no
    partition, every message towards a linked host arrives after that latency, whatever
    its links draw: :meth:`NetworkModel.transmit` then skips them (same outcomes).
    """
    if (
        not isinstance(params.latency, ConstantLatency)
        or params.loss_factory is not NoLoss  # not called: a factory may count its calls
        or params.range_m is not None
        or params.path_loss is not None
        or bandwidth_bps is not None
        or partitions
    ):
        return None
    # the latency as the links draw it (the generator is not used by a constant)
    return int(params.latency.sample(np.random.default_rng(0), 1)[0])
