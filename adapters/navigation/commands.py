"""A local controller's commands, checked where they enter navigation: refused or clipped.

Every control tick the controller's :meth:`~adapters.navigation.contract.LocalController.commands`
hands back three arrays with a row per robot. They are checked once per tick, a few NumPy
reductions over the fleet, before navigation uses them:

- **refused** (:class:`~cosim.core.plugins.PluginError`, naming the controller, the value
  and what was expected): anything but three arrays; an array whose shape is not ``(n,)``;
  speeds or yaw rates that are not real numbers (``float``/``int`` dtypes), a ``blocked``
  that is not ``bool``; a speed or yaw rate that is NaN or infinite (no robot can drive it,
  and nothing sensible can be made of it);
- **clipped and counted** (``controller_commands_clipped`` in the summary): a speed beyond
  ``robots.max_speed_mps`` forward or ``robots.max_reverse_mps`` backward, a yaw rate beyond
  ``robots.max_yaw_rate_radps`` either way. The robots' motion would clamp it to the same
  limits; clipping it here makes what navigation publishes on ``cmd_vel``, and what its
  stall and recovery logic reason on, what the robot will do. Acceleration limits stay the
  motion's: a controller may ask for a step, the robot slews to it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np

from cosim.core.plugins import refuse
from models.arrays import BoolArray, FloatArray
from models.fleet.kinematics import DriveLimits

DOING = "computing the robots' commands (navigation.controller)"
"""What navigation was doing, for the error."""


class Commands(NamedTuple):
    """A tick's commands as navigation takes them.

    Attributes:
        v: (n,) speeds (m/s), within the drive limits.
        w: (n,) yaw rates (rad/s), within the drive limits.
        blocked: (n,) robots that found no way ahead.
        clipped: how many robots' commands were beyond the limits and clipped.
    """

    v: FloatArray
    w: FloatArray
    blocked: BoolArray
    clipped: int


def checked_commands(
    controller: Any, returned: Any, names: Sequence[str], limits: DriveLimits
) -> Commands:
    """What ``controller.commands(...)`` returned, checked against the fleet and its limits.

    Args:
        controller: the local controller (named in errors).
        returned: what its ``commands`` returned: ``(v, w, blocked)``.
        names: the robots, in fleet order (``n`` rows expected).
        limits: the robots' drive limits.

    Raises:
        PluginError: commands cosim cannot drive with (see the module docstring).
    """
    if not isinstance(returned, tuple | list) or len(returned) != 3:
        raise refuse(
            controller,
            f"returned {_kind(returned)}; expected a tuple (v, w, blocked) of three arrays",
            doing=DOING,
        )
    n = len(names)
    v = _numbers(controller, "speeds v (m/s)", returned[0], n)
    w = _numbers(controller, "yaw rates w (rad/s)", returned[1], n)
    blocked = returned[2]
    _shape(controller, "blocked", blocked, n)
    if blocked.dtype.kind != "b":
        raise refuse(
            controller,
            f"returned blocked of dtype {blocked.dtype}; expected bool, one per robot",
            doing=DOING,
        )
    for what, values, unit in (("speed", v, "m/s"), ("yaw rate", w, "rad/s")):
        if not np.isfinite(values).all():
            i = int(np.flatnonzero(~np.isfinite(values))[0])
            raise refuse(
                controller,
                f"returned {what} {values[i]} for {names[i]!r}; expected a finite number ({unit})",
                doing=DOING,
            )
    forward, backward = limits.max_speed_mps, -limits.max_reverse_mps
    turn = limits.max_yaw_rate_radps
    if n == 0 or (v.max() <= forward and v.min() >= backward and np.abs(w).max() <= turn):
        return Commands(v, w, blocked, 0)
    beyond = (v > forward) | (v < backward) | (np.abs(w) > turn)
    clipped = int(np.count_nonzero(beyond))
    return Commands(np.clip(v, backward, forward), np.clip(w, -turn, turn), blocked, clipped)


def _numbers(controller: Any, what: str, values: Any, n: int) -> FloatArray:
    """``values`` as (n,) float64, or the error naming what is wrong with them."""
    _shape(controller, what, values, n)
    if values.dtype.kind not in "fiu":
        raise refuse(
            controller,
            f"returned {what} of dtype {values.dtype}; expected real numbers (float)",
            doing=DOING,
        )
    floats: FloatArray = values.astype(np.float64, copy=False)
    return floats


def _shape(controller: Any, what: str, values: Any, n: int) -> None:
    if not isinstance(values, np.ndarray):
        raise refuse(
            controller,
            f"returned {what} as {_kind(values)}; expected a numpy array of shape ({n},), "
            "one per robot",
            doing=DOING,
        )
    if values.shape != (n,):
        raise refuse(
            controller,
            f"returned {what} of shape {values.shape}; expected ({n},), one per robot",
            doing=DOING,
        )


def _kind(value: Any) -> str:
    """``a list of 2``, ``a float``, ``None``: what a value is, briefly."""
    if value is None:
        return "None"
    name = type(value).__name__
    article = "an" if name[0] in "aeiou" else "a"
    try:
        return f"{article} {name} of {len(value)}"
    except TypeError:
        return f"{article} {name}"
