"""One damped Gauss-Newton step: the solution of the normal equations, kept within a cell."""

import numpy as np
import pytest

from models.mapping.gauss_newton import MAX_TURN_RAD, levenberg_step, within_cell


def test_an_undamped_step_solves_the_normal_equations():
    h = np.array([[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]])
    b = np.array([1.0, -2.0, 0.5])
    dx, dy, dt, ok = levenberg_step(
        h[0, 0], h[0, 1], h[0, 2], h[1, 1], h[1, 2], h[2, 2], *b, 0.0, 0.0, 1e-12
    )
    assert ok and np.allclose([dx, dy, dt], np.linalg.solve(h, b))


def test_damping_shortens_the_step_and_a_singular_system_gives_none():
    h = (2.0, 0.0, 0.0, 2.0, 0.0, 2.0)
    free = levenberg_step(*h, 1.0, 1.0, 1.0, 0.0, 0.0, 1e-12)
    damped = levenberg_step(*h, 1.0, 1.0, 1.0, 0.5, 0.0, 1e-12)
    assert free[:3] == pytest.approx((0.5, 0.5, 0.5)) and damped[:3] == pytest.approx((0.2,) * 3)
    assert levenberg_step(*(0.0,) * 9, 0.0, 0.0, 1e-12) == (0.0, 0.0, 0.0, False)


def test_a_step_is_kept_within_a_cell_and_the_turn_limit_of_its_start():
    assert within_cell((1.0, 2.0, 0.3), 1.3, 1.96, 0.1, 0.05) == pytest.approx(
        (1.05, 1.96, 0.3 - MAX_TURN_RAD)
    )
