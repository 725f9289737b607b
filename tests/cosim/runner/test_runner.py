import errno
import json
import os
from collections.abc import Mapping
from typing import Any, ClassVar
from unittest import mock

import numpy as np
import pandas as pd
import pytest

import cosim
from cosim.core.adapter import RunContext
from cosim.core.errors import ConfigError, ExportError
from cosim.core.hosts import HostId
from cosim.core.kernel import Stage
from cosim.core.registry import AdapterRegistry
from cosim.recording.bag import BagSink
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


# --- a full disk under the bag, and a scenario read to draw a run -------------------------------


def test_a_bag_that_cannot_be_finished_keeps_the_rest_of_the_run(small_scenario, tmp_path):
    out = tmp_path / "run"
    full = ExportError(f"{out}/bag: cannot finish the bag (No space left on device)")
    with (
        mock.patch("cosim.recording.bag.BagSink.close", side_effect=full),
        pytest.raises(ExportError) as refused,
    ):
        cosim.run(small_scenario, duration_s=1.0, out=out)
    assert str(refused.value) == (
        f"{out}/bag: cannot finish the bag (No space left on device); the results of the 1 s "
        f"simulated are in {out}/"
    )
    assert refused.value.kept.out == out
    assert json.loads((out / "summary.json").read_text())["sim_time_s"] == 1.0
    assert len(pd.read_parquet(out / "tables" / "poses.parquet")) > 0


def test_a_disk_that_fills_under_the_bag_mid_run_ends_the_run_keeping_what_ran(
    small_scenario, tmp_path
):
    out = tmp_path / "run"
    real_open = BagSink.open

    def open_on_a_filling_disk(self, *args, **kwargs):
        real_open(self, *args, **kwargs)
        store, calls = self._store, [0]

        def store_until_full(*stored):
            calls[0] += 1
            if calls[0] > 200:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            return store(*stored)

        self._store = store_until_full

    with (
        mock.patch.object(BagSink, "open", open_on_a_filling_disk),
        mock.patch.object(BagSink, "close"),  # the bag's end would not fit either
        pytest.raises(ExportError) as refused,
    ):
        cosim.run(small_scenario, out=out)
    said = str(refused.value)
    assert said.startswith(f"{out}/bag: cannot write the bag ([Errno 28] No space left on device)")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["failure"]["kind"] == "external" and 0 < summary["sim_time_s"] < 3.0
    assert said.endswith(
        f"the results of the {summary['sim_time_s']:g} s simulated are in {out}/ "
        '(summary.json says "failed")'
    )
    assert not (out / "failure.txt").exists()  # a full disk is no code's fault: no traceback


def test_a_scenario_read_with_a_plugins_section_it_cannot_load_is_not_run(tmp_path):
    path = tmp_path / "scenario.toml"
    path.write_text('[provenance]\ngone = "1.0"\n\n[odometer]\nevery = 2\n')
    scenario = cosim.load_scenario(path, reading=True)
    with pytest.raises(ConfigError, match=r"unknown section \[odometer\]: .*install gone 1\.0"):
        cosim.run(scenario, out=tmp_path / "run")
    assert not (tmp_path / "run").exists()
