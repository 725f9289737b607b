"""The ``orca`` local controller: settings, the heard neighbours, and real runs."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pytest

import cosim
from adapters.navigation.contract import CONTROLLERS, ControlInputs, ControllerContext
from adapters.navigation.orca import Orca, OrcaSettings
from cosim.core.errors import ConfigError
from cosim.testing import assert_no_collisions, assert_same_run, run_scenario
from models.fleet.kinematics import DriveLimits
from models.navigation.traffic import MovingPoints

LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)
NO_MOVING = MovingPoints(np.zeros(0, np.int64), np.zeros((0, 2)), np.zeros(0), np.zeros(0))
ORCA = {"navigation.controller": "orca"}


class _Run:
    """A run that only has settings."""

    def __init__(self, settings: OrcaSettings) -> None:
        self._settings = settings

    def settings(self, kind: type[Any]) -> Any:
        assert kind is OrcaSettings
        return self._settings


def _controller(n: int, settings: OrcaSettings | None = None, control_hz: float = 10.0) -> Orca:
    run = _Run(settings or OrcaSettings())
    return Orca(ControllerContext(run, LIMITS, np.full(n, 0.33), control_hz))  # type: ignore[arg-type]


def _head_on(neighbours: np.ndarray | None) -> ControlInputs:
    """Robot 0 at the origin driving +x at 1 m/s towards a carrot 10 m ahead; it heard of a
    robot 5 m ahead; robot 1 far off hears of none."""
    extra = {} if neighbours is None else {"neighbours": neighbours}
    return ControlInputs(
        pose=np.array([[0.0, 0.0, 0.0], [0.0, 20.0, 0.0]]),
        vel=np.array([[1.0, 0.0], [0.0, 0.0]]),
        carrots=np.array([[10.0, 0.0], [10.0, 20.0]]),
        goals=np.array([[10.0, 0.0], [10.0, 20.0]]),
        points=np.zeros((0, 2)),
        start=np.zeros(3, dtype=np.int64),
        moving=NO_MOVING,
        discs=np.array([[5.0, 0.0, 0.33]]),
        disc_start=np.array([0, 1, 1], dtype=np.int64),
        now_ns=0,
        **extra,
    )


def test_orca_is_a_registered_controller_with_its_own_section():
    assert CONTROLLERS.installed().get("orca") is Orca
    assert cosim.load_scenario("warehouse-random", ORCA).section(OrcaSettings) == OrcaSettings()


def test_the_settings_reach_the_model_and_the_margin_pads_the_planners_paths():
    control = _controller(2, OrcaSettings(margin_m=0.2, time_horizon_s=3.0), control_hz=20.0)
    assert control.params.margin_m == control.footprint_padding_m == 0.2
    assert control.params.time_horizon_s == 3.0
    assert control.params.control_period_s == 0.05
    assert control.params.obstacle_sectors == OrcaSettings().obstacle_sectors


@pytest.mark.parametrize(
    ("key", "value"),
    [("margin_m", -0.1), ("time_horizon_s", 0), ("obstacle_sectors", 2), ("heading_gain", 0)],
)
def test_bad_settings_are_refused_naming_the_key(key, value):
    with pytest.raises(ConfigError, match=f"orca.*{key}"):
        cosim.load_scenario("warehouse-random", {**ORCA, f"orca.{key}": value})


def test_a_robot_heard_of_without_news_of_its_motion_is_avoided_as_standing():
    control = _controller(2)
    v, w, blocked = control.commands(_head_on(None))
    standing = np.array([[5.0, 0.0, 0.0, 0.0, 0.0]])
    assert [a.tolist() for a in (v, w, blocked)] == [
        a.tolist() for a in control.commands(_head_on(standing))
    ]
    assert not blocked.any()


def test_news_of_a_robot_coming_head_on_two_seconds_old_makes_the_robot_give_way():
    control = _controller(2)
    fresh = control.commands(_head_on(np.array([[5.0, 0.0, -1.0, 0.0, 0.0]])))
    aged = control.commands(_head_on(np.array([[5.0, 0.0, -1.0, 0.0, 2.0]])))
    assert fresh[1][0] == pytest.approx(0.0) and fresh[0][0] == pytest.approx(1.0)
    assert aged[1][0] < -0.1  # it now sees the robot 3 m ahead: it turns right
    blind = _controller(2, OrcaSettings(extrapolate=False))
    np.testing.assert_array_equal(
        blind.commands(_head_on(np.array([[5.0, 0.0, -1.0, 0.0, 2.0]])))[1], fresh[1]
    )
    assert aged[1][1] == fresh[1][1] == 0.0  # robot 1 heard of nobody: straight to its carrot


def test_commands_are_one_per_robot_within_the_limits():
    v, w, blocked = _controller(2).commands(_head_on(np.array([[5.0, 0.0, -1.0, 0.0, 1.0]])))
    assert v.shape == w.shape == blocked.shape == (2,)
    assert blocked.dtype == bool
    assert ((v >= 0) & (v <= LIMITS.max_speed_mps)).all()
    assert (np.abs(w) <= LIMITS.max_yaw_rate_radps).all()


def test_robots_reach_their_goals_in_the_warehouse_for_60_s_without_touching_anything():
    result = run_scenario("warehouse-random", ORCA, duration_s=60)
    assert_no_collisions(result)
    assert result.summary["arrivals"] >= 8
    assert result.summary["controller_commands_clipped"] == 0


def test_with_the_robots_layer_over_a_slow_network_robots_still_never_touch():
    overrides = {**ORCA, "navigation.robots_layer": True, "network.latency_ms": 150.0}
    result = run_scenario("warehouse-random", overrides, duration_s=60)
    assert_no_collisions(result)
    assert result.summary["arrivals"] >= 8
    assert result.summary["latency_ms_p50"] == pytest.approx(150.0)


def test_the_same_seed_gives_the_same_tables_whatever_the_threads():
    overrides = {**ORCA, "navigation.robots_layer": True, "robots.count": 8, "tasks.initial": 8}
    scenario = cosim.load_scenario("warehouse-random", overrides)
    first = cosim.run(scenario, seed=4, duration_s=30, threads=2)
    second = cosim.run(scenario, seed=4, duration_s=30, threads=1)
    assert_same_run(first, second)
    assert len(first.tables["poses"]) > 0


def test_settings_are_documented_with_units():
    for field in dataclasses.fields(OrcaSettings):
        assert field.metadata["doc"], field.name
