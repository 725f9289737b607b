"""Line-of-sight shadowing: how many walls and shelves stand between two radios.

A radio signal between two points loses a fixed amount for every obstacle the straight line
between them crosses (the "multi-wall" model of COST 231, Damosso and Correia, 1999: a
constant loss per wall on top of the distance loss). Obstacles are the world's axis-aligned
boxes (walls, shelves, extra obstacles, ``map`` frame, m); a box counts once however
the line crosses it, and a line that only touches a box's edge or corner, or ends inside a
box, crosses it too.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from models.arrays import FloatArray


def boxes_crossed(a: FloatArray, b: FloatArray, boxes: FloatArray) -> npt.NDArray[np.int64]:
    """How many boxes each segment from ``a[k]`` to ``b[k]`` meets (slab test).

    Args:
        a: (n, 2) one end of each segment, ``map`` (m).
        b: (n, 2) the other end, ``map`` (m).
        boxes: (m, 4) boxes ``xmin, ymin, xmax, ymax``, ``map`` (m).

    Returns:
        (n,) the number of boxes each segment meets.
    """
    p = np.asarray(a, dtype=float).reshape(-1, 1, 2)
    d = np.asarray(b, dtype=float).reshape(-1, 1, 2) - p
    box = np.asarray(boxes, dtype=float).reshape(1, -1, 4)
    lo, hi = box[..., :2], box[..., 2:]
    with np.errstate(divide="ignore", invalid="ignore"):
        t0 = (lo - p) / d
        t1 = (hi - p) / d
    near = np.minimum(t0, t1)
    far = np.maximum(t0, t1)
    # an axis the segment runs parallel to: inside the slab for every t, or never
    flat = d == 0.0
    inside = (p >= lo) & (p <= hi)
    near = np.where(flat, np.where(inside, -np.inf, np.inf), near)
    far = np.where(flat, np.where(inside, np.inf, -np.inf), far)
    enter = np.maximum(near.max(axis=2), 0.0)
    leave = np.minimum(far.min(axis=2), 1.0)
    met: npt.NDArray[np.int64] = (enter <= leave).sum(axis=1).astype(np.int64)
    return met
