"""The ROS interface of the simulation: what a ROS 2 simulator publishes for its tools.

Gazebo with its ROS plugins, map_server and robot_state_publisher give RViz and Foxglove
the simulation time, every robot's frames, the map and the world's shapes. This adapter
publishes the same on the bus, so a bag or the live view of a run opens in those tools:

- ``/clock`` (rosgraph_msgs/Clock) at ``record.pose_rate_hz``;
- ``/tf`` (tf2_msgs/TFMessage), one message per sample for the whole fleet, as a
  simulator's pose bridge publishes it: ``map`` -> ``robot_i/odom`` (the odometry drift, as
  a localizer would publish it) and ``robot_i/odom`` -> ``robot_i/base_link`` (the
  odometry) of every robot;
- ``/tf_static``: ``robot_i/base_link`` -> ``robot_i/laser`` (the lidar at the centre);
- ``/robot_i/ground_truth`` (nav_msgs/Odometry, ``map`` -> ``robot_i/base_link``);
- ``/map`` (nav_msgs/OccupancyGrid of the walls and shelves, latched);
- ``/world/markers`` (visualization_msgs/MarkerArray, latched): walls, shelves, robot
  footprints riding on their ``base_link``, and the open tasks (orange, green once held),
  re-published whole whenever the open tasks or their holders change;
- ``/humans/markers`` (visualization_msgs/MarkerArray) in runs with people: every worker
  (orange cylinder, 1.7 m) and forklift (yellow box) where SUMO put them, a DELETEALL and
  the whole crowd per sample, a marker id per person for the run.

It samples on the pose recorder's tick and watches ``/fleet/tasks`` with a bus monitor,
so it adds no kernel event, no delivery and no table row: a run's tables are the same
with and without it. The assembly adds it when the run is recorded or viewed live.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

from adapters.fleet.motion import FleetAdapter
from adapters.humans.crowd import People
from adapters.recording.poses import PosesAdapter
from adapters.recording.topics import CLOCK, MAP, MARKERS, TF, TF_STATIC, ground_truth_topic
from adapters.tasks.topics import TASKS
from cosim.core.adapter import RunContext
from cosim.core.bus import TopicQos
from cosim.core.hosts import BASE_HOST
from cosim.core.messages import (
    Clock,
    Marker,
    MarkerArray,
    MarkerType,
    Message,
    OccupancyGrid,
    Odometry,
    TaskSet,
    TFMessage,
    Transform,
)
from cosim.core.messages.scene import RGBA, MarkerAction
from cosim.scenario.sections import RobotsConfig
from models.fleet.kinematics import FleetState
from models.world.warehouse import Warehouse, ground_truth_grid

MAP_RESOLUTION_M = 0.05
"""Cell size of ``/map`` (m), map_server's usual resolution."""
WALL_RGBA: RGBA = (0.3, 0.3, 0.3, 1.0)
SHELF_RGBA: RGBA = (0.78, 0.53, 0.29, 1.0)
ROBOT_RGBA: RGBA = (0.12, 0.47, 0.71, 0.8)
TASK_OPEN_RGBA: RGBA = (1.0, 0.5, 0.05, 0.9)
TASK_HELD_RGBA: RGBA = (0.17, 0.63, 0.17, 0.9)
SHELF_HEIGHT_M = 1.8
WALL_HEIGHT_M = 2.0
ROBOT_HEIGHT_M = 0.25
"""Jackal's body height, about 0.25 m (Clearpath's datasheet)."""

HUMAN_MARKERS = "/humans/markers"
PERSON_RGBA: RGBA = (0.95, 0.56, 0.17, 0.9)
FORKLIFT_RGBA: RGBA = (0.93, 0.79, 0.28, 0.9)
PERSON_HEIGHT_M = 1.7
FORKLIFT_HEIGHT_M = 2.0


class RosInterfaceAdapter:
    """Publishes clock, frames, ground truth, map and markers for ROS 2 tools."""

    name: ClassVar[str] = "ros_interface"
    requires: ClassVar[tuple[str, ...]] = ("world", "fleet", "poses")

    def __init__(self, run: RunContext) -> None:
        self.world = run.service(Warehouse)
        self.fleet = run.service(FleetState)
        self.motion = run.service(FleetAdapter)
        self.names = list(self.fleet.names)
        self.truth_topics = [ground_truth_topic(n) for n in self.names]
        self.frames = [(f"{n}/odom", f"{n}/base_link") for n in self.names]
        self.radius_m = run.settings(RobotsConfig).radius_m
        self.static_markers = self._static_markers()
        self._shown: tuple[tuple[int, str], ...] | None = None
        bus = run.bus
        bus.advertise(CLOCK, Clock)
        bus.advertise(TF, TFMessage)
        bus.advertise(TF_STATIC, TFMessage, TopicQos.LATCHED)
        bus.advertise(MAP, OccupancyGrid, TopicQos.LATCHED)
        bus.advertise(MARKERS, MarkerArray, TopicQos.LATCHED)
        for name in self.truth_topics:
            bus.advertise(name, Odometry)
        self.people = run.service(People) if run.has_service(People) else None
        self.person_ids: dict[str, int] = {}
        if self.people is not None:
            bus.advertise(HUMAN_MARKERS, MarkerArray)
        run.service(PosesAdapter).on_sample(lambda now: self._sample(run, now))

    def start(self, run: RunContext) -> None:
        """Publish the latched topics and follow the task announcements."""
        now = run.kernel.now_ns
        bus = run.bus
        lasers = tuple(Transform(f"{n}/base_link", f"{n}/laser", 0.0, 0.0, 0.0) for n in self.names)
        bus.publish(TF_STATIC, TFMessage(now, lasers), BASE_HOST)
        grid = ground_truth_grid(self.world, MAP_RESOLUTION_M)
        bus.publish(
            MAP,
            OccupancyGrid(
                now,
                "map",
                grid.resolution_m,
                grid.width,
                grid.height,
                grid.origin_xy_m[0],
                grid.origin_xy_m[1],
                grid.data.tobytes(),
            ),
            BASE_HOST,
        )
        bus.publish(MARKERS, MarkerArray(now, self.static_markers), BASE_HOST)
        bus.monitor(TASKS, lambda _topic, message, _src, t_ns: self._on_tasks(run, message, t_ns))

    def _static_markers(self) -> tuple[Marker, ...]:
        markers: list[Marker] = []
        for kind, boxes, rgba, height in (
            ("walls", self.world.walls, WALL_RGBA, WALL_HEIGHT_M),
            ("shelves", self.world.shelves, SHELF_RGBA, SHELF_HEIGHT_M),
            ("obstacles", self.world.obstacles, SHELF_RGBA, SHELF_HEIGHT_M),
        ):
            for i, (x0, y0, x1, y1) in enumerate(np.asarray(boxes).tolist()):
                markers.append(
                    Marker(
                        kind,
                        i,
                        MarkerType.CUBE,
                        x_m=(x0 + x1) / 2,
                        y_m=(y0 + y1) / 2,
                        z_m=height / 2,
                        scale_m=(x1 - x0, y1 - y0, height),
                        color=rgba,
                    )
                )
        diameter = 2 * self.radius_m
        for i, (_, base_link) in enumerate(self.frames):
            markers.append(
                Marker(
                    "robots",
                    i,
                    MarkerType.CYLINDER,
                    frame_id=base_link,
                    z_m=ROBOT_HEIGHT_M / 2,
                    scale_m=(diameter, diameter, ROBOT_HEIGHT_M),
                    color=ROBOT_RGBA,
                    frame_locked=True,
                )
            )
        return tuple(markers)

    def _on_tasks(self, run: RunContext, message: Message, t_ns: int) -> None:
        if not isinstance(message, TaskSet):
            return
        # the source re-sends unchanged sets every `assignment.rebroadcast_s`: draw changes only
        shown = tuple((t.task_id, t.holder) for t in message.tasks)
        if shown == self._shown:
            return
        self._shown = shown
        # RViz and Foxglove drop every marker of the topic on DELETEALL: the whole world is
        # re-sent after it, so the latched last message alone draws everything
        clear = Marker("tasks", 0, MarkerType.CYLINDER, action=MarkerAction.DELETEALL)
        tasks: list[Marker] = []
        for task in message.tasks:
            held = bool(task.holder)
            tasks.append(
                Marker(
                    "tasks",
                    task.task_id,
                    MarkerType.CYLINDER,
                    x_m=task.x_m,
                    y_m=task.y_m,
                    z_m=0.05,
                    scale_m=(0.4, 0.4, 0.1),
                    color=TASK_HELD_RGBA if held else TASK_OPEN_RGBA,
                )
            )
            label = f"task {task.task_id}" + (f": {task.holder}" if held else "")
            tasks.append(
                Marker(
                    "tasks",
                    1_000_000 + task.task_id,
                    MarkerType.TEXT_VIEW_FACING,
                    x_m=task.x_m,
                    y_m=task.y_m,
                    z_m=0.5,
                    scale_m=(0.0, 0.0, 0.35),
                    color=(0.1, 0.1, 0.1, 1.0),
                    text=label,
                )
            )
        markers = MarkerArray(t_ns, (clear, *self.static_markers, *tasks))
        run.bus.publish(MARKERS, markers, BASE_HOST)

    def _sample(self, run: RunContext, now_ns: int) -> None:
        """Clock, frames and ground truth of every robot at the pose recorder's tick."""
        fleet = self.fleet
        odom = self.motion.odom
        x, y, yaw = fleet.x, fleet.y, fleet.yaw
        # map -> odom = (map -> base_link) o (odom -> base_link)^-1
        drift_yaw = yaw - odom[:, 2]
        c, s = np.cos(drift_yaw), np.sin(drift_yaw)
        tx = x - (c * odom[:, 0] - s * odom[:, 1])
        ty = y - (s * odom[:, 0] + c * odom[:, 1])
        bus = run.bus
        bus.publish(CLOCK, Clock(now_ns), BASE_HOST)
        rows = zip(
            x.tolist(),
            y.tolist(),
            yaw.tolist(),
            fleet.v.tolist(),
            fleet.w.tolist(),
            odom.tolist(),
            tx.tolist(),
            ty.tolist(),
            drift_yaw.tolist(),
            strict=True,
        )
        transforms: list[Transform] = []
        for i, (xi, yi, yawi, vi, wi, (ox, oy, oyaw), txi, tyi, dyaw) in enumerate(rows):
            frame, base_link = self.frames[i]
            transforms.append(Transform("map", frame, txi, tyi, dyaw))
            transforms.append(Transform(frame, base_link, ox, oy, oyaw))
            truth = Odometry(now_ns, "map", base_link, xi, yi, yawi, vi, wi)
            bus.publish(self.truth_topics[i], truth, BASE_HOST)
        bus.publish(TF, TFMessage(now_ns, tuple(transforms)), BASE_HOST)
        if self.people is not None:
            bus.publish(HUMAN_MARKERS, self._people_markers(now_ns, self.people), BASE_HOST)

    def _people_markers(self, now_ns: int, people: People) -> MarkerArray:
        markers = [Marker("humans", 0, MarkerType.CYLINDER, action=MarkerAction.DELETEALL)]
        diameter = 2 * people.worker_radius_m
        length, width = people.forklift_size_m
        rows = zip(
            people.names,
            people.kinds,
            people.x_m.tolist(),
            people.y_m.tolist(),
            people.yaw_rad.tolist(),
            strict=True,
        )
        for name, kind, x, y, yaw in rows:
            marker_id = self.person_ids.setdefault(name, len(self.person_ids))
            if kind == "forklift":
                shape = (MarkerType.CUBE, (length, width, FORKLIFT_HEIGHT_M), FORKLIFT_RGBA)
            else:
                shape = (MarkerType.CYLINDER, (diameter, diameter, PERSON_HEIGHT_M), PERSON_RGBA)
            kind_of, scale, rgba = shape
            markers.append(
                Marker(
                    "humans",
                    marker_id,
                    kind_of,
                    x_m=x,
                    y_m=y,
                    z_m=scale[2] / 2,
                    yaw_rad=yaw,
                    scale_m=scale,
                    color=rgba,
                )
            )
        return MarkerArray(now_ns, tuple(markers))

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        """Nothing to add to the summary."""
        return {}
