"""The built-in topologies of the ``links`` backend (``network.topology``).

A topology says which robots may talk directly; the base station (and every host that is
not a robot) reaches every robot, and range and partitions apply on top, per message.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import ClassVar

from adapters.network.contract import NetworkContext
from adapters.network.settings import NetworkConfig
from cosim.scenario.fields import Problem
from models.network.topology import Edges, binomial_connected, complete, explicit, ring


class Complete:
    """Every robot may talk to every other."""

    name: ClassVar[str] = "complete"

    def __init__(self, context: NetworkContext) -> None:
        self._edges = complete(context.robots)

    def edges(self) -> Edges:
        """Every pair of robots."""
        return self._edges


class InRange:
    """Every robot may talk to every other within network.range_m (checked per message)."""

    name: ClassVar[str] = "range"

    def __init__(self, context: NetworkContext) -> None:
        self._edges = complete(context.robots)

    @classmethod
    def problems(cls, network: NetworkConfig) -> Iterator[Problem]:
        """A range topology needs a range."""
        if network.range_m <= 0:
            yield Problem("range_m", network.range_m, "a range > 0 with topology 'range'")

    def edges(self) -> Edges:
        """Every pair of robots (the range cuts links as they move)."""
        return self._edges


class Binomial:
    """A random connected graph, each pair linked with network.edge_prob (ChoiRbot's default)."""

    name: ClassVar[str] = "binomial"

    def __init__(self, context: NetworkContext) -> None:
        rng = context.run.rng.stream("network/topology")
        self._edges = binomial_connected(context.robots, context.network.edge_prob, rng)

    def edges(self) -> Edges:
        """The graph drawn for the run."""
        return self._edges


class Ring:
    """Each robot talks to the robots before and after it, in fleet order."""

    name: ClassVar[str] = "ring"

    def __init__(self, context: NetworkContext) -> None:
        self._edges = ring(context.robots)

    def edges(self) -> Edges:
        """The ring's pairs."""
        return self._edges


class Explicit:
    """The pairs network.edges lists."""

    name: ClassVar[str] = "explicit"
    keys: ClassVar[tuple[str, ...]] = ("edges",)

    def __init__(self, context: NetworkContext) -> None:
        self._edges = explicit(context.robots, context.network.edges)

    @classmethod
    def problems(cls, network: NetworkConfig) -> Iterator[Problem]:
        """An explicit topology needs edges."""
        if not network.edges:
            yield Problem("edges", [], "at least one [a, b] pair with topology 'explicit'")

    def edges(self) -> Edges:
        """The listed pairs."""
        return self._edges
