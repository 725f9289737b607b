"""The pose sampler: every robot's ground truth in tables/poses at record.pose_rate_hz."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import cosim
from adapters.recording.poses import POSE_COLUMNS, POSES, PosesAdapter
from cosim.core.adapter import RunContext
from cosim.core.timebase import s_to_ns
from cosim.runner.assembly import assemble
from models.fleet.kinematics import FleetState
from tests.conftest import SMALL


def _sampled(duration_s: float, **overrides: Any) -> tuple[RunContext, PosesAdapter]:
    scenario = cosim.load_scenario("warehouse-random", {**SMALL, **overrides})
    assembly = assemble(scenario, names=["poses"])
    run = assembly.run
    fleet = run.service(FleetState)
    fleet.v_cmd[:] = 0.5
    fleet.w_cmd[:] = [0.0, 0.5, -0.5]
    for _name, adapter in assembly.adapters:
        adapter.start(run)
    run.kernel.run(s_to_ns(duration_s))
    return run, run.service(PosesAdapter)


def test_the_table_declares_every_column_with_its_unit_in_map():
    assert POSES.name == "poses"
    assert POSE_COLUMNS == ("t_s", "robot", "x_m", "y_m", "yaw_rad", "v_mps", "w_radps")
    assert "(m)" in POSES.columns["x_m"] and "map" in POSES.columns["x_m"]
    assert "(rad" in POSES.columns["yaw_rad"] and "(m/s)" in POSES.columns["v_mps"]
    assert set(POSES.categorical) <= set(POSES.columns) and POSES.volatile == ()
    assert PosesAdapter.tables == (POSES,)


def test_every_robot_is_sampled_from_time_0_at_the_pose_rate():
    run, _ = _sampled(0.55, **{"record.pose_rate_hz": 20.0})
    table = run.recorder.tables["poses"].columns()
    assert tuple(table) == POSE_COLUMNS
    times = np.unique(table["t_s"])
    assert times.tolist() == pytest.approx([k * 0.05 for k in range(11)])
    assert list(table["robot"][:3]) == ["robot_1", "robot_2", "robot_3"]
    assert len(table["t_s"]) == 3 * 11


def test_the_last_sample_is_the_fleets_ground_truth_then():
    run, _ = _sampled(1.0)
    fleet = run.service(FleetState)
    table = run.recorder.tables["poses"].columns()
    last = table["t_s"] == table["t_s"].max()
    assert table["t_s"].max() == pytest.approx(0.9)
    # the fleet moved on after the last sample: sampled values are copies, not views
    assert not np.array_equal(table["x_m"][last], fleet.x)
    assert table["v_mps"][last] == pytest.approx([0.5, 0.5, 0.5])
    assert table["w_radps"][last] == pytest.approx([0.0, 0.5, -0.5])
    mine = table["robot"] == "robot_1"
    steps = np.hypot(np.diff(table["x_m"][mine]), np.diff(table["y_m"][mine]))
    assert steps[-1] == pytest.approx(0.05)  # 0.5 m/s once accelerated: 5 cm a sample
    assert np.all(steps > 0)


def test_listeners_join_the_samplers_tick_after_each_sample():
    scenario = cosim.load_scenario("warehouse-random", SMALL)
    assembly = assemble(scenario, names=["poses"])
    run = assembly.run
    poses = run.service(PosesAdapter)
    heard: list[tuple[int, int]] = []
    poses.on_sample(lambda now: heard.append((now, len(run.recorder.tables["poses"]))))
    for _name, adapter in assembly.adapters:
        adapter.start(run)
    run.kernel.run(s_to_ns(0.35))
    assert heard == [(0, 3), (100_000_000, 6), (200_000_000, 9), (300_000_000, 12)]


def test_the_sampler_adds_nothing_to_the_summary():
    run, poses = _sampled(0.1)
    assert poses.finish(run) == {}
