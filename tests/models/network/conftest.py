"""Named random streams for the network tests, derived like the run's streams: seed + name."""

from __future__ import annotations

import hashlib
from collections.abc import Callable

import numpy as np
import pytest

Streams = Callable[[str], np.random.Generator]


def named_streams(seed: int) -> Streams:
    """A stream factory: the generator for a name depends only on (seed, name)."""

    def stream(name: str) -> np.random.Generator:
        digest = hashlib.sha256(name.encode()).digest()
        key = tuple(int.from_bytes(digest[i : i + 4], "little") for i in range(0, 16, 4))
        return np.random.Generator(np.random.PCG64(np.random.SeedSequence(seed, spawn_key=key)))

    return stream


@pytest.fixture
def streams() -> Streams:
    return named_streams(7)


@pytest.fixture
def make_streams() -> Callable[[int], Streams]:
    return named_streams
