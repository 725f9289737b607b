"""What the network's pluggable parts are: backends, latency and loss models, topologies.

Each is a class registered by name in its entry-point group and chosen in ``[network]``:

- a **network backend** (``cosim.network_backends``, ``network.backend``) decides if and
  when a message between two hosts arrives: it is the bus's
  :class:`~cosim.core.link.Link`, and says which hosts can hear each other. The built-in
  ``links`` backend models every link by itself (latency, loss, bandwidth and queues,
  range, partitions); a radio simulator can be plugged in in its place;
- a **latency model** (``cosim.latency_models``, ``network.latency_model``), a **loss
  model** (``cosim.loss_models``, ``network.loss_model``) and a **topology**
  (``cosim.topologies``, ``network.topology``) are the choices of the ``links`` backend:
  the one-way delay distribution of every link, the loss process of every directed link,
  and which robots may talk directly.

Every class is built once per run with a :class:`NetworkContext`; it reads its settings
by section type (``context.run.settings(MySettings)``: a plugin's own section, or
``context.network`` for the keys of ``[network]``). A class may declare:

- ``keys``: the ``[network]`` keys only it reads; set to another value than their default
  while another entry is chosen, they are refused (they would do nothing);
- ``problems(network)``: a class method yielding :class:`~cosim.scenario.fields.Problem`
  for ``[network]`` values it cannot run with, found when the scenario is loaded.

Hosts are named by strings (robots ``robot_i``, the base station ``base``); times are
integer nanoseconds of kernel time.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol

from adapters.network.settings import NetworkConfig
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.link import AllDelivered, Later, Transfer
from cosim.core.registry import Group
from cosim.core.table import TableSpec
from models.network.latency import LatencyModel
from models.network.loss import LossProcess
from models.network.topology import Edges


@dataclass(frozen=True)
class NetworkContext:
    """What a network backend, latency model, loss model or topology knows when it is built.

    Attributes:
        run: the run (settings by section type, named random streams, services).
        network: the ``[network]`` section.
        robots: the robots' names, in fleet order (hosts of their own name).
    """

    run: RunContext
    network: NetworkConfig
    robots: list[str]


def _is_class(name: str, loaded: Any) -> str | None:
    return None if isinstance(loaded, type) else "is not a class (built with a NetworkContext)"


# -- backends --------------------------------------------------------------------------------
class NetworkBackend(Protocol):
    """What a ``cosim.network_backends`` entry point names: a class built once per run.

    It is installed as the bus's :class:`~cosim.core.link.Link`: every message from one
    host to others goes through :meth:`transmit`.

    Attributes:
        name: the registered name (``network.backend``).
        tables: the tables it writes (for the table reference).

    It declares the keys its :meth:`finish` returns in a ``summary_keys`` class attribute
    (key -> :class:`cosim.core.summary.SummaryKey`), for the summary reference.
    """

    name: ClassVar[str]
    tables: ClassVar[tuple[TableSpec, ...]]

    def __init__(self, context: NetworkContext) -> None: ...

    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> Sequence[Transfer] | AllDelivered | Later:
        """The fate of one transmission towards every destination host (see ``Link``)."""
        ...

    def start(self, run: RunContext) -> None:
        """Start at time 0, once every adapter is built (every host exists)."""
        ...

    def links_at(self, t_ns: int) -> Edges:
        """Every undirected pair of hosts that can reach each other at ``t_ns``."""
        ...

    def robot_graph(self) -> tuple[list[str], Edges]:
        """The robots and the pairs of them that may talk directly (the topology)."""
        ...

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Summary metrics (flat, JSON-serializable) at the end of the run."""
        ...


def _backend_contract(name: str, loaded: Any) -> str | None:
    if not isinstance(loaded, type):
        return "is not a class (built with a NetworkContext)"
    for method in ("transmit", "start", "links_at", "robot_graph", "finish"):
        if not callable(getattr(loaded, method, None)):
            return f"has no {method}() method (see adapters.network.contract.NetworkBackend)"
    return None


NETWORK_BACKENDS = Group(
    "cosim.network_backends",
    "network backend",
    "network backends",
    "`adapters.network.contract` (`NetworkBackend`)",
    "`network.backend`",
    check=_backend_contract,
)
"""Network backends (``network.backend``): what decides if and when messages arrive."""


class RadioView:
    """What each host's radio last measured of each sender (a service of a radio backend).

    A backend that simulates radios (``ns3``) offers it to the run: a protocol may read the
    signal a host received a sender's last message with, as a robot's driver reports it,
    and weigh links by it. Values change when a copy is delivered, not before.
    """

    def __init__(self) -> None:
        self._last: dict[tuple[str, str], tuple[int, float, float]] = {}

    def heard(self, host: str, sender: str, t_ns: int, rssi_dbm: float, snr_db: float) -> None:
        """``host`` received a message of ``sender`` at ``t_ns`` with this signal and SNR."""
        self._last[(host, sender)] = (t_ns, rssi_dbm, snr_db)

    def rssi_dbm(self, host: str, sender: str) -> float | None:
        """The signal (dBm) ``host`` last received ``sender`` with; None: never heard it."""
        last = self._last.get((host, sender))
        return None if last is None else last[1]

    def last(self, host: str, sender: str) -> tuple[int, float, float] | None:
        """When (ns), with what signal (dBm) and SNR (dB) ``host`` last heard ``sender``."""
        return self._last.get((host, sender))


class NetworkView:
    """Who can hear whom, now, as the run's backend says (a service of the run).

    Args:
        backend: the run's network backend.
    """

    def __init__(self, backend: NetworkBackend) -> None:
        self._backend = backend

    def up_links(self, t_ns: int) -> Edges:
        """Every undirected link that is up at ``t_ns`` (sorted host pairs)."""
        return self._backend.links_at(t_ns)

    def neighbors(self, host: str, t_ns: int) -> list[str]:
        """Hosts that ``host`` has a link to at ``t_ns``, sorted."""
        up = self._backend.links_at(t_ns)
        return sorted(b if a == host else a for a, b in up if host in (a, b))

    def robot_graph(self) -> tuple[list[str], Edges]:
        """The robots and the topology edges among them (no range, no partitions)."""
        return self._backend.robot_graph()


# -- the links backend's choices -------------------------------------------------------------
class LatencyChoice(Protocol):
    """What a ``cosim.latency_models`` entry point names: a class built once per run.

    Attributes:
        name: the registered name (``network.latency_model``).
    """

    name: ClassVar[str]

    def __init__(self, context: NetworkContext) -> None: ...

    def model(self) -> LatencyModel:
        """The one-way latency distribution every link draws from."""
        ...


LATENCY_MODELS = Group(
    "cosim.latency_models",
    "latency model",
    "latency models",
    "`adapters.network.contract` (`LatencyChoice`, `models.network.latency.LatencyModel`)",
    "`network.latency_model`",
    check=_is_class,
)
"""Latency models of the ``links`` backend (``network.latency_model``)."""


class LossChoice(Protocol):
    """What a ``cosim.loss_models`` entry point names: a class built once per run.

    Attributes:
        name: the registered name (``network.loss_model``).
    """

    name: ClassVar[str]

    def __init__(self, context: NetworkContext) -> None: ...

    def factory(self) -> Callable[[], LossProcess]:
        """What makes one independent loss process per directed link (called per link)."""
        ...


LOSS_MODELS = Group(
    "cosim.loss_models",
    "loss model",
    "loss models",
    "`adapters.network.contract` (`LossChoice`, `models.network.loss.LossProcess`)",
    "`network.loss_model`",
    check=_is_class,
)
"""Loss models of the ``links`` backend (``network.loss_model``)."""


class TopologyChoice(Protocol):
    """What a ``cosim.topologies`` entry point names: a class built once per run.

    Attributes:
        name: the registered name (``network.topology``).
    """

    name: ClassVar[str]

    def __init__(self, context: NetworkContext) -> None: ...

    def edges(self) -> Edges:
        """The pairs of robots that may talk directly (range and partitions apply on top)."""
        ...


TOPOLOGIES = Group(
    "cosim.topologies",
    "network topology",
    "network topologies",
    "`adapters.network.contract` (`TopologyChoice`)",
    "`network.topology`",
    check=_is_class,
)
"""Topologies of the ``links`` backend (``network.topology``)."""
