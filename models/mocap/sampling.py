"""The measurement model of a motion-capture system (frame ``map``).

A frame shows every tracked body at one instant; each pose gets independent Gaussian
noise on x, y (``noise_std_m``) and yaw (``noise_std_rad``), and a body is missing from a
frame with probability ``dropout`` (occluded markers). The frame reaches the robots
``latency_ms`` after the instant it shows; when is the caller's business. The random draws
are passed in, so the same draws give the same frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray
from models.geometry.angles import wrap_angles


@dataclass(frozen=True)
class MocapParams:
    """A motion-capture system.

    Attributes:
        rate_hz: frames per second (Hz).
        latency_ms: from the instant a frame shows to its poses being sent (ms).
        noise_std_m: Gaussian position noise per axis (m).
        noise_std_rad: Gaussian yaw noise (rad).
        dropout: probability that a body is missing from a frame, in [0, 1].
    """

    rate_hz: float = 100.0
    latency_ms: float = 5.0
    noise_std_m: float = 0.001
    noise_std_rad: float = 0.002
    dropout: float = 0.0

    def __post_init__(self) -> None:
        if not self.rate_hz > 0:
            raise ValueError(f"rate_hz = {self.rate_hz!r}: expected a rate > 0")
        for key in ("latency_ms", "noise_std_m", "noise_std_rad"):
            if not getattr(self, key) >= 0:
                raise ValueError(f"{key} = {getattr(self, key)!r}: expected a value >= 0")
        if not 0 <= self.dropout <= 1:
            raise ValueError(f"dropout = {self.dropout!r}: expected a probability in [0, 1]")


@dataclass(frozen=True)
class Measurement:
    """One frame.

    Attributes:
        poses: (n, 3) measured poses ``x_m, y_m, yaw_rad`` in ``map``, yaw in [-pi, pi).
        seen: (n,) whether each body is in the frame.
    """

    poses: FloatArray
    seen: npt.NDArray[np.bool_]


def measure(
    truth: FloatArray, normals: FloatArray, uniforms: FloatArray, params: MocapParams
) -> Measurement:
    """Measure the bodies at ``truth``.

    Args:
        truth: (n, 3) true poses ``x_m, y_m, yaw_rad`` in ``map``.
        normals: (n, 3) standard normal draws (x, y, yaw noise).
        uniforms: (n,) uniform draws in [0, 1) (a body is seen when its draw >= dropout).
        params: the system.
    """
    truth = np.asarray(truth, dtype=float).reshape(-1, 3)
    scale = np.array([params.noise_std_m, params.noise_std_m, params.noise_std_rad])
    poses = truth + np.asarray(normals, dtype=float).reshape(-1, 3) * scale
    poses[:, 2] = wrap_angles(poses[:, 2])
    seen = np.asarray(uniforms, dtype=float).reshape(-1) >= params.dropout
    return Measurement(poses, seen)
