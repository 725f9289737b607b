"""Map evidence packed for the network: the changed rectangle, quantized and compressed.

A robot sends the log-odds its own scans added since its last update; only the smallest
rectangle holding every changed cell is sent, each cell rounded to an int8 number of
``scale`` steps (0.02 log-odds: a single miss is 0.08, a hit 0.85, so every update keeps
its sign and most of its size), then zlib-compressed. Rounding errors do not accumulate
across updates for the sender (it sends what it added), only per update at the receiver.
"""

from __future__ import annotations

import zlib
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from models.errors import ModelError

SCALE = 0.02
"""Log-odds per int8 step."""
LEVEL = 6
"""zlib compression level."""

Float32Array = npt.NDArray[np.float32]


class PackedUpdate(NamedTuple):
    """A compressed rectangle of log-odds changes.

    Attributes:
        ix0, iy0: lower-left cell of the rectangle.
        width, height: its size in cells.
        scale: log-odds per int8 step.
        data: zlib-compressed int8 cells, rows from the lowest y.
    """

    ix0: int
    iy0: int
    width: int
    height: int
    scale: float
    data: bytes


def pack(changes: Float32Array, scale: float = SCALE) -> PackedUpdate | None:
    """The changed rectangle of a whole-map array of log-odds changes; None if none changed."""
    steps = np.clip(np.round(changes / scale), -127, 127).astype(np.int8)
    rows = np.flatnonzero(steps.any(axis=1))
    if not len(rows):
        return None
    cols = np.flatnonzero(steps.any(axis=0))
    iy0, iy1, ix0, ix1 = int(rows[0]), int(rows[-1]) + 1, int(cols[0]), int(cols[-1]) + 1
    block = np.ascontiguousarray(steps[iy0:iy1, ix0:ix1])
    return PackedUpdate(
        ix0, iy0, ix1 - ix0, iy1 - iy0, scale, zlib.compress(block.tobytes(), LEVEL)
    )


def unpack(update: PackedUpdate, shape: tuple[int, int]) -> Float32Array:
    """The log-odds block of an update.

    Raises:
        ModelError: when the rectangle does not lie in a map of ``shape`` (rows, cols) or
            the data is not a compressed block of that size (a foreign or damaged update).
    """
    rows, cols = shape
    if not (
        update.ix0 >= 0
        and update.iy0 >= 0
        and 0 < update.width <= cols - update.ix0
        and 0 < update.height <= rows - update.iy0
    ):
        raise ModelError(
            "map update",
            (update.ix0, update.iy0, update.width, update.height),
            f"a rectangle inside the {cols} x {rows} map",
        )
    size = update.width * update.height
    try:
        # at most one byte more than expected: a bomb never inflates past the map
        raw = zlib.decompressobj().decompress(update.data, size + 1)
    except zlib.error as error:
        raise ModelError("map update", "data", f"zlib-compressed cells ({error})") from None
    if len(raw) != size:
        raise ModelError("map update", len(raw), f"{size} cells")
    block = np.frombuffer(raw, dtype=np.int8).reshape(update.height, update.width)
    return (block.astype(np.float32) * np.float32(update.scale)).astype(np.float32)
