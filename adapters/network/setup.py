"""From the ``[network]`` section to the pure network model (and its errors to the user's)."""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

from adapters.network.settings import NetworkConfig
from cosim.core.adapter import RunContext
from cosim.core.timebase import s_to_ns
from cosim.scenario.fields import model_problem
from models.errors import ModelError
from models.network.latency import (
    ConstantLatency,
    EmpiricalLatency,
    LatencyModel,
    LognormalLatency,
    NormalLatency,
)
from models.network.loss import BernoulliLoss, GilbertElliottLoss, LossProcess, NoLoss
from models.network.model import LinkParams, NetworkModel, Partition
from models.network.radio import PathLoss
from models.network.topology import (
    Edges,
    binomial_connected,
    complete,
    explicit,
    ring,
)

T = TypeVar("T")


def _checked(source: str, make: Callable[[], T]) -> T:
    """Run a model constructor, turning its ModelError into one line naming the file."""
    try:
        return make()
    except ModelError as error:
        raise model_problem(source, error) from None


def _latency(cfg: NetworkConfig) -> LatencyModel:
    if cfg.latency_model == "normal":
        return NormalLatency(cfg.latency_ms, cfg.jitter_ms)
    if cfg.latency_model == "lognormal":
        return LognormalLatency(cfg.latency_ms, cfg.jitter_ms)
    if cfg.latency_model == "empirical":
        return EmpiricalLatency.from_csv(cfg.latency_csv)
    return ConstantLatency(cfg.latency_ms)


def _loss_factory(cfg: NetworkConfig) -> Callable[[], LossProcess]:
    if cfg.loss_model == "bernoulli":
        BernoulliLoss(cfg.loss_prob)  # validate once, now
        return lambda: BernoulliLoss(cfg.loss_prob)
    if cfg.loss_model == "gilbert_elliott":

        def gilbert_elliott() -> LossProcess:
            return GilbertElliottLoss(
                cfg.ge_p, cfg.ge_r, loss_good=cfg.ge_loss_good, loss_bad=cfg.ge_loss_bad
            )

        gilbert_elliott()
        return gilbert_elliott
    return NoLoss


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


def build_model(cfg: NetworkConfig, run: RunContext, partitions: list[Partition]) -> NetworkModel:
    """The network model of a scenario.

    Raises:
        ConfigError: naming the scenario file, the key and the value, for a malformed
            delay CSV or parameters the models refuse.
    """
    source = run.scenario.source

    def make() -> NetworkModel:
        path_loss = None
        if cfg.path_loss:
            path_loss = PathLoss(
                tx_power_dbm=cfg.tx_power_dbm,
                ref_loss_db=cfg.ref_loss_db,
                exponent=cfg.path_loss_exponent,
                sensitivity_dbm=cfg.sensitivity_dbm,
                shadowing_db=cfg.shadowing_db,
            )
        params = LinkParams(
            latency=_latency(cfg),
            loss_factory=_loss_factory(cfg),
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
        )

    return _checked(source, make)


def build_topology(cfg: NetworkConfig, robots: list[str], run: RunContext) -> Edges:
    """The robot-to-robot topology (range is applied on top, per message).

    Raises:
        ConfigError: for an explicit edge naming an unknown robot, or a binomial graph
            that stays disconnected.
    """
    source = run.scenario.source
    if cfg.topology == "ring":
        return ring(robots)
    if cfg.topology == "binomial":
        rng = run.rng.stream("network/topology")
        return _checked(source, lambda: binomial_connected(robots, cfg.edge_prob, rng))
    if cfg.topology == "explicit":
        return _checked(source, lambda: explicit(robots, cfg.edges))
    return complete(robots)
