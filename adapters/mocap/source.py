"""The motion-capture adapter: poses of the tracked robots from ``mocap.source``.

``mocap.source`` names a registered pose source (:mod:`adapters.mocap.contract`):
``simulated`` (:mod:`adapters.mocap.simulated`), ``bag`` (:mod:`adapters.mocap.replay`),
``motioncapture`` (:mod:`adapters.mocap.motioncapture`), ``ros2``
(:mod:`adapters.mocap.ros2`), ``unity`` (:mod:`adapters.unity.pose_source`), or a plugin's.
The robots an external source tracks are twins that follow its poses; those a simulated
one tracks drive by their commands. A live source never makes the run wait: one that
fails ends the run at once, and one that has sent no pose of some tracked robot
``mocap.connect_timeout_s`` after the start ends it then, or at the run's end when
that comes sooner (:class:`~adapters.mocap.live.LiveSourceError`, one line naming the
system, its host, the robot and what was listened for; an event ``no_pose`` or
``mocap_failed``).

Every pose goes through :class:`adapters.mocap.intake.PoseIntake` and is published on
``/<robot>/pose`` from the ``mocap`` host, so it crosses the network model to the robot.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from adapters.mocap.contract import PoseSource, SourceContext
from adapters.mocap.intake import PoseIntake
from adapters.mocap.settings import NO_SOURCE, MocapConfig
from adapters.mocap.tables import MOCAP, MOCAP_SUMMARY, MocapRecords
from adapters.mocap.tracking import tracked_bodies
from cosim.core.adapter import RunContext
from cosim.core.errors import ConfigError
from cosim.core.hosts import HostKind
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from models.fleet.kinematics import FleetState

MOCAP_HOST = "mocap"


class MocapAdapter:
    """Publishes the tracked robots' measured poses (see the module docstring)."""

    name: ClassVar[str] = "mocap"
    requires: ClassVar[tuple[str, ...]] = ("fleet",)
    tables: ClassVar[tuple[TableSpec, ...]] = (MOCAP,)
    """The tables it writes (documented in the table reference)."""
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = MOCAP_SUMMARY
    """The summary keys :meth:`finish` writes; the source's own are declared by the source
    class (documented in the summary reference)."""

    def __init__(self, run: RunContext) -> None:
        self.cfg = cfg = run.settings(MocapConfig)
        if cfg.source == NO_SOURCE:
            raise ConfigError(
                f"{run.scenario.source}: [scenario] adapters names 'mocap': expected "
                f"mocap.source other than {NO_SOURCE!r}"
            )
        fleet = run.service(FleetState)
        self.host = run.add_host(MOCAP_HOST, HostKind.MOCAP)
        kind = cfg.chosen()
        self.intake = PoseIntake(run, self.host, source=kind)
        self.records = MocapRecords.of(run)
        index = self.intake.index
        tracked = [
            (index[robot], body) for robot, body in tracked_bodies(run.scenario, fleet.names)
        ]
        if kind.external:
            for robot, _ in tracked:
                self.intake.mirrors.add(robot)
        context = SourceContext(run, cfg, self.intake, self.records, self.host, tracked)
        self.source: PoseSource = kind(context)
        for robot, _ in tracked:
            self.intake.advertise(robot)

    def start(self, run: RunContext) -> None:
        """Start the source: sampling, the replay, or taking in live poses."""
        self.source.start(run)

    def close(self) -> None:
        """Disconnect a live source (its counts are kept for the summary)."""
        self.source.close()

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """``mocap_*`` counts (and the source's)."""
        self.close()
        return {**self.records.summary(), **self.source.summary()}
