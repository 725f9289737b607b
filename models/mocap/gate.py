"""Plausibility checks a robot's software applies to the poses it receives.

A pose is rejected when its stamp is not newer than the last accepted one, or when it
lies further from the last accepted pose than the robot can drive in the time between the
two stamps (``max_speed * dt + tolerance``; yaw likewise with the yaw-rate limit): a
marker swap, a ghost body or a corrupt sample. A robot whose newest pose is older than a
limit is *stale* (it should stop).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray
from models.geometry.angles import wrap_angle, wrap_angles

BoolArray = npt.NDArray[np.bool_]
IntArray = npt.NDArray[np.int64]


@dataclass(frozen=True)
class GateResult:
    """What :meth:`PoseGate.check` decided, per pose.

    Attributes:
        accepted: the pose can be used.
        jump: rejected, further than the robot can move in the time between stamps, or
            not a pose at all (NaN or infinite).
        out_of_order: rejected, stamped at or before the last accepted pose.
    """

    accepted: BoolArray
    jump: BoolArray
    out_of_order: BoolArray


@dataclass(frozen=True)
class PoseGate:
    """Rejects poses a robot cannot have reached.

    Attributes:
        max_speed_mps: the robot's top speed (m/s).
        max_yaw_rate_radps: its top yaw rate (rad/s).
        tolerance_m: displacement allowed beyond the drivable one (noise) (m).
        tolerance_rad: heading change allowed beyond the turnable one (rad).
    """

    max_speed_mps: float
    max_yaw_rate_radps: float
    tolerance_m: float
    tolerance_rad: float

    def check(
        self,
        last: FloatArray,
        last_stamp_ns: IntArray,
        new: FloatArray,
        new_stamp_ns: IntArray,
        has_last: BoolArray,
    ) -> GateResult:
        """Check ``new`` poses (n, 3) against the last accepted ones of the same robots.

        Args:
            last: (n, 3) last accepted poses ``x_m, y_m, yaw_rad`` in ``map``.
            last_stamp_ns: (n,) their stamps (ns).
            new: (n, 3) the poses to check.
            new_stamp_ns: (n,) their stamps (ns).
            has_last: (n,) whether a robot has an accepted pose at all (else any finite
                pose is accepted).
        """
        # a NaN or infinite pose is not a pose at all: never accepted (as check_one)
        finite = np.isfinite(new).all(axis=1)
        dt_s = (np.asarray(new_stamp_ns) - np.asarray(last_stamp_ns)) / 1e9
        out_of_order = finite & has_last & (dt_s <= 0)
        with np.errstate(invalid="ignore"):  # non-finite rows are rejected above
            moved = np.hypot(new[:, 0] - last[:, 0], new[:, 1] - last[:, 1])
            turned = np.abs(wrap_angles(new[:, 2] - last[:, 2]))
        reach = self.max_speed_mps * np.maximum(dt_s, 0.0) + self.tolerance_m
        turn = self.max_yaw_rate_radps * np.maximum(dt_s, 0.0) + self.tolerance_rad
        jump = ~finite | (has_last & ~out_of_order & ((moved > reach) | (turned > turn)))
        return GateResult(~(out_of_order | jump), jump, out_of_order)

    def check_one(
        self,
        last: tuple[float, float, float] | None,
        last_stamp_ns: int,
        new: tuple[float, float, float],
        new_stamp_ns: int,
    ) -> str:
        """:meth:`check` for one pose without arrays (poses arrive one by one at 100 Hz).

        Returns:
            ``"ok"``, ``"jump"`` or ``"out_of_order"``; ``last`` None accepts any pose.
        """
        if not all(math.isfinite(v) for v in new):
            return "jump"  # not a pose at all: never accepted
        if last is None:
            return "ok"
        dt_s = (new_stamp_ns - last_stamp_ns) / 1e9
        if dt_s <= 0:
            return "out_of_order"
        moved = math.hypot(new[0] - last[0], new[1] - last[1])
        turned = abs(wrap_angle(new[2] - last[2]))
        if moved > self.max_speed_mps * dt_s + self.tolerance_m:
            return "jump"
        if turned > self.max_yaw_rate_radps * dt_s + self.tolerance_rad:
            return "jump"
        return "ok"


def stale(last_stamp_ns: IntArray, now_ns: int, max_age_ns: int, has_last: BoolArray) -> BoolArray:
    """Robots whose newest pose is older than ``max_age_ns`` at ``now_ns`` (or have none)."""
    return ~has_last | (now_ns - np.asarray(last_stamp_ns) > max_age_ns)
