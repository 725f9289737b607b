"""Planar lidar: beam geometry, exact ray casting, and the sensor's error model.

Conventions follow ``sensor_msgs/LaserScan`` and REP 117: beam ``i`` of ``n`` points at
``angle_min + i * increment`` in the sensor frame (x forward, counter-clockwise
positive). A full 360 deg scan has ``increment = 2 pi / n`` and no duplicated first/last
beam; a narrower field of view spans ``[-fov/2, +fov/2]`` with ``increment = fov/(n-1)``.
A beam that hits nothing within ``range_max`` reads ``+inf``; a dropped-out beam reads
``nan``; a hit closer than ``range_min`` reads ``-inf``.

:func:`cast_reference` is the exact float64 brute force over every segment and circle; it
defines what a correct scan is and serves as the oracle for faster casters.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray


@dataclass(frozen=True)
class ScanGeometry:
    """Beam layout and range limits of a lidar.

    Attributes:
        beams: number of beams.
        fov_rad: field of view (rad), at most 2 pi.
        range_min_m: minimum valid range (m).
        range_max_m: maximum range (m).
    """

    beams: int
    fov_rad: float
    range_min_m: float
    range_max_m: float

    @property
    def full_circle(self) -> bool:
        """Whether the scan covers 360 deg (then no beam is duplicated)."""
        return math.isclose(self.fov_rad, 2 * math.pi)

    @property
    def angle_min_rad(self) -> float:
        """Angle of the first beam in the sensor frame (rad)."""
        return -math.pi if self.full_circle else -self.fov_rad / 2

    @property
    def angle_increment_rad(self) -> float:
        """Angle between consecutive beams (rad)."""
        if self.full_circle:
            return 2 * math.pi / self.beams
        return self.fov_rad / (self.beams - 1) if self.beams > 1 else 0.0

    def angles(self) -> FloatArray:
        """Beam angles in the sensor frame (rad)."""
        return self.angle_min_rad + self.angle_increment_rad * np.arange(
            self.beams, dtype=np.float64
        )


def beam_directions(yaws: FloatArray, beam_angles: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Unit directions in ``map`` of every beam of every sensor.

    The beam's sensor-frame direction ``(cos a, sin a)`` rotated by the sensor's yaw:
    ``dx = cos(yaw) cos(a) - sin(yaw) sin(a)``, ``dy = sin(yaw) cos(a) + cos(yaw) sin(a)``.
    This is *the* definition of a beam's direction: every caster evaluates exactly these
    products and sums, so all of them agree bit for bit on which beams graze a corner,
    and only ``r + b`` trigonometric calls are needed instead of ``r * b``.

    Args:
        yaws: (r,) sensor headings in ``map`` (rad).
        beam_angles: (b,) beam angles in the sensor frame (rad).

    Returns:
        ``(dx, dy)``, each (r, b).
    """
    cy = np.cos(yaws)[:, None]
    sy = np.sin(yaws)[:, None]
    ca = np.cos(beam_angles)[None, :]
    sa = np.sin(beam_angles)[None, :]
    return cy * ca - sy * sa, sy * ca + cy * sa


def cast_reference(
    origins: FloatArray,
    yaws: FloatArray,
    beam_angles: FloatArray,
    segments: FloatArray,
    circles: FloatArray,
    range_max_m: float,
    exclude: npt.NDArray[np.int64] | None = None,
) -> FloatArray:
    """Exact distances from each origin along each beam to the nearest surface.

    Args:
        origins: (r, 2) ray origins in ``map`` (m).
        yaws: (r,) sensor headings in ``map`` (rad).
        beam_angles: (b,) beam angles in the sensor frame (rad); directions as
            :func:`beam_directions`.
        segments: (s, 4) segments ``x0, y0, x1, y1`` (m).
        circles: (c, 3) circles ``x, y, radius`` (m), e.g. other robots.
        range_max_m: rays longer than this read ``inf``.
        exclude: (r,) index of a circle each origin must not see (its own body), or -1.

    Returns:
        (r, b) float64 ranges (m); ``inf`` where nothing is hit within ``range_max_m``.
    """
    ox = origins[:, 0, None, None]
    oy = origins[:, 1, None, None]
    dir_x, dir_y = beam_directions(
        np.asarray(yaws, dtype=float), np.asarray(beam_angles, dtype=float)
    )
    dx = dir_x[:, :, None]
    dy = dir_y[:, :, None]
    best = np.full(dir_x.shape, np.inf)
    if len(segments):
        x0, y0, x1, y1 = (segments[:, k][None, None, :] for k in range(4))
        ex, ey = x1 - x0, y1 - y0
        denom = dx * ey - dy * ex
        wx, wy = x0 - ox, y0 - oy
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (wx * ey - wy * ex) / denom
            u = (wx * dy - wy * dx) / denom
        hit = (denom != 0) & (t >= 0) & (u >= 0) & (u <= 1)
        best = np.minimum(best, np.where(hit, t, np.inf).min(axis=2))
    if len(circles):
        cx = circles[None, None, :, 0]
        cy = circles[None, None, :, 1]
        rad = circles[None, None, :, 2]
        fx, fy = ox - cx, oy - cy
        b = fx * dx + fy * dy
        c = fx * fx + fy * fy - rad * rad
        disc = b * b - c
        root = np.sqrt(np.maximum(disc, 0.0))
        near = -b - root
        far = -b + root
        # from outside: the near root; from inside a circle: the exit point
        t = np.where(c > 0, near, far)
        ok = (disc >= 0) & (t >= 0)
        if exclude is not None:
            own = np.arange(circles.shape[0])[None, None, :] == exclude[:, None, None]
            ok &= ~own
        best = np.minimum(best, np.where(ok, t, np.inf).min(axis=2))
    return np.where(best <= range_max_m, best, np.inf)


def apply_sensor_model(
    ranges: FloatArray,
    geometry: ScanGeometry,
    noise_std_m: float,
    dropout_prob: float,
    normals: npt.NDArray[np.floating[Any]],
    uniforms: npt.NDArray[np.floating[Any]],
) -> npt.NDArray[np.float32]:
    """Add Gaussian range noise and dropouts to exact ranges (any shape, e.g. robots x beams).

    Noisy hits beyond ``range_max`` read ``inf``, below ``range_min`` read ``-inf``
    (REP 117); dropped beams read ``nan``.

    Args:
        ranges: exact ranges (m), float64 (other dtypes are converted); ``inf`` where
            nothing was hit.
        geometry: the lidar's limits.
        noise_std_m: standard deviation of the range noise (m).
        dropout_prob: probability that a beam returns nothing.
        normals: standard normal draws, same shape as ``ranges`` (any float dtype).
        uniforms: uniform draws in [0, 1), same shape as ``ranges`` (any float dtype).

    Returns:
        float32 ranges as published in a LaserScan.

    Raises:
        ValueError: if the draws do not have the shape of ``ranges``.
    """
    # What this computes, element by element and compiled (numpy's calls on one robot's
    # or a small fleet's scans cost more than the arithmetic), with numpy's promotion
    # rules (the noise product and the dropout test in the draws' own precision):
    #   out = where(isfinite(ranges), ranges + normals * noise_std_m, inf)
    #   out = where(out > range_max_m, inf, out); out = where(out < range_min_m, -inf, out)
    #   out = where(uniforms < dropout_prob, nan, out).astype(float32)
    exact = np.asarray(ranges, dtype=np.float64)
    normals = np.asarray(normals)
    uniforms = np.asarray(uniforms)
    if normals.shape != exact.shape or uniforms.shape != exact.shape:
        raise ValueError(
            f"draws of shapes {normals.shape} and {uniforms.shape} for ranges {exact.shape}"
        )
    out = np.empty(exact.shape, dtype=np.float32)
    _sensor_model(
        exact.reshape(-1),
        normals.reshape(-1),
        uniforms.reshape(-1),
        normals.dtype.type(noise_std_m),
        uniforms.dtype.type(dropout_prob),
        float(geometry.range_min_m),
        float(geometry.range_max_m),
        out.reshape(-1),
    )
    return out


def _sensor_model_py(
    ranges: FloatArray,
    normals: npt.NDArray[np.floating[Any]],
    uniforms: npt.NDArray[np.floating[Any]],
    noise_std: np.floating[Any],
    dropout_prob: np.floating[Any],
    range_min_m: float,
    range_max_m: float,
    out: npt.NDArray[np.float32],
) -> None:
    for k in range(ranges.shape[0]):
        r = ranges[k] + normals[k] * noise_std if np.isfinite(ranges[k]) else np.inf
        if r > range_max_m:
            r = np.inf
        if r < range_min_m:
            r = -np.inf
        if uniforms[k] < dropout_prob:
            r = np.nan
        out[k] = r


_sensor_model: Any = numba.njit(cache=True, nogil=True)(_sensor_model_py)


def hits_within(
    ranges: npt.NDArray[np.float32],
    seen: npt.NDArray[np.bool_],
    poses: FloatArray,
    cos_a: FloatArray,
    sin_a: FloatArray,
    within_m: float,
) -> tuple[FloatArray, npt.NDArray[np.int64]]:
    """Hits of a fleet's latest scans within ``within_m`` of their robots, CSR-packed.

    One compiled pass over every beam of every robot (it was a dozen fleet-sized numpy
    temporaries a control tick); the arithmetic is numpy's, operation for operation, so the
    points are the same to the bit.

    Args:
        ranges: (n, b) float32 ranges of each robot's latest scan (m); ``inf``, ``-inf``
            and ``nan`` as in ``LaserScan``.
        seen: (n,) whether robot ``i`` has a scan at all.
        poses: (n, 3) ``x, y, yaw`` in ``map`` each scan was taken from (m, rad).
        cos_a: (b,) cosine of each beam angle in the sensor frame.
        sin_a: (b,) sine of each beam angle.
        within_m: hits farther than this are left out (m), compared in ``ranges``' float
            type (as numpy compares a float32 array with a Python float).

    Returns:
        ``(points, start)``: (m, 2) hits in ``map`` (m); robot ``i`` owns
        ``points[start[i]:start[i + 1]]``; robots without a scan own none.
    """
    n = ranges.shape[0]
    yaw = poses[:, 2]
    points = np.empty((ranges.size, 2))
    start = np.zeros(n + 1, dtype=np.int64)
    count = _hits_within(
        ranges,
        seen,
        np.ascontiguousarray(poses[:, 0]),
        np.ascontiguousarray(poses[:, 1]),
        np.cos(yaw),
        np.sin(yaw),
        np.ascontiguousarray(cos_a, dtype=np.float64),
        np.ascontiguousarray(sin_a, dtype=np.float64),
        ranges.dtype.type(within_m),
        points,
        start,
    )
    return points[:count].copy(), start


def _hits_within_py(
    ranges: npt.NDArray[np.float32],
    seen: npt.NDArray[np.bool_],
    x: FloatArray,
    y: FloatArray,
    cos_yaw: FloatArray,
    sin_yaw: FloatArray,
    cos_a: FloatArray,
    sin_a: FloatArray,
    within: np.floating[Any],
    points: FloatArray,
    start: npt.NDArray[np.int64],
) -> int:
    k = 0
    for i in range(ranges.shape[0]):
        start[i] = k
        if seen[i]:
            c, s = cos_yaw[i], sin_yaw[i]
            for j in range(ranges.shape[1]):
                r32 = ranges[i, j]
                if np.isfinite(r32) and r32 > 0 and r32 <= within:
                    r = np.float64(r32)
                    points[k, 0] = x[i] + r * (c * cos_a[j] - s * sin_a[j])
                    points[k, 1] = y[i] + r * (s * cos_a[j] + c * sin_a[j])
                    k += 1
    start[ranges.shape[0]] = k
    return k


_hits_within: Any = numba.njit(cache=True, nogil=True)(_hits_within_py)


def seen_beyond(
    pose: FloatArray,
    ranges: npt.NDArray[np.float32],
    angle_min_rad: float,
    increment_rad: float,
    range_max_m: float,
    points: FloatArray,
    tolerance_m: float,
) -> npt.NDArray[np.bool_]:
    """Which points a scan sees free space beyond: its beam towards each passes it.

    A point is seen through when it lies within the maximum range and the beam nearest its
    bearing reads more than its distance plus ``tolerance_m``: no return counts as free up
    to the maximum range, a return below the minimum range as nothing seen, a dropout
    (``nan``) as nothing known. One compiled pass with numpy's operations in numpy's order
    (the same answers to the bit as the array formulation it replaces).

    Args:
        pose: ``x, y, yaw`` the scan was taken from, in ``map`` (m, rad).
        ranges: (b,) the scan's ranges (m), as in ``LaserScan``.
        angle_min_rad: angle of beam 0 in the sensor frame (rad).
        increment_rad: angle between beams (rad).
        range_max_m: the lidar's maximum range (m).
        points: (k, 2) points in ``map`` (m).
        tolerance_m: how far beyond a point the beam must reach (m).

    Returns:
        (k,) True where the scan sees through the point.
    """
    out = np.zeros(len(points), dtype=np.bool_)
    if len(points):
        _seen_beyond(
            float(pose[0]),
            float(pose[1]),
            float(pose[2]),
            ranges,
            float(angle_min_rad),
            float(increment_rad),
            float(range_max_m),
            np.ascontiguousarray(points, dtype=np.float64).reshape(-1, 2),
            float(tolerance_m),
            out,
        )
    return out


def _seen_beyond_py(
    x: float,
    y: float,
    yaw: float,
    ranges: npt.NDArray[np.float32],
    angle_min: float,
    increment: float,
    range_max: float,
    points: FloatArray,
    tolerance: float,
    out: npt.NDArray[np.bool_],
) -> None:
    beams = ranges.shape[0]
    turn = 2 * math.pi
    for p in range(points.shape[0]):
        dx, dy = points[p, 0] - x, points[p, 1] - y
        dist = np.hypot(dx, dy)
        bearing = (np.arctan2(dy, dx) - yaw - angle_min) % turn
        beam = np.int64(np.rint(bearing / increment))
        seen = float(ranges[min(beam, beams - 1)])
        if seen == np.inf:
            seen = range_max
        elif seen == -np.inf:
            seen = 0.0
        out[p] = beam < beams and dist < range_max and seen > dist + tolerance


_seen_beyond: Any = numba.njit(cache=True, nogil=True)(_seen_beyond_py)
