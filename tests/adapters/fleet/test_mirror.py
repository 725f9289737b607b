import math

import numpy as np
import pytest

from adapters.fleet.mirror import Mirrors
from models.fleet.kinematics import DriveLimits, FleetState

LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)


def fleet() -> FleetState:
    starts = np.array([[1.0, 1.0, 0.0], [5.0, 5.0, 0.0]])
    state = FleetState(["robot_1", "robot_2"], starts, 0.3)
    state.v_cmd[:] = 1.0
    return state


def test_a_twin_goes_where_it_was_measured_and_its_velocity_explains_the_step():
    state = fleet()
    mirrors = Mirrors(state)
    mirrors.add(0)
    mirrors.set(0, 1.05, 1.0, 0.1)
    motion = state.propose(LIMITS, 0.05)
    mirrors.apply(motion, 0.05)
    state.commit(motion)
    assert (state.x[0], state.y[0], state.yaw[0]) == pytest.approx((1.05, 1.0, 0.1))
    assert state.v[0] == pytest.approx(1.0)
    assert state.w[0] == pytest.approx(2.0)
    assert state.x[1] > 5.0  # the other robot is integrated from its command


def test_a_twin_without_a_new_pose_stands_still_whatever_it_was_commanded():
    state = fleet()
    mirrors = Mirrors(state)
    mirrors.add(0)
    for _ in range(3):
        motion = state.propose(LIMITS, 0.05)
        mirrors.apply(motion, 0.05)
        state.commit(motion)
    assert (state.x[0], state.y[0]) == (1.0, 1.0)
    assert state.v[0] == 0.0


def test_a_pose_is_applied_once_then_the_twin_holds_it():
    state = fleet()
    mirrors = Mirrors(state)
    mirrors.add(0)
    mirrors.set(0, 1.1, 1.2, math.pi)
    for _ in range(2):
        motion = state.propose(LIMITS, 0.05)
        mirrors.apply(motion, 0.05)
        state.commit(motion)
    assert (state.x[0], state.y[0]) == pytest.approx((1.1, 1.2))
    assert state.v[0] == 0.0 and state.w[0] == 0.0


def test_setting_the_pose_of_a_robot_that_is_not_mirrored_is_refused():
    mirrors = Mirrors(fleet())
    with pytest.raises(ValueError, match="robot_2 is not mirrored"):
        mirrors.set(1, 0.0, 0.0, 0.0)
