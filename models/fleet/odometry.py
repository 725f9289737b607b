"""Wheel odometry with drift: noisy increments integrated like the true motion.

Each step, the true travelled distance ``ds`` (m) and turned angle ``dtheta`` (rad) are
corrupted with zero-mean Gaussian errors whose variance grows linearly with the motion,
so the pose error is a random walk independent of the step length:

* distance: ``sigma_s^2 = drift^2 * |ds|`` (m^2, with ``|ds|`` in m),
* heading: ``sigma_theta^2 = drift^2 * (|ds| + |dtheta|)`` (rad^2).

With ``drift = 0.02``, one metre driven straight gives a 2 cm distance error and a
0.02 rad (1.1 deg) heading error (one standard deviation); the heading error then bends
the path. This is the shape of the odometry motion model of Thrun, Burgard and Fox,
*Probabilistic Robotics* (2005), sec. 5.4, with its four coefficients tied to one scale.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray
from models.fleet.kinematics import integrate_fleet


def drift_increments(
    ds_m: FloatArray,
    dtheta_rad: FloatArray,
    drift: float,
    normals: npt.NDArray[np.floating[Any]],
) -> tuple[FloatArray, FloatArray]:
    """Corrupt true motion increments with odometry drift.

    Args:
        ds_m: (n,) signed distance travelled along the heading this step (m).
        dtheta_rad: (n,) heading change this step (rad).
        drift: the noise scale (see module doc); 0 returns the increments unchanged.
        normals: (n, 2) standard normal draws (one pair per robot).

    Returns:
        The measured ``(ds_m, dtheta_rad)``.
    """
    travelled = np.abs(ds_m)
    ds_meas = ds_m + drift * np.sqrt(travelled) * normals[:, 0]
    dtheta_meas = dtheta_rad + drift * np.sqrt(travelled + np.abs(dtheta_rad)) * normals[:, 1]
    return ds_meas, dtheta_meas


def advance(
    x: FloatArray,
    y: FloatArray,
    yaw: FloatArray,
    ds_m: FloatArray,
    dtheta_rad: FloatArray,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Integrate measured increments into odometry poses (frame ``odom``), as an exact arc.

    :func:`models.fleet.kinematics.integrate` over a step of 1 (the increments are the step's).
    """
    f64 = np.float64
    return integrate_fleet(
        np.asarray(x, f64),
        np.asarray(y, f64),
        np.asarray(yaw, f64),
        np.asarray(ds_m, f64),
        np.asarray(dtheta_rad, f64),
        1.0,
    )
