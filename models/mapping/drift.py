"""Drifting odometry drawn along a reference trajectory: other realizations of one drift.

A recording comes with one realization of its odometry's drift; whether a mapper's result
depends on that realization is a question only other realizations answer. The model is
the one the shared recordings were made with (``../shared/data/README.md``): each step
between consecutive reference poses (dx, dy in the earlier pose's frame, turn dtheta,
length d) is measured as ``scale dx + s_t z1``, ``scale dy + s_t z2``,
``dtheta + bias d + s_r z3`` with ``s_t = a d + b`` (m) and ``s_r = c |dtheta| + e d``
(rad), z standard normal; the measured steps are composed from the first reference pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from models.arrays import FloatArray
from models.geometry.se2 import compose, relative


@dataclass(frozen=True)
class DriftModel:
    """How far each odometry step is off.

    Attributes:
        scale: every step's translation is this times the true one (wheel radius).
        per_m: translation noise per metre of step (m/m).
        floor_m: translation noise of any step (m).
        per_rad: rotation noise per radian turned (rad/rad).
        rad_per_m: rotation noise per metre driven (rad/m).
        bias_rad_per_m: the heading gains this much per metre driven (rad/m).
    """

    scale: float = 1.01
    per_m: float = 0.05
    floor_m: float = 0.001
    per_rad: float = 0.02
    rad_per_m: float = 0.005
    bias_rad_per_m: float = 0.002


def drifting_odometry(
    reference: FloatArray, seed: int, model: DriftModel | None = None
) -> FloatArray:
    """An odometry (n, 3: x m, y m, yaw rad) drifting from ``reference`` (n, 3), rng ``seed``.

    The noise of step k is row k of ``numpy.random.default_rng(seed).standard_normal``
    of shape (n - 1, 3): seeds 7 and 11 draw the shared ACES and Freiburg 079 odometry.
    """
    m = model or DriftModel()
    poses = np.asarray(reference, dtype=np.float64).reshape(-1, 3)
    noise = np.random.default_rng(seed).standard_normal((max(0, len(poses) - 1), 3))
    out = np.empty_like(poses)
    if not len(poses):
        return out
    current = (float(poses[0, 0]), float(poses[0, 1]), float(poses[0, 2]))
    out[0] = current
    for k in range(1, len(poses)):
        dx, dy, turn = relative(tuple(poses[k - 1]), tuple(poses[k]))
        d = math.hypot(dx, dy)
        s_t = m.per_m * d + m.floor_m
        s_r = m.per_rad * abs(turn) + m.rad_per_m * d
        z1, z2, z3 = noise[k - 1]
        step = (
            m.scale * dx + s_t * z1,
            m.scale * dy + s_t * z2,
            turn + m.bias_rad_per_m * d + s_r * z3,
        )
        current = compose(current, step)
        out[k] = current
    return out
