"""The built-in network backend ``links``: every link modelled by itself.

It builds :class:`models.network.model.NetworkModel` from ``[network]``: the latency,
loss model and topology chosen there (registered in ``cosim.latency_models``,
``cosim.loss_models`` and ``cosim.topologies``), bandwidth and interface queues, range or
path loss, and scheduled partitions. It feeds the model the robots' ground-truth positions
for range and path loss and records link changes (topology, range, partitions) in
``tables/links``. Robots talk to each other along the topology; the base station (and any
host without a position) reaches every robot, subject to latency, loss, bandwidth and
partitions.
"""

from __future__ import annotations

import functools
from array import array
from collections.abc import Callable, Mapping, Sequence
from typing import Any, ClassVar, TypeVar

import numpy as np

from adapters.network.contract import (
    LATENCY_MODELS,
    LOSS_MODELS,
    TOPOLOGIES,
    LatencyChoice,
    LossChoice,
    NetworkContext,
    TopologyChoice,
)
from adapters.network.settings import NetworkConfig
from cosim.core.adapter import RunContext
from cosim.core.errors import ConfigError
from cosim.core.hosts import HostId, HostKind
from cosim.core.kernel import Stage
from cosim.core.link import AllDelivered, Transfer
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import NS_PER_S, period_ns, s_to_ns
from cosim.scenario.fields import model_problem
from models.errors import ModelError
from models.fleet.kinematics import FleetState
from models.network.model import LinkParams, NetworkModel, Partition
from models.network.radio import PathLoss
from models.network.shadowing import boxes_crossed
from models.network.topology import Edges, edge
from models.world.warehouse import Warehouse

T = TypeVar("T")

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


def _checked(source: str, make: Callable[[], T]) -> T:
    """Run a model constructor, turning its ModelError into one line naming the file."""
    try:
        return make()
    except ModelError as error:
        raise model_problem(source, error) from None


def partitions_of(cfg: NetworkConfig) -> list[Partition]:
    """The scheduled partitions, in kernel time."""
    return [
        Partition(
            from_ns=s_to_ns(p.from_s),
            to_ns=s_to_ns(p.to_s),
            hosts=frozenset(p.hosts),
            links=frozenset((a, b) for a, b in p.links),
        )
        for p in cfg.partitions
    ]


def build_model(context: NetworkContext, partitions: list[Partition]) -> NetworkModel:
    """The network model of a scenario, with its latency and loss models chosen by name."""
    cfg, run = context.network, context.run
    latency: LatencyChoice = LATENCY_MODELS.installed().get(cfg.latency_model)(context)
    loss: LossChoice = LOSS_MODELS.installed().get(cfg.loss_model)(context)
    path_loss = None
    if cfg.path_loss:
        path_loss = PathLoss(
            tx_power_dbm=cfg.tx_power_dbm,
            ref_loss_db=cfg.ref_loss_db,
            exponent=cfg.path_loss_exponent,
            sensitivity_dbm=cfg.sensitivity_dbm,
            shadowing_db=cfg.shadowing_db,
            wall_loss_db=cfg.wall_loss_db,
        )
    params = LinkParams(
        latency=latency.model(),
        loss_factory=loss.factory(),
        reorder=cfg.reorder,
        path_loss=path_loss,
        range_m=cfg.range_m if cfg.range_m > 0 else None,
    )
    bandwidth = cfg.bandwidth_mbps * 1e6 if cfg.bandwidth_mbps > 0 else None
    return NetworkModel(
        params,
        streams=run.rng.stream,
        bandwidth_bps=bandwidth,
        queue_packets=cfg.queue_packets,
        partitions=partitions,
        airtime_bps=cfg.airtime_mbps * 1e6 if cfg.airtime_mbps > 0 else None,
    )


class ModelLink:
    """A :class:`cosim.core.link.Link` deciding by a network model, latencies kept.

    Args:
        model: the network model.
        distance_m: the distance between two hosts (m), None for a host without a place.

    Attributes:
        latencies_ns: the latency of every delivered copy (ns), in delivery decision order.
    """

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
        for dst, status, arrival in outcome:
            if arrival is not None:
                latencies.append(arrival - t_ns)
            out.append(Transfer(HostId(dst), status, arrival))
        return out


class LinksBackend(ModelLink):
    """Per-link latency, loss, bandwidth and queues, range and partitions (see the module)."""

    name: ClassVar[str] = "links"
    tables: ClassVar[tuple[TableSpec, ...]] = (LINKS,)
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "link_changes": SummaryKey(
            "count",
            "links between two hosts that came up (those of the start included) or went "
            "down: the rows of tables/links",
        ),
        "loss_rate_configured": SummaryKey(
            "fraction",
            "the long-run loss rate of each link's loss model as configured (not measured)",
        ),
        **{
            f"latency_ms_p{q}": SummaryKey(
                "ms",
                f"{said} one-way latency of the messages delivered between two hosts "
                "(null: none crossed the network)",
            )
            for q, said in ((50, "median"), (95, "95th percentile"), (99, "99th percentile"))
        },
    }
    """The summary keys :meth:`finish` writes (documented in the summary reference)."""
    keys: ClassVar[tuple[str, ...]] = (
        "topology", "edge_prob", "edges", "latency_model", "latency_ms", "jitter_ms",
        "latency_csv", "reorder", "loss_model", "loss_prob", "ge_p", "ge_r", "ge_loss_bad",
        "ge_loss_good", "bandwidth_mbps", "queue_packets", "range_m", "path_loss",
        "path_loss_exponent", "tx_power_dbm", "ref_loss_db", "sensitivity_dbm", "shadowing_db",
        "wall_loss_db", "airtime_mbps",
        "topology_update_hz", "partitions",
    )  # fmt: skip
    """The ``[network]`` keys only this backend reads (another backend leaves them unset)."""

    def __init__(self, context: NetworkContext) -> None:
        run, cfg = context.run, context.network
        self.fleet = run.service(FleetState)
        self.robots = list(context.robots)
        self._index = {name: i for i, name in enumerate(self.robots)}
        self.source = run.scenario.source
        self.partitions: list[Partition] = partitions_of(cfg)
        model = _checked(self.source, lambda: build_model(context, self.partitions))
        super().__init__(model, self._distance_m)
        if cfg.path_loss and cfg.wall_loss_db > 0:
            self.boxes = np.asarray(run.service(Warehouse).inner_boxes, dtype=float).reshape(-1, 4)
            self.kernel = run.kernel
            self._walls = np.zeros((len(self.robots), len(self.robots)), dtype=np.int64)
            self._walls_ns = -1
            model.walls_between = self._walls_between
        choice: TopologyChoice = TOPOLOGIES.installed().get(cfg.topology)(context)
        self.topology = _checked(self.source, choice.edges)
        self.range_m = cfg.range_m if cfg.range_m > 0 else None
        self.table = run.recorder.table(LINKS)
        self.update_ns = period_ns(cfg.topology_update_hz)
        self._state: Edges = frozenset()
        self.changes = 0
        run.check_when_assembled(lambda: self._check_partition_hosts(run))

    def _distance_m(self, a: str, b: str) -> float | None:
        i = self._index.get(a)
        j = self._index.get(b)
        if i is None or j is None:
            return None
        fleet = self.fleet
        return float(np.hypot(fleet.x[i] - fleet.x[j], fleet.y[i] - fleet.y[j]))

    def _walls_between(self, a: str, b: str) -> int:
        """Walls, shelves and obstacles the straight line between two robots meets.

        Counted for every pair at once, in one call, the first time it is asked in an
        instant (robots move between instants, not within one).
        """
        i, j = self._index.get(a), self._index.get(b)
        if i is None or j is None:
            return 0
        now = self.kernel.now_ns
        if now != self._walls_ns:
            fleet = self.fleet
            xy = np.column_stack([fleet.x, fleet.y])
            p, q = np.triu_indices(len(xy), 1)
            crossed = boxes_crossed(xy[p], xy[q], self.boxes)
            self._walls[p, q] = crossed
            self._walls[q, p] = crossed
            self._walls_ns = now
        return int(self._walls[i, j])

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
        self.infrastructure = [
            h for h, host in run.hosts.items() if host.kind is not HostKind.ROBOT
        ]
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

    def robot_graph(self) -> tuple[list[str], Edges]:
        """The robots and the topology's edges (no range, no partitions)."""
        return list(self.robots), self.topology

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
        latencies = np.frombuffer(self.latencies_ns, dtype=np.int64) / 1e6
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
