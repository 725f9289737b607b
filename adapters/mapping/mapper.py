"""The mapping adapter: every robot maps as it drives and corrects its odometry (slam_toolbox).

On each robot's host, its scans and odometry go through a :class:`~models.mapping.slam.ScanMapper`
(update gate, correlative matching, log-odds map). After every map update the robot
publishes its ``map -> robot_i/odom`` correction on ``/robot_i/tf`` (namespaced tf, as
Nav2's multi-robot bringup remaps it), which its navigation composes with odometry to
localize; every ``mapping.map_update_interval_s`` it publishes its map on
``/robot_i/map`` (nav_msgs/OccupancyGrid), which its navigation plans on, as
slam_toolbox's ``/map`` feeds Nav2's static layer.

What robots send their neighbours of what they map is the registered sharing mode
``mapping.share`` names (:mod:`adapters.mapping.sharing`: ``none``, ``scans``, ``maps``).
With the navigation's robots layer (:mod:`adapters.fleet.robots_layer`), each robot leaves
returns off the robots it heard of out of its map and its matching.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any, ClassVar

import numpy as np

from adapters.fleet.robots_layer import RobotsLayer
from adapters.fleet.topics import odom_topic
from adapters.mapping.contract import MAP_SHARING, MapSharing, SharingContext
from adapters.mapping.geometry import map_geometry
from adapters.mapping.memory import check_mapping_memory
from adapters.mapping.pending import Pending, ThreadScratch
from adapters.mapping.settings import MappingConfig
from adapters.mapping.tables import (
    MAP_MERGES,
    MAP_QUALITY,
    MAPPING_SUMMARY,
    SCAN_MATCHES,
    MappingRecords,
)
from adapters.mapping.topics import FLEET_MAP, correction_topic, map_topic
from adapters.sensing.topics import scan_topic
from cosim.core.adapter import RunContext
from cosim.core.batches import InstantBatch
from cosim.core.bus import Envelope, TopicQos
from cosim.core.hosts import BASE_HOST, HostId
from cosim.core.kernel import Stage
from cosim.core.messages import (
    LaserScan,
    Message,
    OccupancyGrid,
    Odometry,
    TFMessage,
    Transform,
)
from cosim.core.summary import SummaryKey
from cosim.core.table import TableSpec
from cosim.core.timebase import period_ns
from cosim.scenario.model import Scenario
from cosim.scenario.sections import LidarConfig
from models.arrays import FloatArray
from models.fleet.kinematics import FleetState
from models.geometry.occupancy import OccupancyGrid as Grid
from models.mapping.grid import LogOddsMap, Scratch, merged
from models.mapping.loop_params import LoopParams
from models.mapping.matcher import MatcherParams
from models.mapping.slam import MapperParams, ScanMapper, Update, UpdateGate
from models.sensing.lidar import ScanGeometry
from models.world.warehouse import Warehouse

ROBOT_MARGIN_M = 0.15
"""Returns this close to a robot's disc are taken as the robot's (m): pose age and noise."""


def mapper_params(cfg: MappingConfig, lidar_min_m: float, lidar_max_m: float) -> MapperParams:
    """The model parameters of ``[mapping]`` for a lidar's valid ranges."""
    return MapperParams(
        gate=UpdateGate(cfg.min_travel_m, cfg.min_heading_rad, cfg.min_interval_s),
        matcher=MatcherParams(
            window_m=cfg.search_window_m,
            window_rad=cfg.search_window_rad,
            margin=cfg.match_margin,
            refine_against=cfg.refine,
        ),
        scan_matching=cfg.scan_matching != "none",
        range_min_m=lidar_min_m,
        range_max_m=lidar_max_m,
        clear_no_return_m=cfg.clear_no_return_m,
        loop_closure=(
            LoopParams(
                search_radius_m=cfg.loop_search_radius_m,
                min_path_m=cfg.loop_min_path_m,
                min_correction=cfg.loop_min_correction,
            )
            if cfg.loop_closure and cfg.scan_matching != "none"
            else None
        ),
    )


def grid_message(t_ns: int, grid: LogOddsMap) -> OccupancyGrid:
    """A robot's map as the nav_msgs/OccupancyGrid slam_toolbox publishes."""
    return occupancy_message(t_ns, grid.occupancy_grid())


def occupancy_message(t_ns: int, grid: Grid) -> OccupancyGrid:
    """An occupancy grid as a nav_msgs/OccupancyGrid in ``map``."""
    rows, cols = grid.data.shape
    x0, y0 = grid.origin_xy_m
    return OccupancyGrid(t_ns, "map", grid.resolution_m, cols, rows, x0, y0, grid.data.tobytes())


class MappingAdapter:
    """Maps, pose corrections and map sharing of every robot."""

    name: ClassVar[str] = "mapping"
    requires: ClassVar[tuple[str, ...]] = ("world", "fleet", "lidar", "network")
    tables: ClassVar[tuple[TableSpec, ...]] = (MAP_QUALITY, SCAN_MATCHES, MAP_MERGES)
    """The tables it writes (documented in the table reference)."""
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        **MAPPING_SUMMARY,
        "map_loop_closures": SummaryKey("count", "loop closures added to the robots' pose graphs"),
        "map_loop_closures_not_needed": SummaryKey(
            "count", "verified loop closures left out: the estimate agreed already"
        ),
    }
    """The summary keys :meth:`finish` writes (documented in the summary reference)."""

    @staticmethod
    def check_scenario(scenario: Scenario) -> None:
        """Refuse a ``mapping.resolution_m`` whose maps would not fit in memory.

        See :mod:`adapters.mapping.memory`.
        """
        check_mapping_memory(scenario)

    def __init__(self, run: RunContext) -> None:
        self.cfg = run.settings(MappingConfig)
        world = run.service(Warehouse)
        self.fleet = run.service(FleetState)
        self.names = list(self.fleet.names)
        self.hosts = [HostId(n) for n in self.names]
        lidar = run.settings(LidarConfig)
        self.angles = ScanGeometry(
            lidar.beams, math.radians(lidar.fov_deg), lidar.range_min_m, lidar.range_max_m
        ).angles()
        self.geometry = map_geometry(world, self.cfg.resolution_m)
        scratch = Scratch(self.geometry)
        self._scratches = ThreadScratch(self.geometry)
        sharing = MAP_SHARING.installed().get(self.cfg.share)
        track = sharing.tracks_changes
        self.maps = [
            LogOddsMap(
                self.geometry,
                scratch=scratch,
                track_changes=track,
                hit_centroids=self.cfg.refine == "walls",
            )
            for _ in self.names
        ]
        self.params = mapper_params(self.cfg, lidar.range_min_m, lidar.range_max_m)
        self.mappers = [
            ScanMapper(grid, (float(x), float(y), float(yaw)), self.params, self.angles)
            for grid, (x, y, yaw) in zip(self.maps, world.starts, strict=True)
        ]
        self.odom = [(float(x), float(y), float(yaw)) for x, y, yaw in world.starts]
        self.records = MappingRecords(run.recorder, self.names, world, self.geometry)
        self.tf_topics = [correction_topic(n) for n in self.names]
        self.map_topics = [map_topic(n) for n in self.names]
        bus = run.bus
        for tf, grid in zip(self.tf_topics, self.map_topics, strict=True):
            bus.advertise(tf, TFMessage)
            bus.advertise(grid, OccupancyGrid, TopicQos.LATCHED)
        bus.advertise(FLEET_MAP, OccupancyGrid, TopicQos.LATCHED)
        context = SharingContext(
            run,
            self.cfg,
            self.names,
            self.hosts,
            self.maps,
            self.geometry,
            self.params,
            self.records,
        )
        self.sharing: MapSharing = sharing(context)
        self.recorder = run.recorder
        self.workers = run.workers
        # with a robots layer each robot hears where the others are: returns off them are
        # left out of its map and its matching (robots are not the building); whether one
        # runs is known once every adapter is built (the navigation provides it)
        self.robots_layer: RobotsLayer | None = None
        self._batch: InstantBatch[Pending, Update | None] = InstantBatch(
            run.kernel,
            run.workers,
            self._process,
            lambda item, update: self._mapped(run, item, update),
        )

    # -- wiring ----------------------------------------------------------------------
    def start(self, run: RunContext) -> None:
        """Follow every robot's odometry and scans; start publishing, sharing and sampling."""
        bus = run.bus
        if run.has_service(RobotsLayer):
            self.robots_layer = run.service(RobotsLayer)
        for i, (name, host) in enumerate(zip(self.names, self.hosts, strict=True)):
            bus.subscribe(odom_topic(name), host, self._on_odom(i))
            bus.subscribe(scan_topic(name), host, self._on_scan(run, i))
        kernel = run.kernel
        interval = period_ns(1.0 / self.cfg.map_update_interval_s)
        kernel.every(
            interval,
            lambda now: self._publish_maps(run, now),
            stage=Stage.CONTROL,
            start_ns=kernel.now_ns + interval,
        )
        self.sharing.start(run)
        quality = period_ns(1.0 / self.cfg.quality_period_s)
        kernel.every(quality, self._sample, stage=Stage.RECORD, start_ns=kernel.now_ns + quality)

    def _on_odom(self, i: int) -> Callable[[Message, Envelope], None]:
        def on_odom(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, Odometry)
            self.odom[i] = (message.x_m, message.y_m, message.yaw_rad)

        return on_odom

    def _on_scan(self, run: RunContext, i: int) -> Callable[[Message, Envelope], None]:
        def on_scan(message: Message, _envelope: Envelope) -> None:
            assert isinstance(message, LaserScan)
            self._scan(run, i, message)

        return on_scan

    def _without_robots(
        self, layer: RobotsLayer, i: int, now_ns: int, ranges: FloatArray
    ) -> FloatArray:
        """The scan with returns off robots it heard of (recently) set to NaN (ignored)."""
        discs = layer.discs(i, now_ns)
        if not len(discs):
            return ranges
        x, y, yaw = self.mappers[i].estimate(self.odom[i])
        ends = np.stack(
            [x + ranges * np.cos(yaw + self.angles), y + ranges * np.sin(yaw + self.angles)], axis=1
        )
        gap = np.hypot(*(ends[:, None, :] - discs[None, :, :2]).transpose(2, 0, 1))
        on_robot = (gap <= discs[None, :, 2] + ROBOT_MARGIN_M).any(axis=1)
        return np.where(on_robot, np.nan, ranges)

    # -- a robot's own scans ---------------------------------------------------------------
    def _scan(self, run: RunContext, i: int, scan: LaserScan) -> None:
        """Keep a scan that would update robot ``i``'s map, for this instant's batch."""
        now = run.kernel.now_ns
        odom = self.odom[i]
        if not self.mappers[i].due(now, odom):
            return
        ranges = scan.ranges_m
        if self.robots_layer is not None:
            ranges = self._without_robots(
                self.robots_layer, i, now, ranges.astype(np.float64)
            ).astype(np.float32)
        self._batch.add(Pending(i, now, odom, ranges, scan))

    def _mapped(self, run: RunContext, item: Pending, update: Update | None) -> None:
        """What a mapped scan sends: its record, the robot's correction, shared evidence."""
        if update is None:
            return
        now = run.kernel.now_ns
        i, odom = item.robot, item.odom
        truth = (float(self.fleet.x[i]), float(self.fleet.y[i]))
        self.records.update(
            now, i, update.pose, truth, (odom[0], odom[1]), update.score, update.matched
        )
        correction = self.mappers[i].correction
        tf = TFMessage(now, (Transform("map", f"{self.names[i]}/odom", *correction),))
        run.bus.publish(self.tf_topics[i], tf, self.hosts[i])
        self.sharing.mapped(run, i, update.pose, item.scan)

    def _process(self, item: Pending) -> Update | None:
        """One robot's scan, on whichever thread runs it, with that thread's scratch.

        Each robot's mapper reads and writes only its own map, so the scans of one instant
        are matched and mapped at once (:class:`~cosim.core.batches.InstantBatch`).
        """
        grid = self.maps[item.robot]
        shared = grid.scratch
        grid.scratch = self._scratches.mine()
        try:
            return self.mappers[item.robot].process(item.now_ns, item.odom, item.ranges)
        finally:
            grid.scratch = shared

    # -- maps out --------------------------------------------------------------------------
    def _publish_maps(self, run: RunContext, now_ns: int) -> None:
        bus = run.bus
        # each robot's grid classified on the run's threads, published in robot order
        messages = run.workers.map(lambda grid: grid_message(now_ns, grid), self.maps)
        for message, name, host in zip(messages, self.map_topics, self.hosts, strict=True):
            bus.publish(name, message, host)
        bus.publish(FLEET_MAP, occupancy_message(now_ns, merged(self.maps)), BASE_HOST)

    def _sample(self, now_ns: int) -> None:
        self.records.sample(now_ns, self.maps, merged(self.maps), self.workers.map)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Final quality, errors and sharing; the final maps for the run folder."""
        fleet = merged(self.maps)
        self.records.sample(run.kernel.now_ns, self.maps, fleet, self.workers.map)
        for name, grid in zip(self.names, self.maps, strict=True):
            self.recorder.add_map(name, grid.occupancy_grid())
        self.recorder.add_map("fleet", fleet)
        loops = [m.loops for m in self.mappers if m.loops is not None]
        return {
            **self.records.summary(),
            "map_loop_closures": sum(closer.closures for closer in loops),
            "map_loop_closures_not_needed": sum(closer.not_needed for closer in loops),
        }
