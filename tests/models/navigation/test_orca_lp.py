"""ORCA's linear programs: the velocity nearest a preferred one within half-planes."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from models.navigation.orca_lp import det, det_py, lp2, lp2_py, lp3


def _line(px: float, py: float, dx: float, dy: float) -> list[float]:
    """A half-plane: allowed to the left of direction (dx, dy) through (px, py)."""
    norm = float(np.hypot(dx, dy))
    return [px, py, dx / norm, dy / norm]


def test_the_cross_product_is_positive_when_b_lies_left_of_a():
    assert det_py(1.0, 0.0, 0.0, 1.0) == 1.0 and det(1.0, 0.0, 0.0, -1.0) == -1.0


def test_a_preferred_velocity_inside_every_half_plane_is_kept():
    lines = np.array([_line(0.0, -1.0, 1.0, 0.0)])  # allowed: y >= -1
    res = np.zeros(2)
    assert lp2(lines, 1, 2.0, 0.5, 0.2, False, res) == 1
    np.testing.assert_allclose(res, [0.5, 0.2])


def test_a_preferred_velocity_outside_is_projected_onto_the_nearest_boundary():
    lines = np.array([_line(0.0, 0.5, 1.0, 0.0)])  # allowed: y >= 0.5
    res = np.zeros(2)
    assert lp2(lines, 1, 2.0, 1.0, 0.0, False, res) == 1
    np.testing.assert_allclose(res, [1.0, 0.5], atol=1e-12)


def test_a_velocity_beyond_the_speed_disc_is_cut_to_it():
    res = np.zeros(2)
    assert lp2(np.zeros((0, 4)), 0, 1.0, 3.0, 4.0, False, res) == 0
    np.testing.assert_allclose(res, [0.6, 0.8])


def test_without_a_feasible_velocity_the_least_violating_one_is_found():
    # y >= 0.5 and y <= -0.5 cannot both hold: the best violates each by 0.5
    lines = np.array([_line(0.0, 0.5, 1.0, 0.0), _line(0.0, -0.5, -1.0, 0.0)])
    res = np.zeros(2)
    failed = lp2(lines, 2, 2.0, 0.0, 0.0, False, res)
    assert failed == 1
    lp3(lines, 2, 0, failed, 2.0, res, np.empty((2, 4)))
    assert res[1] == pytest.approx(0.0, abs=1e-9)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(
        st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-np.pi, np.pi)),
        min_size=1,
        max_size=6,
    ),
    st.floats(-2, 2),
    st.floats(-2, 2),
)
def test_the_compiled_program_agrees_with_python_and_its_answer_meets_the_lines(lines, ox, oy):
    table = np.array([_line(px, py, np.cos(a), np.sin(a)) for px, py, a in lines])
    fast, slow = np.zeros(2), np.zeros(2)
    done_fast = lp2(table, len(table), 2.0, ox, oy, False, fast)
    done_slow = lp2_py(table, len(table), 2.0, ox, oy, False, slow)
    assert done_fast == done_slow
    np.testing.assert_allclose(fast, slow, atol=1e-9)
    if done_fast == len(table):  # feasible: every half-plane holds, within the disc
        for px, py, dx, dy in table:
            assert det_py(dx, dy, px - fast[0], py - fast[1]) <= 1e-9
        assert np.hypot(*fast) <= 2.0 + 1e-9
