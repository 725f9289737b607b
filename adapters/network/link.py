"""The network adapter: every inter-host message crosses the network model.

It builds :class:`models.network.model.NetworkModel` from ``[network]``, installs it as
the bus's link, feeds it the robots' ground-truth positions for range and path loss,
records link changes (topology, range, partitions) in ``tables/links``, and offers a
:class:`NetworkView` (who can hear whom right now) to protocols. Robots talk to each other
along the topology; the base station (and any host without a position) reaches every
robot, subject to latency, loss, bandwidth and partitions.
"""

from __future__ import annotations

import functools
from array import array
from collections.abc import Callable, Mapping, Sequence
from typing import Any, ClassVar

import numpy as np

from adapters.network.settings import NetworkConfig
from adapters.network.setup import build_model, build_topology, partitions_of
from cosim.core.adapter import RunContext
from cosim.core.errors import ConfigError
from cosim.core.hosts import HostId, HostKind
from cosim.core.kernel import Stage
from cosim.core.link import AllDelivered, DeliveryStatus, Transfer
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S, period_ns
from models.fleet.kinematics import FleetState
from models.network.fate import Fate
from models.network.model import NetworkModel, Partition
from models.network.topology import Edges, edge

LINKS = TableSpec(
    "links",
    "The links between hosts at t = 0, then every change (by range or partition).",
    {
        "t_s": "when (s)",
        "a": "one host",
        "b": "the other host",
        "up": "whether the pair can reach each other from then on",
    },
    categorical=("a", "b"),
)
LINK_COLUMNS = tuple(LINKS.columns)
_STATUS = {fate: DeliveryStatus(fate.value) for fate in Fate}


class NetworkLink:
    """The bus's :class:`cosim.core.link.Link`, backed by the network model."""

    def __init__(self, model: NetworkModel, distance_m: Callable[[str, str], float | None]):
        self.model = model
        self.distance_m = distance_m
        self.latencies_ns = array("q")

    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> Sequence[Transfer] | AllDelivered:
        """Decide the fate of one transmission towards every destination host."""
        outcome = self.model.transmit_all(t_ns, src, dsts, nbytes, self.distance_m)
        latencies = self.latencies_ns
        if isinstance(outcome, int):  # an ideal network: every copy after the latency
            latencies.extend([outcome - t_ns] * len(dsts))
            return AllDelivered(outcome)
        out = []
        for dst, fate, arrival in outcome:
            if arrival is not None:
                latencies.append(arrival - t_ns)
            out.append(Transfer(HostId(dst), _STATUS[fate], arrival))
        return out


class NetworkView:
    """Who can hear whom, now: the topology minus range and active partitions.

    Args:
        adapter: the network adapter (holds topology, positions, partitions).
    """

    def __init__(self, adapter: NetworkAdapter) -> None:
        self._adapter = adapter

    def up_links(self, t_ns: int) -> Edges:
        """Every undirected link that is up at ``t_ns`` (sorted host pairs)."""
        return self._adapter.links_at(t_ns)

    def neighbors(self, host: str, t_ns: int) -> list[str]:
        """Hosts that ``host`` has a link to at ``t_ns``, sorted."""
        up = self._adapter.links_at(t_ns)
        return sorted(b if a == host else a for a, b in up if host in (a, b))

    def robot_graph(self) -> tuple[list[str], Edges]:
        """The robots and the topology edges among them (no range, no partitions)."""
        return list(self._adapter.robots), self._adapter.topology


class NetworkAdapter:
    """Builds the network model, installs it on the bus and records links."""

    name: ClassVar[str] = "network"
    requires: ClassVar[tuple[str, ...]] = ("world", "fleet")
    tables: ClassVar[tuple[TableSpec, ...]] = (LINKS,)
    """The tables it writes (documented in the table reference)."""

    def __init__(self, run: RunContext) -> None:
        cfg = run.settings(NetworkConfig)
        self.fleet = run.service(FleetState)
        self.robots = list(self.fleet.names)
        self._index = {name: i for i, name in enumerate(self.robots)}
        self.source = run.scenario.source
        self.partitions: list[Partition] = partitions_of(cfg)
        self.model = build_model(cfg, run, self.partitions)
        self.topology = build_topology(cfg, self.robots, run)
        self.range_m = cfg.range_m if cfg.range_m > 0 else None
        self.link = NetworkLink(self.model, self._distance_m)
        run.bus.link = self.link
        self.table = run.recorder.table(LINKS)
        self.update_ns = period_ns(cfg.topology_update_hz)
        self._state: Edges = frozenset()
        self.changes = 0
        run.provide(NetworkView(self))
        run.check_when_assembled(lambda: self._check_partition_hosts(run))

    def _distance_m(self, a: str, b: str) -> float | None:
        i = self._index.get(a)
        j = self._index.get(b)
        if i is None or j is None:
            return None
        fleet = self.fleet
        return float(np.hypot(fleet.x[i] - fleet.x[j], fleet.y[i] - fleet.y[j]))

    def _infrastructure(self, run: RunContext) -> list[str]:
        return [h for h, host in run.hosts.items() if host.kind is not HostKind.ROBOT]

    def _check_partition_hosts(self, run: RunContext) -> None:
        known = set(run.hosts)
        for i, partition in enumerate(self.partitions):
            for host in sorted(partition.hosts | {h for pair in partition.links for h in pair}):
                if host not in known:
                    raise ConfigError(
                        f"{self.source}: [network.partitions[{i}]] names host {host!r}: "
                        f"expected one of {', '.join(sorted(known))}"
                    )

    def start(self, run: RunContext) -> None:
        """Set the topology and record the links now and whenever they change."""
        self.infrastructure = self._infrastructure(run)
        # every pair of robots linked: the topology's edges are pairs of distinct robots,
        # so n (n - 1) / 2 of them are all pairs (no 500,000-edge set built to compare)
        robots, n = set(self.robots), len(self.robots)
        every_pair = len(self.topology) == n * (n - 1) // 2 and all(
            a in robots and b in robots and a < b for a, b in self.topology
        )
        if every_pair:
            self.model.set_edges(None)
        else:
            infra = frozenset(edge(h, r) for h in self.infrastructure for r in self.robots)
            self.model.set_edges(self.topology | infra)
        now = run.kernel.now_ns
        self._update(now)
        if self.range_m is not None:
            run.kernel.every(self.update_ns, self._update, stage=Stage.PHYSICS)
        for partition in self.partitions:  # links change exactly at the boundaries
            for t_ns in (partition.from_ns, partition.to_ns):
                if t_ns > now:
                    run.kernel.at(t_ns, functools.partial(self._update, t_ns), Stage.PHYSICS)

    def links_at(self, t_ns: int) -> Edges:
        """Undirected links up at ``t_ns``: topology within range, infrastructure, no cut."""
        robots = self.robots
        up = set(self.topology)
        if self.range_m is not None:
            up = {(a, b) for a, b in up if (self._distance_m(a, b) or 0.0) <= self.range_m}
        up |= {edge(h, r) for h in self.infrastructure for r in robots}
        active = [p for p in self.partitions if p.active(t_ns)]
        if active:
            up = {(a, b) for a, b in up if not any(p.separates(a, b) for p in active)}
        return frozenset(up)

    def _update(self, now_ns: int) -> None:
        state = self.links_at(now_ns)
        went_up = sorted(state - self._state)
        went_down = sorted(self._state - state)
        self._state = state
        if not went_up and not went_down:
            return
        pairs = went_up + went_down
        self.table.extend(
            t_s=now_ns / NS_PER_S,
            a=[a for a, _ in pairs],
            b=[b for _, b in pairs],
            up=[True] * len(went_up) + [False] * len(went_down),
        )
        self.changes += len(pairs)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Latency percentiles (ms) of delivered inter-host messages, and link changes."""
        latencies = np.frombuffer(self.link.latencies_ns, dtype=np.int64) / 1e6
        summary: dict[str, Any] = {
            "link_changes": self.changes,
            # the long-run loss of each link's loss process as configured (not measured)
            "loss_rate_configured": round(self.model.params.loss_factory().stationary_loss(), 6),
        }
        for q in (50, 95, 99):
            # null (not NaN, which is not JSON) when nothing crossed the network
            value = round(float(np.percentile(latencies, q)), 6) if len(latencies) else None
            summary[f"latency_ms_p{q}"] = value
        return summary
