import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.mocap.gate import PoseGate, stale

GATE = PoseGate(max_speed_mps=1.0, max_yaw_rate_radps=2.0, tolerance_m=0.05, tolerance_rad=0.1)
# no tolerance: the drivable distance is the whole limit (0.5 s at 1 m/s is exactly 0.5 m)
STRICT = PoseGate(max_speed_mps=1.0, max_yaw_rate_radps=2.0, tolerance_m=0.0, tolerance_rad=0.0)
EPOCH_NS = 1_700_000_000_123_456_789  # a wall-clock stamp: too large for float64 to hold exactly
MS = 1_000_000


def check(gate, last, last_ns, new, new_ns, has_last=True):
    """The array gate on one pose; returns the verdict as check_one spells it."""
    result = gate.check(
        np.array([last], dtype=float),
        np.array([last_ns], dtype=np.int64),
        np.array([new], dtype=float),
        np.array([new_ns], dtype=np.int64),
        np.array([has_last]),
    )
    assert result.accepted[0] + result.jump[0] + result.out_of_order[0] == 1
    return "ok" if result.accepted[0] else "jump" if result.jump[0] else "out_of_order"


def verdicts(gate, last, last_ns, new, new_ns):
    """(array gate, one-pose gate), which must agree."""
    one = gate.check_one(last, last_ns, new, new_ns)
    array = check(gate, last or (0.0, 0.0, 0.0), last_ns, new, new_ns, last is not None)
    return array, one


def test_a_pose_moved_at_exactly_the_top_speed_is_accepted():
    last = (2.0, -1.0, 0.0)
    assert verdicts(STRICT, last, EPOCH_NS, (2.5, -1.0, 0.0), EPOCH_NS + 500 * MS) == ("ok", "ok")
    assert verdicts(STRICT, last, EPOCH_NS, (2.0, -1.0, 1.0), EPOCH_NS + 500 * MS) == ("ok", "ok")
    diagonal = (2.0 + 0.3, -1.0 - 0.4, 0.0)  # 0.5 m along a 3-4-5 diagonal
    assert verdicts(STRICT, last, 0, diagonal, 500 * MS) == ("ok", "ok")


def test_a_pose_a_hair_beyond_the_top_speed_is_a_jump():
    last = (2.0, -1.0, 0.0)
    beyond = (2.5 + 1e-9, -1.0, 0.0)
    assert verdicts(STRICT, last, EPOCH_NS, beyond, EPOCH_NS + 500 * MS) == ("jump", "jump")
    assert verdicts(STRICT, last, 0, (2.0, -1.0, 1.001), 500 * MS) == ("jump", "jump")


def test_a_one_metre_jump_ten_milliseconds_later_is_rejected_as_a_jump():
    result = GATE.check(
        np.array([[1.0, 1.0, 0.0], [1.0, 1.0, 0.0]]),
        np.array([EPOCH_NS, EPOCH_NS]),
        np.array([[2.0, 1.0, 0.0], [1.005, 1.0, 0.0]]),
        np.array([EPOCH_NS + 10 * MS, EPOCH_NS + 10 * MS]),
        np.array([True, True]),
    )
    assert result.accepted.tolist() == [False, True]
    assert result.jump.tolist() == [True, False]
    assert result.out_of_order.tolist() == [False, False]
    assert GATE.check_one((1.0, 1.0, 0.0), EPOCH_NS, (2.0, 1.0, 0.0), EPOCH_NS + 10 * MS) == "jump"


@pytest.mark.parametrize("new_ns", [EPOCH_NS, EPOCH_NS - 1, EPOCH_NS - 10 * MS])
def test_a_pose_stamped_at_or_before_the_last_is_out_of_order(new_ns):
    result = GATE.check(
        np.array([[1.0, 1.0, 0.0]]),
        np.array([EPOCH_NS]),
        np.array([[1.0, 1.0, 0.0]]),
        np.array([new_ns]),
        np.array([True]),
    )
    assert result.out_of_order.tolist() == [True]
    assert result.accepted.tolist() == [False] and result.jump.tolist() == [False]
    assert GATE.check_one((1.0, 1.0, 0.0), EPOCH_NS, (1.0, 1.0, 0.0), new_ns) == "out_of_order"


def test_a_pose_one_nanosecond_after_the_last_is_in_order():
    assert verdicts(GATE, (1.0, 1.0, 0.0), EPOCH_NS, (1.0, 1.0, 0.0), EPOCH_NS + 1) == ("ok", "ok")


def test_a_robot_without_a_last_pose_accepts_any_pose_at_any_stamp():
    assert verdicts(GATE, None, EPOCH_NS, (900.0, -900.0, 3.0), 0) == ("ok", "ok")


def test_turning_through_pi_is_a_small_turn():
    last, new = (0.0, 0.0, 3.1), (0.0, 0.0, -3.1)  # 0.083 rad apart, not 6.2
    assert verdicts(GATE, last, 0, new, 1 * MS) == ("ok", "ok")
    assert verdicts(GATE, new, 0, last, 1 * MS) == ("ok", "ok")
    assert verdicts(GATE, (0.0, 0.0, 3.1), 0, (0.0, 0.0, 0.0), 1 * MS) == ("jump", "jump")


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_a_pose_that_is_not_a_number_is_never_accepted(bad, axis):
    new = [1.0, 1.0, 0.0]
    new[axis] = bad
    pose = (new[0], new[1], new[2])
    assert verdicts(GATE, (1.0, 1.0, 0.0), 0, pose, 10 * MS) == ("jump", "jump")
    assert verdicts(GATE, None, 0, pose, 10 * MS) == ("jump", "jump")
    assert verdicts(GATE, (1.0, 1.0, 0.0), 10 * MS, pose, 0) == ("jump", "jump")


def test_a_pose_is_stale_only_once_it_is_older_than_the_limit_to_the_nanosecond():
    max_age = 250 * MS
    stamps = np.array([EPOCH_NS, EPOCH_NS - 1, EPOCH_NS + 1, EPOCH_NS], dtype=np.int64)
    has = np.array([True, True, True, False])
    now = EPOCH_NS + max_age
    assert stale(stamps, now, max_age, has).tolist() == [False, True, False, True]
    assert stale(stamps, now + 1, max_age, has).tolist() == [True, True, False, True]
    assert stale(stamps, now + 2, max_age, has).tolist() == [True, True, True, True]


def test_a_robot_without_any_pose_is_stale_even_at_time_zero():
    assert stale(np.zeros(2, dtype=np.int64), 0, 10**9, np.array([False, True])).tolist() == [
        True,
        False,
    ]


COORD = st.floats(-1e3, 1e3) | st.sampled_from([math.nan, math.inf, -math.inf])
YAW = st.floats(-10.0, 10.0) | st.sampled_from([math.nan, math.inf])
POSE = st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3), st.floats(-math.pi, math.pi))
LIMITS = st.builds(
    PoseGate,
    max_speed_mps=st.floats(0.0, 5.0),
    max_yaw_rate_radps=st.floats(0.0, 10.0),
    tolerance_m=st.floats(0.0, 1.0),
    tolerance_rad=st.floats(0.0, 1.0),
)


@settings(max_examples=300, deadline=None)
@given(
    gate=LIMITS,
    last=POSE,
    new=st.tuples(COORD, COORD, YAW),
    last_ns=st.integers(0, 2**62),
    dt_ns=st.integers(-(10**9), 10 * 10**9),
)
def test_an_accepted_pose_never_lies_beyond_what_the_robot_can_drive(
    gate, last, new, last_ns, dt_ns
):
    array, one = verdicts(gate, last, last_ns, new, last_ns + dt_ns)
    assert array == one
    if one == "ok":
        dt_s = dt_ns / 1e9
        assert all(math.isfinite(v) for v in new) and dt_ns > 0
        moved = math.hypot(new[0] - last[0], new[1] - last[1])
        assert moved <= gate.max_speed_mps * dt_s + gate.tolerance_m + 1e-9
        turned = abs(math.remainder(new[2] - last[2], 2 * math.pi))
        assert turned <= gate.max_yaw_rate_radps * dt_s + gate.tolerance_rad + 1e-9
