"""What a motion-capture pose source is: a class registered in ``cosim.mocap_sources``.

``mocap.source`` names one (``"none"``, the default, runs no source). The mocap adapter
builds it once per run with a :class:`SourceContext` and starts it with the run; the
source hands every pose it measures or receives to the pose intake
(``context.intake.submit``), which checks it and publishes it on ``/<robot>/pose`` from
the ``mocap`` host. A source declares, as class attributes:

- ``external``: its poses come from outside the simulation (a recording, a live system):
  the robots it tracks are twins that follow them; otherwise it measures the simulated
  robots (their ground truth);
- ``live``: it sends poses on the wall clock, so the run goes in real time;
- ``uses_dds``: it listens on the run's DDS domain;
- ``keys`` (optional): the ``[mocap]`` keys only it reads (set while another source is
  chosen, they are refused);
- ``problems(mocap)`` (optional): a class method yielding
  :class:`~cosim.scenario.fields.Problem` for ``[mocap]`` values it cannot run with;
- ``tracks(mocap, outside, names)``: which robots it tracks, by what body (a topic, a
  rigid body's name; ``""`` where it needs none);
- ``describe(mocap, body)``: where it listens for a body, for messages.

Poses are in ``map`` (m, rad); stamps are kernel time (ns).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol, runtime_checkable

from adapters.mocap.intake import PoseIntake
from adapters.mocap.settings import MocapConfig
from adapters.mocap.tables import MocapRecords
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.registry import Group
from cosim.scenario.fields import Problem

Tracked = list[tuple[str, str]]
"""(robot name, body) pairs: what tracks each robot."""


@runtime_checkable
class ExternalPoses(Protocol):
    """A settings section whose robots get their poses from outside the simulation.

    The physical robots' section is one: by default an external source tracks each of
    its robots, and robots posed by something else than a mocap source (their own
    odometry) still localize by ``/<robot>/pose``.
    """

    def external_poses(self) -> Mapping[str, str]:
        """Robot name -> where its pose comes from: ``"mocap"``, or another word."""
        ...


def external_poses(sections: Mapping[str, Any]) -> dict[str, str]:
    """Every robot some section says is posed from outside, and by what (see above)."""
    found: dict[str, str] = {}
    for section in sections.values():
        if isinstance(section, ExternalPoses):
            found.update(section.external_poses())
    return found


@dataclass(frozen=True)
class SourceContext:
    """What a pose source knows of the run when it is built.

    Attributes:
        run: the run (settings by section type, random streams, the kernel).
        mocap: the ``[mocap]`` section.
        intake: where every pose goes (checked, then published on ``/<robot>/pose``).
        records: the ``mocap`` table and counters.
        host: the ``mocap`` host the poses are published from.
        tracked: (robot index, body) of every tracked robot, in fleet order of the
            source's :meth:`PoseSource.tracks`.
    """

    run: RunContext
    mocap: MocapConfig
    intake: PoseIntake
    records: MocapRecords
    host: HostId
    tracked: Sequence[tuple[int, str]]


class PoseSource(Protocol):
    """What a ``cosim.mocap_sources`` entry point names: a class built once per run.

    Building it must open nothing (``cosim check`` builds it too); :meth:`start` connects.
    """

    name: ClassVar[str]
    external: ClassVar[bool]
    live: ClassVar[bool]
    uses_dds: ClassVar[bool]

    @classmethod
    def tracks(cls, mocap: MocapConfig, outside: Mapping[str, str], names: list[str]) -> Tracked:
        """(robot, body) of every robot it tracks.

        Args:
            mocap: the ``[mocap]`` section.
            outside: robots posed from outside the simulation (:func:`external_poses`).
            names: the fleet's robots, in order.
        """
        ...

    @classmethod
    def describe(cls, mocap: MocapConfig, body: str) -> str:
        """Where it listens for ``body`` (``rigid body 'jackal' of the vicon motion capture``)."""
        ...

    def __init__(self, context: SourceContext) -> None: ...

    def start(self, run: RunContext) -> None:
        """Start measuring, replaying or taking in poses (connect to a live system)."""
        ...

    def close(self) -> None:
        """Disconnect (called once the run ends, or fails; idempotent)."""
        ...

    def summary(self) -> Mapping[str, Any]:
        """``mocap_*`` counts of its own for the run's summary.

        Each key is declared, with its unit and meaning, in the class's ``summary_keys``
        (a mapping of key to :class:`cosim.core.summary.SummaryKey`).
        """
        ...


def _source_contract(name: str, loaded: Any) -> str | None:
    if not isinstance(loaded, type):
        return "is not a class (built with a SourceContext)"
    for flag in ("external", "live", "uses_dds"):
        if not isinstance(getattr(loaded, flag, None), bool):
            return f"{flag} = {getattr(loaded, flag, None)!r}; expected True or False"
    for method in ("tracks", "describe", "start", "close", "summary"):
        if not callable(getattr(loaded, method, None)):
            return f"has no {method}() method (see adapters.mocap.contract.PoseSource)"
    return None


MOCAP_SOURCES = Group(
    "cosim.mocap_sources",
    "motion capture source",
    "motion capture sources",
    "`adapters.mocap.contract` (`PoseSource`, `SourceContext`)",
    "`mocap.source`",
    check=_source_contract,
)
"""Motion-capture pose sources (``mocap.source``)."""


def all_robots_or(mocap: MocapConfig, names: list[str]) -> Tracked:
    """``mocap.robots`` (or every robot) without bodies: what a simulated system tracks."""
    return [(robot, "") for robot in (mocap.robots or names)]


def bodies_or(mocap: MocapConfig, outside: Mapping[str, str], body_of: Any) -> Tracked:
    """``mocap.bodies``, or each robot posed from outside with the body ``body_of(robot)``."""
    if mocap.bodies:
        return [(robot, body) for robot, body in mocap.bodies]
    return [(robot, body_of(robot)) for robot in outside]


def no_problems(mocap: MocapConfig) -> Iterator[Problem]:
    """Nothing to refuse (for sources without checks of their own)."""
    return iter(())
