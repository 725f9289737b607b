"""The ROS interface: clock, frames, ground truth, map and markers on the bus, for ROS tools."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import cosim
from adapters.recording.ros_interface import (
    MAP_RESOLUTION_M,
    ROBOT_HEIGHT_M,
    TASK_HELD_RGBA,
    TASK_OPEN_RGBA,
    RosInterfaceAdapter,
)
from adapters.recording.topics import CLOCK, MAP, MARKERS, TF, TF_STATIC, ground_truth_topic
from adapters.tasks.topics import TASKS
from cosim.core.bus import TopicQos
from cosim.core.hosts import BASE_HOST
from cosim.core.messages import (
    Clock,
    MarkerArray,
    MarkerType,
    Message,
    OccupancyGrid,
    Odometry,
    TaskInfo,
    TaskSet,
    TFMessage,
)
from cosim.core.messages.scene import MarkerAction
from cosim.core.timebase import s_to_ns
from cosim.runner.assembly import assemble
from models.fleet.kinematics import FleetState
from models.geometry.se2 import compose
from models.world.warehouse import Warehouse, ground_truth_grid
from tests.conftest import SMALL

ROBOTS = ["robot_1", "robot_2", "robot_3"]


class Interface:
    """A small warehouse with the ROS interface, robots driving in arcs, every topic heard."""

    def __init__(self, names: tuple[str, ...] = ("ros_interface",), **overrides: Any) -> None:
        scenario = cosim.load_scenario("warehouse-random", {**SMALL, **overrides})
        self.assembly = assemble(scenario, names=list(names))
        self.run = self.assembly.run
        self.heard: dict[str, list[tuple[int, Message]]] = {}
        topics = [CLOCK, TF, TF_STATIC, MAP, MARKERS, *map(ground_truth_topic, ROBOTS)]
        for topic in topics:
            self.run.bus.monitor(topic, self._keep)
        fleet = self.run.service(FleetState)
        fleet.v_cmd[:] = [0.3, 0.2, 0.1]
        fleet.w_cmd[:] = [0.4, -0.3, 0.0]

    def _keep(self, topic: str, message: Message, _src: Any, t_ns: int) -> None:
        self.heard.setdefault(topic, []).append((t_ns, message))

    def start(self) -> None:
        for _name, adapter in self.assembly.adapters:
            adapter.start(self.run)

    def until(self, t_s: float) -> None:
        self.run.kernel.run(s_to_ns(t_s))

    def messages(self, topic: str) -> list[Any]:
        return [m for _, m in self.heard.get(topic, [])]


@pytest.fixture(scope="module")
def driven() -> Interface:
    """One second of driving with odometry drift: map -> odom is not the identity."""
    interface = Interface(**{"odometry.drift": 0.2})
    interface.start()
    interface.until(1.05)
    return interface


def test_the_latched_topics_are_advertised_latched_and_the_others_not():
    advertised = Interface().run.bus.advertised()
    for topic in (TF_STATIC, MAP, MARKERS):
        assert advertised[topic].qos is TopicQos.LATCHED
    for topic in (CLOCK, TF, ground_truth_topic("robot_2")):
        assert advertised[topic].qos is not TopicQos.LATCHED
    assert advertised[ground_truth_topic("robot_2")].message_type is Odometry


def test_the_clock_ticks_at_the_pose_rate(driven: Interface):
    clock = driven.heard[CLOCK]
    assert [t for t, _ in clock] == [k * 100_000_000 for k in range(11)]  # 10 Hz
    assert all(isinstance(m, Clock) and m.stamp_ns == t for t, m in clock)


def test_tf_static_puts_every_robots_laser_at_its_centre(driven: Interface):
    [(t_ns, message)] = driven.heard[TF_STATIC]
    assert t_ns == 0 and isinstance(message, TFMessage)
    assert [tuple(t) for t in message.transforms] == [
        (f"{r}/base_link", f"{r}/laser", 0.0, 0.0, 0.0) for r in ROBOTS
    ]


def test_every_tf_chains_map_odom_base_link_to_the_ground_truth(driven: Interface):
    fleet = driven.run.service(FleetState)
    last = driven.messages(TF)[-1]
    assert len(last.transforms) == 2 * len(ROBOTS)
    truth = driven.messages(ground_truth_topic("robot_1"))[-1]
    for i, robot in enumerate(ROBOTS):
        to_odom, to_base = last.transforms[2 * i], last.transforms[2 * i + 1]
        assert (to_odom.parent, to_odom.child) == ("map", f"{robot}/odom")
        assert (to_base.parent, to_base.child) == (f"{robot}/odom", f"{robot}/base_link")
        pose = compose(to_odom[2:], to_base[2:])
        assert pose == pytest.approx((fleet.x[i], fleet.y[i], fleet.yaw[i]), abs=1e-9)
    assert (truth.x_m, truth.y_m, truth.yaw_rad) == pytest.approx(
        (fleet.x[0], fleet.y[0], fleet.yaw[0])
    )


def test_with_drift_map_to_odom_is_the_odometrys_error(driven: Interface):
    first, last = driven.messages(TF)[0], driven.messages(TF)[-1]
    assert tuple(first.transforms[0][2:]) == pytest.approx((0.0, 0.0, 0.0), abs=1e-12)
    assert np.hypot(*last.transforms[0][2:4]) > 1e-6  # the odometry drifted off the truth


def test_ground_truth_is_each_robots_odometry_in_map_with_its_speeds(driven: Interface):
    fleet = driven.run.service(FleetState)
    for i, robot in enumerate(ROBOTS):
        samples = driven.heard[ground_truth_topic(robot)]
        assert len(samples) == 11
        t_ns, truth = samples[-1]
        assert truth == Odometry(
            t_ns,
            "map",
            f"{robot}/base_link",
            fleet.x[i],
            fleet.y[i],
            fleet.yaw[i],
            fleet.v[i],
            fleet.w[i],
        )
    assert driven.messages(ground_truth_topic("robot_1"))[-1].v_mps == pytest.approx(0.3)


def test_the_map_is_the_worlds_true_occupancy_at_5_cm(driven: Interface):
    [grid] = driven.messages(MAP)
    truth = ground_truth_grid(driven.run.service(Warehouse), MAP_RESOLUTION_M)
    assert isinstance(grid, OccupancyGrid) and grid.frame_id == "map"
    assert (grid.resolution_m, grid.width, grid.height) == (0.05, truth.width, truth.height)
    assert (grid.origin_x_m, grid.origin_y_m) == tuple(truth.origin_xy_m)
    assert grid.data == truth.data.tobytes()


def test_the_world_markers_are_walls_shelves_and_robot_footprints_riding_on_base_link(
    driven: Interface,
):
    [markers] = driven.messages(MARKERS)
    assert isinstance(markers, MarkerArray) and markers.stamp_ns == 0
    world = driven.run.service(Warehouse)
    by_ns: dict[str, list[Any]] = {}
    for marker in markers.markers:
        by_ns.setdefault(marker.ns, []).append(marker)
    assert len(by_ns["walls"]) == len(world.walls)
    assert len(by_ns["shelves"]) == len(world.shelves) == 4
    x0, y0, x1, y1 = world.shelves[0]
    shelf = by_ns["shelves"][0]
    assert (shelf.x_m, shelf.y_m) == pytest.approx(((x0 + x1) / 2, (y0 + y1) / 2))
    assert shelf.scale_m[:2] == pytest.approx((x1 - x0, y1 - y0))
    robots = by_ns["robots"]
    diameter = 2 * driven.run.service(FleetState).radius_m[0]
    assert [m.frame_id for m in robots] == [f"{r}/base_link" for r in ROBOTS]
    assert all(m.frame_locked and m.kind is MarkerType.CYLINDER for m in robots)
    assert robots[0].scale_m == pytest.approx((diameter, diameter, ROBOT_HEIGHT_M))


def _tasks(*tasks: tuple[int, float, float, str]) -> TaskSet:
    return TaskSet(0, 1, tuple(TaskInfo(i, x, y, ("robot_1",), h) for i, x, y, h in tasks))


def test_open_tasks_are_drawn_over_the_whole_world_after_clearing_the_display():
    interface = Interface()
    interface.start()
    static = interface.messages(MARKERS)[0].markers
    publish = interface.run.bus.publish
    publish(TASKS, _tasks((4, 1.0, 2.0, ""), (7, 3.0, 4.0, "robot_2")), BASE_HOST)
    drawn = interface.messages(MARKERS)[-1].markers
    assert drawn[0].action is MarkerAction.DELETEALL
    assert drawn[1 : 1 + len(static)] == static
    tasks = drawn[1 + len(static) :]
    shapes = {m.marker_id: m for m in tasks if m.kind is MarkerType.CYLINDER}
    labels = {m.marker_id: m.text for m in tasks if m.kind is MarkerType.TEXT_VIEW_FACING}
    assert (shapes[4].color, shapes[7].color) == (TASK_OPEN_RGBA, TASK_HELD_RGBA)
    assert (shapes[7].x_m, shapes[7].y_m) == (3.0, 4.0)
    assert labels == {1_000_004: "task 4", 1_000_007: "task 7: robot_2"}


def test_a_task_set_sent_again_unchanged_is_not_drawn_again():
    interface = Interface()
    interface.start()
    publish = interface.run.bus.publish
    publish(TASKS, _tasks((4, 1.0, 2.0, "")), BASE_HOST)
    publish(TASKS, _tasks((4, 1.0, 2.0, "")), BASE_HOST)
    assert len(interface.messages(MARKERS)) == 2  # the world, then the task once
    publish(TASKS, _tasks((4, 1.0, 2.0, "robot_1")), BASE_HOST)  # now held
    assert len(interface.messages(MARKERS)) == 3


def test_the_interface_adds_no_kernel_event_and_no_table_row():
    def run(names: tuple[str, ...]) -> tuple[int, dict[str, int]]:
        interface = Interface(names)
        interface.start()
        interface.until(1.0)
        rows = {name: len(table) for name, table in interface.run.recorder.tables.items()}
        return interface.run.kernel.events_processed, rows

    assert run(("ros_interface",)) == run(("world", "fleet", "poses"))


def test_the_interface_is_added_when_the_run_is_recorded_only():
    from cosim.runner.assembly import adapter_names

    scenario = cosim.load_scenario("warehouse-random", SMALL)
    assert "ros_interface" not in adapter_names(scenario)
    assert "ros_interface" in adapter_names(scenario, recording=True)
    assert RosInterfaceAdapter.requires == ("world", "fleet", "poses")
