"""The ``dwa`` local controller: the whole fleet's speeds and yaw rates in one call."""

from __future__ import annotations

import numpy as np
import pytest

from adapters.navigation.contract import CONTROLLERS, ControlInputs, ControllerContext
from adapters.navigation.local_control import DwaControl
from models.fleet.kinematics import DriveLimits
from models.navigation.dwa import DwaParams
from models.navigation.traffic import MovingPoints

LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)
NO_MOVING = MovingPoints(np.zeros(0, np.int64), np.zeros((0, 2)), np.zeros(0), np.zeros(0))


def _controller(n: int, control_hz: float = 10.0) -> DwaControl:
    context = ControllerContext(None, LIMITS, np.full(n, 0.33), control_hz)  # type: ignore[arg-type]
    return DwaControl(context)


def _inputs(
    pose: list[list[float]],
    carrots: list[list[float]],
    points: list[list[list[float]]] | None = None,
    vel: list[list[float]] | None = None,
) -> ControlInputs:
    n = len(pose)
    hits = points or [[] for _ in range(n)]
    start = np.cumsum([0, *(len(h) for h in hits)]).astype(np.int64)
    flat = np.array([p for h in hits for p in h], dtype=float).reshape(-1, 2)
    return ControlInputs(
        pose=np.array(pose, dtype=float),
        vel=np.array(vel or [[0.5, 0.0]] * n, dtype=float),
        carrots=np.array(carrots, dtype=float),
        goals=np.array(carrots, dtype=float) + 5.0 * np.array([[1.0, 0.0]] * n),
        points=flat,
        start=start,
        moving=NO_MOVING,
        discs=np.zeros((0, 3)),
        disc_start=np.zeros(n + 1, dtype=np.int64),
        now_ns=0,
    )


def test_dwa_is_the_registered_default_controller():
    assert CONTROLLERS.installed().get("dwa") is DwaControl


def test_the_controller_looks_one_control_period_ahead_and_keeps_its_margin():
    control = _controller(2, control_hz=20.0)
    assert control.params == DwaParams(control_period_s=0.05)
    assert control.footprint_padding_m == DwaParams().safety_margin_m == 0.1
    assert control.radii_m.tolist() == [0.33, 0.33]


def test_a_robot_heads_for_its_carrot_straight_ahead_left_or_right():
    control = _controller(3)
    v, w, blocked = control.commands(
        _inputs(
            pose=[[0.0, 0.0, 0.0], [0.0, 5.0, 0.0], [0.0, 10.0, 0.0]],
            carrots=[[1.0, 0.0], [1.0, 6.0], [1.0, 9.0]],
        )
    )
    assert not blocked.any()
    assert (v > 0).all() and (v <= LIMITS.max_speed_mps).all()
    assert abs(w[0]) < 0.3  # straight on
    assert w[1] > 0.3 and w[2] < -0.3  # left is counter-clockwise (REP 103)
    assert (np.abs(w) <= LIMITS.max_yaw_rate_radps).all()


def test_each_robot_keeps_clear_of_its_own_lidar_hits_only():
    control = _controller(2)
    wall = [[0.6, y] for y in np.arange(-1.0, 1.05, 0.05)]  # 0.6 m ahead of robot 0
    v, _, _ = control.commands(
        _inputs(
            pose=[[0.0, 0.0, 0.0], [0.0, 5.0, 0.0]],
            carrots=[[1.5, 0.0], [1.5, 5.0]],
            points=[wall, []],
            vel=[[0.0, 0.0], [0.0, 0.0]],
        )
    )
    assert v[0] < 0.1  # no way through the wall ahead
    assert v[1] > 0.1  # robot 1 sees nothing: it drives


def test_a_robot_boxed_in_finds_no_admissible_command_and_says_so():
    control = _controller(1)
    ring = [[0.45 * np.cos(a), 0.45 * np.sin(a)] for a in np.linspace(0, 2 * np.pi, 90)]
    v, _, blocked = control.commands(
        _inputs(pose=[[0.0, 0.0, 0.0]], carrots=[[2.0, 0.0]], points=[ring], vel=[[0.0, 0.0]])
    )
    assert blocked.tolist() == [True]
    assert v[0] == pytest.approx(0.0, abs=1e-9)


def test_the_commands_are_one_per_robot_and_the_same_for_the_same_inputs():
    control = _controller(4)
    inputs = _inputs(
        pose=[[0.0, 0.0, 0.0], [3.0, 0.0, 1.0], [6.0, 0.0, -1.0], [9.0, 0.0, 3.0]],
        carrots=[[1.0, 1.0], [3.0, 1.0], [7.0, -1.0], [8.0, 0.0]],
    )
    first, second = control.commands(inputs), control.commands(inputs)
    for a, b in zip(first, second, strict=True):
        assert a.shape == (4,)
        np.testing.assert_array_equal(a, b)
