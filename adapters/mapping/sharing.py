"""The built-in map sharing modes (``mapping.share``): nothing, localized scans, map updates.

``scans`` sends every mapped scan with its estimated pose on ``/fleet/mapping/scans`` and
a neighbour adds it to its map at that pose (as slam_toolbox's multi-robot mode); ``maps``
sends, every ``mapping.share_period_s``, the log-odds the robot's own scans added since
its last update, compressed (:mod:`models.mapping.exchange`), on
``/fleet/mapping/updates``. Robots start with known poses in the common ``map`` frame. A
lost message is not sent again: its evidence is lost, as with slam_toolbox.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import ClassVar

import numpy as np

from adapters.mapping.contract import SharingContext
from adapters.mapping.settings import MappingConfig
from adapters.mapping.topics import SCANS, UPDATES
from cosim.core.adapter import RunContext
from cosim.core.bus import Envelope, TopicQos
from cosim.core.kernel import Stage
from cosim.core.messages import LaserScan, LocalizedScan, MapUpdate, Message
from cosim.core.timebase import period_ns
from cosim.scenario.fields import Problem
from models.errors import ModelError
from models.mapping.exchange import PackedUpdate, pack, unpack


class NoSharing:
    """Robots keep what they map to themselves."""

    name: ClassVar[str] = "none"
    tracks_changes: ClassVar[bool] = False

    def __init__(self, context: SharingContext) -> None:
        pass

    def start(self, run: RunContext) -> None:
        """Nothing to listen to."""

    def mapped(
        self, run: RunContext, robot: int, pose: tuple[float, float, float], scan: LaserScan
    ) -> None:
        """Nothing to send."""


class ScanSharing:
    """Every mapped scan goes to the neighbours with its pose; they map it too."""

    name: ClassVar[str] = "scans"
    tracks_changes: ClassVar[bool] = False

    def __init__(self, context: SharingContext) -> None:
        self.context = context
        context.run.bus.advertise(SCANS, LocalizedScan, TopicQos.SENSOR)

    def start(self, run: RunContext) -> None:
        """Every robot takes in its neighbours' scans."""
        for i, host in enumerate(self.context.hosts):
            run.bus.subscribe(SCANS, host, self._on_scan(run, i))

    def mapped(
        self, run: RunContext, robot: int, pose: tuple[float, float, float], scan: LaserScan
    ) -> None:
        """Send the scan at its estimated pose."""
        x, y, yaw = pose
        shared = LocalizedScan(
            run.kernel.now_ns,
            self.context.names[robot],
            x,
            y,
            yaw,
            scan.angle_min_rad,
            scan.angle_increment_rad,
            scan.range_min_m,
            scan.range_max_m,
            scan.ranges_m,
        )
        self.context.records.shared(shared.size_bytes())
        run.bus.publish(SCANS, shared, self.context.hosts[robot])

    def _on_scan(self, run: RunContext, i: int) -> Callable[[Message, Envelope], None]:
        context = self.context
        me = context.names[i]
        grid = context.maps[i]
        clear_m = context.params.clear_no_return_m

        def on_scan(message: Message, envelope: Envelope) -> None:
            assert isinstance(message, LocalizedScan)
            if message.robot == me:
                return
            angles = message.angle_min_rad + message.angle_increment_rad * np.arange(
                len(message.ranges_m), dtype=np.float64
            )
            cells = grid.integrate(
                (message.x_m, message.y_m, message.yaw_rad),
                angles,
                message.ranges_m,
                range_min_m=message.range_min_m,
                range_max_m=message.range_max_m,
                clear_no_return_m=clear_m,
            )
            context.records.merge(
                run.kernel.now_ns,
                i,
                message.robot,
                "scan",
                message.size_bytes(),
                message.stamp_ns,
                cells,
            )

        return on_scan


class MapUpdateSharing:
    """Every mapping.share_period_s each robot sends what its own scans added, compressed."""

    name: ClassVar[str] = "maps"
    tracks_changes: ClassVar[bool] = True

    @classmethod
    def problems(cls, mapping: MappingConfig) -> Iterator[Problem]:
        """A map rebuilt after a loop closure cannot be sent as an update."""
        if mapping.loop_closure:
            yield Problem(
                "loop_closure",
                True,
                "false with share = 'maps' (a map rebuilt after a loop closure would be sent "
                "again on top of what the neighbours hold; share 'scans' instead)",
            )

    def __init__(self, context: SharingContext) -> None:
        self.context = context
        self.seq = [0] * len(context.names)
        context.run.bus.advertise(UPDATES, MapUpdate)

    def start(self, run: RunContext) -> None:
        """Every robot takes in its neighbours' updates; updates go out periodically."""
        for i, host in enumerate(self.context.hosts):
            run.bus.subscribe(UPDATES, host, self._on_update(run, i))
        kernel = run.kernel
        share = period_ns(1.0 / self.context.mapping.share_period_s)
        kernel.every(
            share,
            lambda now: self._share(run, now),
            stage=Stage.CONTROL,
            start_ns=kernel.now_ns + share,
        )

    def mapped(
        self, run: RunContext, robot: int, pose: tuple[float, float, float], scan: LaserScan
    ) -> None:
        """Nothing at once: the map keeps the change until the next update."""

    def _share(self, run: RunContext, now_ns: int) -> None:
        context = self.context
        for i, grid in enumerate(context.maps):
            changes = grid.take_changes()
            packed = pack(changes) if changes is not None else None
            if packed is None:
                continue
            self.seq[i] += 1
            update = MapUpdate(
                now_ns,
                context.names[i],
                self.seq[i],
                packed.ix0,
                packed.iy0,
                packed.width,
                packed.height,
                packed.scale,
                packed.data,
            )
            context.records.shared(update.size_bytes())
            run.bus.publish(UPDATES, update, context.hosts[i])

    def _on_update(self, run: RunContext, i: int) -> Callable[[Message, Envelope], None]:
        context = self.context
        me = context.names[i]
        grid = context.maps[i]
        shape = (context.geometry.height, context.geometry.width)

        def on_update(message: Message, envelope: Envelope) -> None:
            assert isinstance(message, MapUpdate)
            if message.robot == me:
                return
            packed = PackedUpdate(
                message.ix0,
                message.iy0,
                message.width,
                message.height,
                message.scale,
                message.data,
            )
            try:
                block = unpack(packed, shape)
            except ModelError as error:  # a malformed update is ignored, and counted
                run.recorder.event(run.kernel.now_ns, me, "map_update_refused", str(error))
                return
            cells = grid.add_logodds(message.iy0, message.ix0, block)
            context.records.merge(
                run.kernel.now_ns,
                i,
                message.robot,
                "map",
                message.size_bytes(),
                message.stamp_ns,
                cells,
            )

        return on_update
