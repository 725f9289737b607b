"""Per-component random streams derived from one scenario seed.

Each component asks for a stream by a stable name (``"lidar/robot_3"``). The stream is
``numpy.random.SeedSequence(seed, spawn_key=hash(name))``, so it depends only on the
seed and the name: adding a robot or an adapter never shifts another component's
numbers. The global NumPy and ``random`` states are never touched.
"""

from __future__ import annotations

import hashlib
from typing import Any

import numpy as np
import numpy.typing as npt

from cosim.core.workers import Spread, in_turn


def _name_key(name: str) -> tuple[int, ...]:
    digest = hashlib.sha256(name.encode("utf-8")).digest()
    return tuple(int.from_bytes(digest[i : i + 4], "little") for i in range(0, 16, 4))


class RngStreams:
    """Factory of independent, named ``numpy.random.Generator`` streams.

    Args:
        seed: the scenario seed (a non-negative integer).
    """

    def __init__(self, seed: int) -> None:
        if seed < 0:
            raise ValueError(f"seed must be >= 0, got {seed}")
        self.seed = seed
        self._issued: set[str] = set()

    def stream(self, name: str) -> np.random.Generator:
        """Return the generator for component ``name``; each name may be asked for once.

        Raises:
            ValueError: if ``name`` was issued already (two components sharing a stream
                would make their randomness depend on each other's call order).
        """
        if name in self._issued:
            raise ValueError(f"random stream {name!r} was already issued")
        self._issued.add(name)
        sequence = np.random.SeedSequence(self.seed, spawn_key=_name_key(name))
        return np.random.Generator(np.random.PCG64(sequence))


BLOCK_TICKS = 64
"""Ticks a :class:`BlockDraws` fetches at once, at most."""


class BlockDraws:
    """Random draws for many components, each from its own stream, fetched in blocks.

    Drawing one small vector per component per tick costs a Python call each; fetching
    ``block`` ticks at once keeps every component's numbers exactly those it would get
    one tick at a time from its own stream, at a fraction of the calls.

    Args:
        streams: one generator per component (row).
        width: draws per component per call.
        kind: ``"normal"`` (standard normal) or ``"uniform"`` (in [0, 1)).
        budget: maximum number of buffered values (bounds the memory).
        dtype: ``numpy.float64`` or ``numpy.float32`` (twice as fast to draw).
        spread: refills the components' rows (``spread(fn, rows)``, e.g. the run's
            threads: :meth:`cosim.core.workers.Workers.map`); each row is drawn from its own
            stream, so the numbers are the same however the rows are spread.
    """

    def __init__(
        self,
        streams: list[np.random.Generator],
        width: int,
        kind: str = "normal",
        budget: int = 1 << 22,
        dtype: type[np.floating[Any]] = np.float64,
        spread: Spread = in_turn,
    ) -> None:
        if kind not in ("normal", "uniform"):
            raise ValueError(f"kind must be 'normal' or 'uniform', got {kind!r}")
        self.streams = streams
        self.width = width
        self.kind = kind
        # at most BLOCK_TICKS ticks ahead: what a run's last block draws past its end is lost
        self.block = max(1, min(BLOCK_TICKS, budget // max(1, len(streams) * width)))
        self.spread = spread
        self.dtype = dtype
        self._buffer = np.zeros((len(streams), self.block, width), dtype=dtype)
        self._next = self.block

    def draw(self) -> npt.NDArray[np.floating[Any]]:
        """Return (components, width) draws; a view, valid until the next call."""
        if self._next == self.block:
            self.spread(self._refill, range(len(self.streams)))
            self._next = 0
        out = self._buffer[:, self._next, :]
        self._next += 1
        return out

    def _refill(self, row: int) -> None:
        """The next ``block`` ticks of component ``row``, from its own stream.

        numpy draws into the buffer without holding the interpreter lock, so rows refill
        at once on several threads.
        """
        stream, out = self.streams[row], self._buffer[row]
        if self.kind == "normal":
            stream.standard_normal(out=out, dtype=self.dtype)
        else:
            stream.random(out=out, dtype=self.dtype)
