"""What every batched controller checks and packs: fleet rows, CSR offsets, limits, parameters."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.errors import ModelError
from models.fleet.kinematics import DriveLimits
from models.navigation.dwa import DwaParams
from models.navigation.fleet_inputs import (
    check_limits,
    decide_sliced,
    fleet_rows,
    offsets,
    packed,
    points,
)

LIMITS = DriveLimits(1.0, 0.3, 2.0, 2.0, 3.0)


def test_the_fleet_rows_are_pose_velocity_radius_carrot_and_goal_side_by_side():
    rows = fleet_rows(
        np.array([[1.0, 2.0, 0.5]]),
        np.array([[0.3, -0.1]]),
        np.array([0.33]),
        np.array([[4.0, 5.0]]),
        np.array([[6.0, 7.0]]),
    )
    assert rows.flags.c_contiguous and rows.dtype == np.float64
    np.testing.assert_array_equal(rows, [[1.0, 2.0, 0.5, 0.3, -0.1, 0.33, 4.0, 5.0, 6.0, 7.0]])


def test_an_array_of_the_wrong_shape_is_refused_by_name():
    good = {
        "poses": np.zeros((2, 3)),
        "velocities": np.zeros((2, 2)),
        "radius_m": np.zeros(2),
        "carrots": np.zeros((2, 2)),
        "goals": np.zeros((2, 2)),
    }
    for name in good:
        bad = {**good, name: np.zeros((2, 7))}
        with pytest.raises(ValueError, match=rf"^{name} must be \(2"):
            fleet_rows(**bad)


@settings(max_examples=80, deadline=None)
@given(st.lists(st.integers(-3, 8), max_size=6), st.integers(0, 4), st.integers(0, 6))
def test_offsets_are_refused_unless_they_rise_from_0_to_the_rows(start, count, items):
    ok = len(start) == count + 1 and start[:1] == [0] and start[-1:] == [items]
    ok = ok and all(b >= a for a, b in itertools.pairwise(start))
    if ok:
        np.testing.assert_array_equal(offsets(np.array(start), count, items, "s"), start)
    else:
        with pytest.raises(ValueError, match=r"^s must "):
            offsets(np.array(start, dtype=np.int64), count, items, "s")


def test_points_are_contiguous_rows_of_their_width():
    rows = points([1, 2, 3, 4], 2)
    assert rows.shape == (2, 2) and rows.dtype == np.float64 and rows.flags.c_contiguous
    assert points(np.zeros((0, 3)), 3).shape == (0, 3)


def test_limits_a_kernel_divides_by_must_be_positive_and_are_named():
    check_limits(LIMITS, "max_accel_mps2")
    with pytest.raises(ModelError, match=r"robots\.max_speed_mps"):
        check_limits(DriveLimits(0.0, 0.3, 2.0, 2.0, 3.0))
    with pytest.raises(ModelError, match=r"robots\.max_yaw_accel_radps2"):
        check_limits(DriveLimits(1.0, 0.3, 2.0, 2.0, 0.0), "max_yaw_accel_radps2")


def test_the_packed_parameters_are_the_fields_then_the_limits_built_once():
    vector = packed(DwaParams(), LIMITS)
    assert vector[0] == DwaParams().sim_time_s and vector[-1] == LIMITS.max_yaw_accel_radps2
    assert packed(DwaParams(), LIMITS) is vector  # frozen parameters: built once


def test_a_sliced_decision_hands_each_slice_its_rows_and_absolute_offsets():
    seen = []

    def kernel(rows, hits, hit_start, others, other_start, config, out):
        seen.append((rows[:, 0].tolist(), hit_start.tolist(), other_start.tolist()))
        out[:, 0] = rows[:, 0] * 10

    rows = np.arange(3.0).reshape(3, 1)
    out = np.zeros((3, 1))

    def two_slices(n, decide):
        decide(0, 2)
        decide(2, n)

    decide_sliced(
        kernel,
        two_slices,
        rows,
        np.zeros((4, 2)),
        np.array([0, 1, 3, 4]),
        np.zeros((0, 3)),
        np.zeros(4, dtype=np.int64),
        np.zeros(1),
        out,
    )
    assert seen == [([0.0, 1.0], [0, 1, 3], [0, 0, 0]), ([2.0], [3, 4], [0, 0])]
    np.testing.assert_array_equal(out[:, 0], [0.0, 10.0, 20.0])
