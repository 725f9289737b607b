"""What a map sharing mode is: a class registered in ``cosim.map_sharing``.

``mapping.share`` names one: what robots send their neighbours of what they map, over
the network model like any message (``none``, ``scans``, ``maps``, or a plugin's). The
mapping adapter builds it once per run with a :class:`SharingContext` (when it may
advertise its topics), starts it with the run (when it subscribes every robot's host and
schedules what it sends), and tells it of every scan a robot maps (:meth:`MapSharing.mapped`).
A mode declares, as class attributes:

- ``tracks_changes``: the robots' maps keep the log-odds their own scans added since the
  mode last took them (:meth:`models.mapping.grid.LogOddsMap.take_changes`);
- ``problems(mapping)`` (optional): a class method yielding
  :class:`~cosim.scenario.fields.Problem` for ``[mapping]`` values it cannot run with.

Poses are in ``map`` (m, rad); times are kernel time (ns).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar, Protocol

from adapters.mapping.settings import MappingConfig
from adapters.mapping.tables import MappingRecords
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.messages import LaserScan
from cosim.core.registry import Group
from models.mapping.grid import LogOddsMap, MapGeometry
from models.mapping.slam import MapperParams


@dataclass(frozen=True)
class SharingContext:
    """What a sharing mode knows of the run's mapping when it is built.

    Attributes:
        run: the run.
        mapping: the ``[mapping]`` section.
        names: the robots, in fleet order.
        hosts: each robot's host (where it sends from and receives).
        maps: each robot's map (its own scans and what it took from others).
        geometry: the grid every map shares.
        params: the mapping parameters (``clear_no_return_m`` for scans taken in).
        records: the mapping tables (``records.shared`` when sending,
            ``records.merge`` when taking a neighbour's evidence in).
    """

    run: RunContext
    mapping: MappingConfig
    names: list[str]
    hosts: list[HostId]
    maps: list[LogOddsMap]
    geometry: MapGeometry
    params: MapperParams
    records: MappingRecords


class MapSharing(Protocol):
    """What a ``cosim.map_sharing`` entry point names: a class built once per run."""

    name: ClassVar[str]
    tracks_changes: ClassVar[bool]

    def __init__(self, context: SharingContext) -> None: ...

    def start(self, run: RunContext) -> None:
        """Subscribe the robots' hosts and schedule what is sent periodically."""
        ...

    def mapped(
        self, run: RunContext, robot: int, pose: tuple[float, float, float], scan: LaserScan
    ) -> None:
        """Robot ``robot`` has just mapped ``scan`` at its estimated ``pose`` (m, rad)."""
        ...


def _sharing_contract(name: str, loaded: Any) -> str | None:
    if not isinstance(loaded, type):
        return "is not a class (built with a SharingContext)"
    if not isinstance(getattr(loaded, "tracks_changes", None), bool):
        return "tracks_changes is not True or False"
    for method in ("start", "mapped"):
        if not callable(getattr(loaded, method, None)):
            return f"has no {method}() method (see adapters.mapping.contract.MapSharing)"
    return None


MAP_SHARING = Group(
    "cosim.map_sharing",
    "map sharing mode",
    "map sharing modes",
    "`adapters.mapping.contract` (`MapSharing`, `SharingContext`)",
    "`mapping.share`",
    check=_sharing_contract,
)
"""Map sharing modes (``mapping.share``)."""
