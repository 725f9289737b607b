"""A network backend: a wired switch, every copy delivered after a delay drawn per link.

Every host reaches every other; each copy arrives ``wired.min_ms`` to ``wired.max_ms``
after it was sent (uniform, from the link's own random stream), never lost, never out of
order on a link. It replaces the built-in ``links`` backend with ``network.backend =
"wired"``: a network model of one's own is one class like this one.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from adapters.network.contract import NetworkContext
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.link import DELIVERED, AllDelivered, Transfer
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import ms_to_ns
from cosim.scenario.fields import Problem, param
from models.network.topology import Edges, complete


@dataclass(frozen=True)
class WiredSettings:
    """``[wired]``: the backend ``network.backend = "wired"``."""

    min_ms: float = param(0.2, "shortest one-way delay of a copy (ms)", ge=0)
    max_ms: float = param(1.0, "longest one-way delay of a copy (ms)", ge=0)

    def problems(self) -> Any:
        """The delays must make an interval."""
        if self.max_ms < self.min_ms:
            yield Problem("max_ms", self.max_ms, f"a delay >= min_ms ({self.min_ms:g} ms)")


class WiredBackend:
    """Every host on one switch: no loss, a uniform delay per copy (``[wired]``)."""

    name: ClassVar[str] = "wired"
    tables: ClassVar[tuple[TableSpec, ...]] = ()
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "wired_copies": SummaryKey("count", "message copies that crossed the switch"),
    }

    def __init__(self, context: NetworkContext) -> None:
        settings = context.run.settings(WiredSettings)
        self.low_ns, self.high_ns = ms_to_ns(settings.min_ms), ms_to_ns(settings.max_ms)
        self.streams = context.run.rng.stream
        self.rng: dict[tuple[str, str], np.random.Generator] = {}
        self.last: dict[tuple[str, str], int] = {}
        self.robots = list(context.robots)
        self.hosts: list[str] = []
        self.copies = 0

    def transmit(
        self, t_ns: int, src: HostId, dsts: Sequence[HostId], nbytes: int, topic: str
    ) -> Sequence[Transfer] | AllDelivered:
        """Each copy after its link's next delay, never before the link's previous one."""
        out = []
        for dst in dsts:
            link = (src, dst)
            rng = self.rng.get(link)
            if rng is None:
                rng = self.rng[link] = self.streams(f"wired/{src}->{dst}")
            arrival = t_ns + int(rng.integers(self.low_ns, self.high_ns + 1))
            arrival = max(arrival, self.last.get(link, 0))  # a cable keeps the order
            self.last[link] = arrival
            out.append(Transfer(dst, DELIVERED, arrival))
        self.copies += len(dsts)
        return out

    def start(self, run: RunContext) -> None:
        """Every host is on the switch."""
        self.hosts = sorted(run.hosts)

    def links_at(self, t_ns: int) -> Edges:
        """Every pair of hosts."""
        return complete(self.hosts)

    def robot_graph(self) -> tuple[list[str], Edges]:
        """Every robot reaches every other."""
        return list(self.robots), complete(self.robots)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """How many copies crossed the switch."""
        return {"wired_copies": self.copies}
