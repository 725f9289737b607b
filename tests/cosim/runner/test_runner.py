from collections.abc import Mapping
from typing import Any, ClassVar

import numpy as np
import pandas as pd
import pytest

import cosim
from cosim.core.adapter import RunContext
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.registry import AdapterRegistry
from cosim.runner.assembly import adapter_names
from cosim.runner.execute import execute


def test_two_runs_with_the_same_seed_give_identical_tables(small_scenario):
    first = cosim.run(small_scenario, seed=4)
    second = cosim.run(small_scenario, seed=4)
    assert {"poses", "messages", "events", "collisions"} <= set(first.tables)
    second_tables = second.deterministic_tables()
    for name, frame in first.deterministic_tables().items():
        pd.testing.assert_frame_equal(frame, second_tables[name])


def test_different_seeds_give_different_tables(small_scenario):
    first = cosim.run(small_scenario, seed=4)
    second = cosim.run(small_scenario, seed=5)
    assert not first.tables["poses"].equals(second.tables["poses"])


class NoiseProbe:
    """An unrelated component that draws many random numbers at every tick."""

    name: ClassVar[str] = "noise_probe"
    requires: ClassVar[tuple[str, ...]] = ()

    def __init__(self, run: RunContext) -> None:
        self.rng = run.rng.stream("noise_probe")
        self.total = 0.0

    def start(self, run: RunContext) -> None:
        def draw(now: int) -> None:
            self.total += float(self.rng.random(1000).sum())

        run.kernel.every(1_000_000, draw, stage=Stage.SENSING)

    def finish(self, run: RunContext) -> Mapping[str, Any]:
        return {"probe_total": self.total}


def test_adding_an_unrelated_component_does_not_change_another_components_stream(small_scenario):
    registry = AdapterRegistry.from_entry_points()
    base = adapter_names(small_scenario)
    plain = execute(small_scenario, registry=registry, names=base)
    probed = execute(
        small_scenario, registry=registry.with_adapter(NoiseProbe), names=["noise_probe", *base]
    )
    assert probed.summary["probe_total"] > 0
    pd.testing.assert_frame_equal(plain.tables["poses"], probed.tables["poses"])
    pd.testing.assert_frame_equal(plain.tables["events"], probed.tables["events"])


def test_robots_keep_their_random_streams_when_the_fleet_grows():
    four = cosim.run(
        cosim.load_scenario(
            "warehouse-random",
            overrides={
                "scenario.duration_s": 3.0,
                "world.size_m": [12.0, 12.0],
                "world.shelf_count": 4,
                "robots.count": 4,
                "lidar.beams": 90,
                "robots.placement": "explicit",
                "robots.positions": [
                    [2.0, 1.0, 1.57],
                    [4.0, 1.0, 1.57],
                    [6.0, 1.0, 1.57],
                    [8.0, 1.0, 1.57],
                ],
            },
        )
    )
    three_explicit = cosim.run(
        cosim.load_scenario(
            "warehouse-random",
            overrides={
                "scenario.duration_s": 3.0,
                "world.size_m": [12.0, 12.0],
                "world.shelf_count": 4,
                "robots.count": 3,
                "lidar.beams": 90,
                "robots.placement": "explicit",
                "robots.positions": [[2.0, 1.0, 1.57], [4.0, 1.0, 1.57], [6.0, 1.0, 1.57]],
            },
        )
    )

    def goals(result):
        navigation = result.tables["navigation"]
        rows = navigation[(navigation["event"] == "goal") & (navigation["robot"] == "robot_1")]
        return list(zip(rows["goal_x_m"], rows["goal_y_m"], strict=True))

    first, second = goals(four), goals(three_explicit)
    common = min(len(first), len(second))
    assert common >= 1
    assert first[:common] == second[:common]


def test_the_poses_table_samples_every_robot_at_the_record_rate(small_scenario):
    result = cosim.run(small_scenario)
    poses = result.tables["poses"]
    times = np.unique(poses["t_s"])
    np.testing.assert_allclose(times, np.arange(30) * 0.1)
    assert set(poses["robot"]) == {"robot_1", "robot_2", "robot_3"}
    assert poses.groupby("robot", observed=True).size().tolist() == [30, 30, 30]


def test_robots_move_towards_their_waypoints(small_scenario):
    result = cosim.run(small_scenario, duration_s=10.0)
    assert result.summary["distance_m"] > 5.0
    assert result.summary["waypoints_reached"] >= 1
    assert result.summary["lidar_scans"] == 100


def test_summary_counts_messages_and_events(small_scenario):
    result = cosim.run(small_scenario)
    summary = result.summary
    assert summary["messages_sent"] == len(result.tables["messages"])
    assert summary["messages_dropped"] == 0
    assert summary["events"] > 0
    assert summary["real_time_factor"] > 0


class _Odometer:
    """Counts the odometry messages of robot_1 (an adapter given in code, not registered)."""

    name = "odometer"
    requires = ("fleet",)

    def __init__(self, run):
        self.count = 0
        self.table = run.recorder.table("odometer", ("t_s", "count"))

    def start(self, run):
        run.bus.subscribe("/robot_1/odom", HostId("robot_1"), self._on_odom(run))

    def _on_odom(self, run):
        def on_odom(message, envelope):
            self.count += 1
            self.table.append(t_s=run.kernel.now_ns / 1e9, count=self.count)

        return on_odom

    def finish(self, run):
        return {"odometer_messages": self.count}


class _NoFinish:
    name = "no_finish"
    requires = ()

    def __init__(self, run):
        pass

    def start(self, run):
        pass


def test_an_adapter_class_given_to_run_runs_beside_the_scenarios(small_scenario):
    result = cosim.run(small_scenario, seed=2, adapters=[_Odometer])
    # odometry at robots.control_hz (20 Hz) for 3 s
    assert result.summary["odometer_messages"] == 60
    assert len(result.tables["odometer"]) == 60
    again = cosim.run(small_scenario, seed=2, adapters=[_Odometer])
    pd.testing.assert_frame_equal(result.tables["poses"], again.tables["poses"])


def test_an_adapter_missing_finish_is_refused_before_the_run_naming_it(small_scenario):
    with pytest.raises(cosim.RegistryError, match=r"adapter 'no_finish' .* has no finish\(run\)"):
        cosim.run(small_scenario, adapters=[_NoFinish])


def test_an_unknown_adapter_name_given_to_run_suggests_the_nearest(small_scenario):
    with pytest.raises(cosim.RegistryError, match=r"unknown adapter 'lidr'; did you mean 'lidar'"):
        cosim.run(small_scenario, adapters=["lidr"])
