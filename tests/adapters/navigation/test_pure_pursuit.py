"""The ``rpp`` local controller: settings, one call for the fleet, real runs."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest

from adapters.navigation.contract import CONTROLLERS, ControlInputs, ControllerContext
from adapters.navigation.pure_pursuit import RegulatedPurePursuit, RppSettings
from cosim.core.errors import ConfigError
from cosim.scenario import load_scenario
from cosim.scenario.model import section_registry
from cosim.testing import SMALL_WAREHOUSE, assert_no_collisions, assert_same_run, run_scenario
from models.fleet.kinematics import DriveLimits
from models.navigation.pure_pursuit import RppParams
from models.navigation.traffic import MovingPoints

LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)
NO_MOVING = MovingPoints(np.zeros(0, np.int64), np.zeros((0, 2)), np.zeros(0), np.zeros(0))
RPP = {"navigation.controller": "rpp"}


def _controller(n: int, settings: RppSettings | None = None, hz: float = 10.0) -> Any:
    run: Any = SimpleNamespace(settings=lambda kind: settings or kind())
    return RegulatedPurePursuit(ControllerContext(run, LIMITS, np.full(n, 0.33), hz))


def _inputs(pose: list[list[float]], carrots: list[list[float]], points: Any = None) -> Any:
    n = len(pose)
    hits = points or [[] for _ in range(n)]
    start = np.cumsum([0, *(len(h) for h in hits)]).astype(np.int64)
    return ControlInputs(
        pose=np.array(pose, dtype=float),
        vel=np.full((n, 2), [0.5, 0.0]),
        carrots=np.array(carrots, dtype=float),
        goals=np.array(carrots, dtype=float) + 10.0,
        points=np.array([p for h in hits for p in h], dtype=float).reshape(-1, 2),
        start=start,
        moving=NO_MOVING,
        discs=np.zeros((0, 3)),
        disc_start=np.zeros(n + 1, dtype=np.int64),
        now_ns=0,
    )


def test_rpp_is_registered_with_its_settings_section():
    assert CONTROLLERS.installed().get("rpp") is RegulatedPurePursuit
    assert section_registry().get("rpp") is RppSettings


def test_the_settings_reach_the_kernel_and_the_planner_gets_the_padding():
    settings = RppSettings(desired_speed_mps=0.7, collision_margin_m=0.02, footprint_padding_m=0.2)
    control = _controller(2, settings, hz=20.0)
    assert control.params.control_period_s == pytest.approx(0.05)
    assert control.params.desired_speed_mps == 0.7
    assert control.params.collision_margin_m == 0.02
    assert control.footprint_padding_m == 0.2
    kernel = {f.name for f in dataclasses.fields(RppParams)} - {"control_period_s"}
    assert kernel | {"footprint_padding_m"} == {f.name for f in dataclasses.fields(RppSettings)}


def test_the_defaults_are_the_kernels():
    params = _controller(1).params
    assert dataclasses.replace(params, control_period_s=0.1) == RppParams()


def test_one_call_commands_every_robot_each_against_its_own_hits():
    wall = [[1.0, y] for y in np.arange(-1.0, 1.01, 0.02)]  # 1 m ahead of robot 0
    v, w, blocked = _controller(3).commands(
        _inputs(
            pose=[[0.0, 0.0, 0.0], [0.0, 5.0, 0.0], [0.0, 10.0, 0.0]],
            carrots=[[1.5, 0.0], [1.0, 5.0], [-1.0, 10.0]],
            points=[wall, [], []],
        )
    )
    assert blocked.tolist() == [True, False, False]
    assert v[0] == 0.0 and v[1] > 0.5  # robot 1 sees nothing and drives on
    assert v[2] < v[1] and w[2] > 0.0  # robot 2's carrot is behind: it turns on the spot
    assert all(a.shape == (3,) for a in (v, w, blocked))


@pytest.mark.parametrize(
    ("key", "value"),
    [("collision_time_s", 0), ("proximity_gain", 2), ("footprint_padding_m", -0.1)],
)
def test_a_bad_setting_is_refused_naming_it(key, value):
    with pytest.raises(ConfigError, match=f"rpp.*{key}"):
        load_scenario("warehouse-random", {**RPP, f"rpp.{key}": value})


def test_robots_reach_their_goals_in_the_warehouse_without_touching_anything():
    result = run_scenario("warehouse-random", RPP, duration_s=60)
    assert_no_collisions(result)
    assert result.summary["arrivals"] >= 8
    assert result.summary["controller_commands_clipped"] == 0
    poses = result.tables["poses"]
    assert poses["v_mps"].max() == pytest.approx(LIMITS.max_speed_mps)  # full speed somewhere


def test_the_same_seed_gives_the_same_tables():
    overrides = {**SMALL_WAREHOUSE, "robots.driver": "navigation", **RPP}
    first = run_scenario("warehouse-random", overrides, duration_s=30, seed=4)
    second = run_scenario("warehouse-random", overrides, duration_s=30, seed=4)
    assert first.summary["arrivals"] >= 2
    assert_same_run(first, second)
