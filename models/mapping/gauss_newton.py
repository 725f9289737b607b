"""One damped Gauss-Newton step in (x, y, yaw), shared by the matcher's refines.

Both refines (:mod:`models.mapping.matcher` on the score, :mod:`models.mapping.walls` on
the walls) sum a 3 x 3 normal matrix and its right-hand side over the scan's points; this
solves the damped system (Levenberg: the diagonal raised by ``damping`` times the trace,
plus ``floor``) by Cramer's rule and keeps the pose within a cell and 0.02 rad of where the
search put it.
"""

from __future__ import annotations

from typing import Any

import numba

MAX_TURN_RAD = 0.02
"""How far a refine may turn the search's pose (rad): about its rotation step."""


def _levenberg_step_py(
    h00: float,
    h01: float,
    h02: float,
    h11: float,
    h12: float,
    h22: float,
    b0: float,
    b1: float,
    b2: float,
    damping: float,
    floor: float,
    min_det: float,
) -> tuple[float, float, float, bool]:
    """The step (dx m, dy m, dyaw rad) solving the damped normal equations, and whether one was.

    ``h`` is the symmetric normal matrix (upper triangle), ``b`` the right-hand side; no
    step when the damped matrix's determinant is below ``min_det`` in magnitude.
    """
    lam = damping * (h00 + h11 + h22) + floor
    a00, a11, a22 = h00 + lam, h11 + lam, h22 + lam
    m00 = a11 * a22 - h12 * h12
    m01 = h01 * a22 - h12 * h02
    m02 = h01 * h12 - a11 * h02
    det = a00 * m00 - h01 * m01 + h02 * m02
    if abs(det) < min_det:
        return 0.0, 0.0, 0.0, False
    dx = (b0 * m00 - h01 * (b1 * a22 - h12 * b2) + h02 * (b1 * h12 - a11 * b2)) / det
    dy = (a00 * (b1 * a22 - h12 * b2) - b0 * m01 + h02 * (h01 * b2 - b1 * h02)) / det
    dt = (a00 * (a11 * b2 - b1 * h12) - h01 * (h01 * b2 - b1 * h02) + b0 * m02) / det
    return dx, dy, dt, True


def _within_cell_py(
    start: tuple[float, float, float],
    x: float,
    y: float,
    yaw: float,
    res: float,
) -> tuple[float, float, float]:
    """``(x, y, yaw)`` kept within a cell (``res`` m) and :data:`MAX_TURN_RAD` of ``start``."""
    x0, y0, yaw0 = start
    return (
        min(x0 + res, max(x0 - res, x)),
        min(y0 + res, max(y0 - res, y)),
        min(yaw0 + MAX_TURN_RAD, max(yaw0 - MAX_TURN_RAD, yaw)),
    )


levenberg_step: Any = numba.njit(cache=True, nogil=True, inline="always")(_levenberg_step_py)
within_cell: Any = numba.njit(cache=True, nogil=True, inline="always")(_within_cell_py)
