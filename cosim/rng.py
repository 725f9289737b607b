"""Per-component random streams derived from one scenario seed.

Each component asks for a stream by a stable name (``"lidar/robot_3"``). The stream is
``numpy.random.SeedSequence(seed, spawn_key=hash(name))``, so it depends only on the
seed and the name: adding a robot or an adapter never shifts another component's
numbers. The global NumPy and ``random`` states are never touched.
"""

from __future__ import annotations

import hashlib

import numpy as np


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
