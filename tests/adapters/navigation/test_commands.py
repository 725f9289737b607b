"""A local controller's commands at the boundary: refused when cosim cannot drive them, clipped
to the drive limits and counted when they ask too much."""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import cosim
from adapters.navigation.commands import checked_commands
from adapters.navigation.contract import ControlInputs, ControllerContext
from cosim.core.plugins import PluginError
from cosim.core.registry import registered
from models.fleet.kinematics import DriveLimits
from tests.conftest import SMALL

LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)
NAMES = ["robot_1", "robot_2", "robot_3"]


class Scripted:
    """A controller handing back whatever ``answer(n)`` makes (one class per case below)."""

    name: ClassVar[str] = "scripted"

    def __init__(self, context: ControllerContext) -> None:
        self.n = len(context.radii_m)

    def answer(self, n: int) -> Any:
        return np.zeros(n), np.zeros(n), np.zeros(n, dtype=bool)

    def commands(self, inputs: ControlInputs) -> Any:
        return self.answer(self.n)


def _run(controller: type[Scripted], **more: Any) -> cosim.RunResult:
    overrides = {
        **SMALL,
        "robots.driver": "navigation",
        "navigation.controller": controller.name,
        "scenario.duration_s": 2.0,
        **more,
    }
    with registered("cosim.controllers", controller.name, controller):
        return cosim.run(cosim.load_scenario("warehouse-random", overrides))


def _refusal(controller: type[Scripted]) -> str:
    with pytest.raises(PluginError) as caught:
        _run(controller)
    error = caught.value
    assert error.plugin is not None and error.plugin.name == controller.name
    assert "computing the robots' commands" in error.doing
    return str(error)


class NotANumber(Scripted):
    name: ClassVar[str] = "not_a_number"

    def answer(self, n: int) -> Any:
        v, w, blocked = super().answer(n)
        w[1] = np.nan
        return v, w, blocked


class Infinite(Scripted):
    name: ClassVar[str] = "infinite"

    def answer(self, n: int) -> Any:
        v, w, blocked = super().answer(n)
        v[2] = np.inf
        return v, w, blocked


class OneShort(Scripted):
    name: ClassVar[str] = "one_short"

    def answer(self, n: int) -> Any:
        return np.zeros(n - 1), np.zeros(n), np.zeros(n, dtype=bool)


class Strings(Scripted):
    name: ClassVar[str] = "strings"

    def answer(self, n: int) -> Any:
        return np.zeros(n), np.array(["left"] * n), np.zeros(n, dtype=bool)


class Lists(Scripted):
    name: ClassVar[str] = "lists"

    def answer(self, n: int) -> Any:
        return [0.1] * n, np.zeros(n), np.zeros(n, dtype=bool)


class TwoArrays(Scripted):
    name: ClassVar[str] = "two_arrays"

    def answer(self, n: int) -> Any:
        return np.zeros(n), np.zeros(n)


class IntBlocked(Scripted):
    name: ClassVar[str] = "int_blocked"

    def answer(self, n: int) -> Any:
        return np.zeros(n), np.zeros(n), np.zeros(n, dtype=np.int64)


def test_a_controller_returning_nan_is_refused_naming_it_the_robot_and_the_value():
    line = _refusal(NotANumber)
    assert line.startswith("local controller 'not_a_number' (")
    assert "given in code" in line
    assert "returned yaw rate nan for 'robot_2'; expected a finite number (rad/s)" in line


def test_a_controller_returning_an_infinite_speed_is_refused_naming_the_robot():
    assert "returned speed inf for 'robot_3'; expected a finite number (m/s)" in _refusal(Infinite)


@pytest.mark.parametrize(
    ("controller", "said"),
    [
        (OneShort, "returned speeds v (m/s) of shape (2,); expected (3,), one per robot"),
        (Strings, "returned yaw rates w (rad/s) of dtype <U4; expected real numbers (float)"),
        (Lists, "returned speeds v (m/s) as a list of 3; expected a numpy array of shape (3,)"),
        (TwoArrays, "returned a tuple of 2; expected a tuple (v, w, blocked) of three arrays"),
        (IntBlocked, "returned blocked of dtype int64; expected bool, one per robot"),
    ],
)
def test_commands_of_the_wrong_shape_or_type_are_refused_saying_what_was_expected(
    controller: type[Scripted], said: str
):
    line = _refusal(controller)
    assert line.startswith(f"local controller {controller.name!r} (")
    assert said in line


class Reckless(Scripted):
    """Full speed ahead and spinning, far beyond any robot's limits."""

    name: ClassVar[str] = "reckless"

    def answer(self, n: int) -> Any:
        return np.full(n, 50.0), np.full(n, -9.0), np.zeros(n, dtype=bool)


def test_commands_beyond_the_drive_limits_are_clipped_and_counted_in_the_summary():
    result = _run(Reckless, **{"navigation.control_hz": 10.0})
    robots = SMALL["robots.count"]
    # every robot's command of every tick in 2 s at 10 Hz (the first at t = 0)
    assert result.summary["controller_commands_clipped"] == robots * 20


def test_the_built_in_controller_needs_no_clipping():
    result = cosim.run(
        cosim.load_scenario("warehouse-random", {**SMALL, "robots.driver": "navigation"})
    )
    assert result.summary["controller_commands_clipped"] == 0


# -- the check itself ------------------------------------------------------------------------
def test_commands_within_the_limits_come_back_as_they_were():
    v, w = np.array([0.5, -0.3, 1.0]), np.array([2.0, -2.0, 0.0])
    blocked = np.array([False, True, False])
    checked = checked_commands(Scripted, (v, w, blocked), NAMES, LIMITS)
    assert checked.v is v and checked.w is w and checked.blocked is blocked
    assert checked.clipped == 0


def test_integer_speeds_are_taken_as_floats():
    checked = checked_commands(
        Scripted, (np.array([1, 0, 0]), np.zeros(3), np.zeros(3, dtype=bool)), NAMES, LIMITS
    )
    assert checked.v.dtype == np.float64 and checked.v.tolist() == [1.0, 0.0, 0.0]


def test_only_the_robots_beyond_a_limit_are_counted_and_each_value_is_clipped_to_its_own():
    v = np.array([1.5, -0.5, 0.2])
    w = np.array([0.0, 0.0, 2.5])
    checked = checked_commands(Scripted, (v, w, np.zeros(3, dtype=bool)), NAMES, LIMITS)
    assert checked.clipped == 3
    assert checked.v.tolist() == [1.0, -0.3, 0.2]
    assert checked.w.tolist() == [0.0, 0.0, 2.0]
    assert v.tolist() == [1.5, -0.5, 0.2]  # the controller's own arrays are left alone


def test_an_empty_fleet_has_nothing_to_clip():
    empty = (np.zeros(0), np.zeros(0), np.zeros(0, dtype=bool))
    assert checked_commands(Scripted, empty, [], LIMITS).clipped == 0


FINITE = st.floats(-1e6, 1e6, allow_nan=False)


@settings(max_examples=60, deadline=None)
@given(
    hnp.arrays(np.float64, 3, elements=FINITE),
    hnp.arrays(np.float64, 3, elements=FINITE),
)
def test_any_finite_commands_come_back_within_the_limits_with_the_clipped_ones_counted(v, w):
    checked = checked_commands(Scripted, (v, w, np.zeros(3, dtype=bool)), NAMES, LIMITS)
    assert ((checked.v <= 1.0) & (checked.v >= -0.3)).all()
    assert (np.abs(checked.w) <= 2.0).all()
    changed = (checked.v != v) | (checked.w != w)
    assert checked.clipped == int(changed.sum())


@settings(max_examples=60, deadline=None)
@given(
    hnp.arrays(np.float64, 3, elements=FINITE),
    st.sets(st.integers(0, 2), min_size=1),
    st.sampled_from([np.nan, np.inf, -np.inf]),
)
def test_any_speed_that_is_not_finite_is_refused_naming_its_robot(v, bad, value):
    v[sorted(bad)] = value
    with pytest.raises(PluginError) as caught:
        checked_commands(Scripted, (v, np.zeros(3), np.zeros(3, dtype=bool)), NAMES, LIMITS)
    first = min(bad)
    assert f"returned speed {value} for {NAMES[first]!r}" in str(caught.value)
