"""Angles in the plane: the one wrap into [-pi, pi) (rad), for one angle and for arrays.

``(a + pi) % 2pi - pi`` alone is not a wrap to rely on: it rounds angles that need no
wrapping (0.1 becomes 0.10000000000000009), so a heading integrated step after step drifts
by the rounding, and it sends an angle a hair below -pi to +pi (``-tiny % 2pi`` rounds up
to 2pi). Here an angle already in [-pi, pi) is returned as it is, and the result is never
+pi. :func:`wrap_angle` is plain arithmetic so that compiled kernels use it too
(``numba.njit(wrap_angle)``); :func:`wrap_angles` is the same rule over arrays, element for
element bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray

TAU = 2.0 * math.pi
"""A full turn (rad)."""


def wrap_angle(angle: float) -> float:
    """One angle (rad) in [-pi, pi); unchanged if it is in that interval already."""
    if -math.pi <= angle < math.pi:
        return angle
    wrapped = (angle + math.pi) % TAU - math.pi
    return -math.pi if wrapped >= math.pi else wrapped


def wrap_angles(angles: npt.ArrayLike) -> FloatArray:
    """Angles (rad) in [-pi, pi), element by element as :func:`wrap_angle`; NaN stays NaN."""
    a = np.asarray(angles, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        wrapped = (a + np.pi) % TAU - np.pi
        wrapped = np.where(wrapped >= np.pi, -np.pi, wrapped)
        inside = (a >= -np.pi) & (a < np.pi)
    return np.where(inside, a, wrapped)
