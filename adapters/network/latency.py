"""The built-in latency models of the ``links`` backend (``network.latency_model``).

Each reads ``network.latency_ms`` (the mean one-way delay) and, where it has one, a spread
or a file; the distributions themselves are :mod:`models.network.latency`'s.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import ClassVar

from adapters.network.contract import NetworkContext
from adapters.network.settings import NetworkConfig
from cosim.scenario.fields import Problem
from models.network.latency import (
    ConstantLatency,
    EmpiricalLatency,
    LatencyModel,
    LognormalLatency,
    NormalLatency,
)


class Constant:
    """Every message takes exactly network.latency_ms."""

    name: ClassVar[str] = "constant"

    def __init__(self, context: NetworkContext) -> None:
        self._model = ConstantLatency(context.network.latency_ms)

    def model(self) -> LatencyModel:
        """:class:`~models.network.latency.ConstantLatency`."""
        return self._model


class Normal:
    """Normal delays, mean network.latency_ms and deviation jitter_ms, cut at 0."""

    name: ClassVar[str] = "normal"
    keys: ClassVar[tuple[str, ...]] = ("jitter_ms",)

    def __init__(self, context: NetworkContext) -> None:
        self._model = NormalLatency(context.network.latency_ms, context.network.jitter_ms)

    def model(self) -> LatencyModel:
        """:class:`~models.network.latency.NormalLatency`."""
        return self._model


class Lognormal:
    """Lognormal delays (a long tail), mean network.latency_ms and deviation jitter_ms."""

    name: ClassVar[str] = "lognormal"
    keys: ClassVar[tuple[str, ...]] = ("jitter_ms",)

    def __init__(self, context: NetworkContext) -> None:
        self._model = LognormalLatency(context.network.latency_ms, context.network.jitter_ms)

    @classmethod
    def problems(cls, network: NetworkConfig) -> Iterator[Problem]:
        """A lognormal distribution needs a mean above 0."""
        if network.latency_ms <= 0:
            yield Problem(
                "latency_ms", network.latency_ms, "a value > 0 with latency_model 'lognormal'"
            )

    def model(self) -> LatencyModel:
        """:class:`~models.network.latency.LognormalLatency`."""
        return self._model


class Empirical:
    """Delays drawn from measured ones: the one-way delays (ms) of network.latency_csv."""

    name: ClassVar[str] = "empirical"
    keys: ClassVar[tuple[str, ...]] = ("latency_csv",)

    def __init__(self, context: NetworkContext) -> None:
        self._model = EmpiricalLatency.from_csv(context.network.latency_csv)

    @classmethod
    def problems(cls, network: NetworkConfig) -> Iterator[Problem]:
        """The measured delays must be given."""
        if not network.latency_csv:
            yield Problem(
                "latency_csv",
                network.latency_csv,
                "a CSV file of delays (ms) with latency_model 'empirical'",
            )

    def model(self) -> LatencyModel:
        """:class:`~models.network.latency.EmpiricalLatency` of the file's samples."""
        return self._model
