from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np

import cosim
from adapters.naming import topic
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.messages import LaserScan
from cosim.core.registry import AdapterRegistry
from cosim.runner.execute import execute
from models.world.obstacles import DynamicObstacles

SCENARIO = {
    "scenario.duration_s": 0.35,
    "world.size_m": [10.0, 10.0],
    "world.shelf_count": 0,
    "robots.count": 1,
    "robots.placement": "explicit",
    "robots.positions": [[5.0, 5.0, 0.0]],
    "lidar.beams": 4,
    "lidar.noise_std_m": 0.0,
}


class ScanCatcher:
    """Test adapter keeping every scan of robot_1, and placing a person 2 m ahead."""

    name: ClassVar[str] = "scan_catcher"
    requires: ClassVar[tuple[str, ...]] = ("lidar",)
    scans: ClassVar[list[tuple[int, LaserScan]]] = []

    def __init__(self, run: RunContext) -> None:
        run.service(DynamicObstacles).update("people", np.array([[7.0, 5.0, 0.25]]), ["p0"])

    def start(self, run: RunContext) -> None:
        def keep(message, envelope) -> None:
            ScanCatcher.scans.append((envelope.t_recv_ns, message))

        run.bus.subscribe(topic("robot_1", "scan"), HostId("robot_1"), keep)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        return {}


def test_scans_arrive_at_the_lidar_rate_and_see_walls_and_dynamic_obstacles():
    ScanCatcher.scans.clear()
    registry = AdapterRegistry.from_entry_points().with_adapter(ScanCatcher)
    scenario = cosim.load_scenario("warehouse-random", SCENARIO)
    execute(scenario, names=["world", "fleet", "lidar", "scan_catcher"], registry=registry)
    times = [t for t, _ in ScanCatcher.scans]
    assert times == [0, 100_000_000, 200_000_000, 300_000_000]
    scan = ScanCatcher.scans[0][1]
    # beams at -180, -90, 0, 90 deg from (5, 5) facing +x, person at x = 7 with r = 0.25
    np.testing.assert_allclose(scan.ranges_m, [5.0, 5.0, 1.75, 5.0], atol=1e-6)
    assert scan.angle_min_rad == -np.pi
    assert scan.frame_id == "robot_1/laser"
