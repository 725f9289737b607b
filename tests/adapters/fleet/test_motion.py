import numpy as np
import pytest

import cosim
from cosim.core.registry import AdapterRegistry
from cosim.runner.execute import execute

SMALL = {
    "scenario.duration_s": 6.0,
    "world.size_m": [12.0, 12.0],
    "world.shelf_count": 4,
    "robots.count": 3,
    "lidar.beams": 0,
    "robots.driver": "waypoints",
}


def test_perfect_odometry_equals_ground_truth():
    result = cosim.run(cosim.load_scenario("warehouse-random", SMALL))
    assert result.summary["distance_m"] > 1.0
    assert result.summary["odometry_error_m_mean"] == pytest.approx(0.0, abs=1e-9)


def test_odometry_drifts_with_drift_and_repeats_with_the_seed():
    scenario = cosim.load_scenario("warehouse-random", {**SMALL, "odometry.drift": 0.05})
    first = cosim.run(scenario)
    second = cosim.run(scenario)
    assert first.summary["odometry_error_m_mean"] > 0.001
    assert first.summary["odometry_error_m_mean"] == second.summary["odometry_error_m_mean"]


def test_odometry_is_published_at_the_control_rate_on_each_robot():
    scenario = cosim.load_scenario("warehouse-random", SMALL)
    result = execute(
        scenario, names=["fleet", "waypoints"], registry=AdapterRegistry.from_entry_points()
    )
    messages = result.tables["messages"]
    odom = messages[messages["topic"] == "/robot_2/odom"]
    assert list(odom["t_sent_ns"]) == [k * 50_000_000 for k in range(120)]
    assert set(odom["src_host"]) == {"robot_2"} and set(odom["dst_host"]) == {"robot_2"}
    assert np.all(odom["bytes"] == odom["bytes"].iloc[0])
