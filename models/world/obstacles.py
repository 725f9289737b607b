"""Dynamic obstacles: discs that move (people, forklifts), shared by sensors and collision checks.

Adapters that move such things publish their current discs here under their own source
name; the lidar and the collision checker read the union, in the order the sources first
registered, so that indices are stable within a run.
"""

from __future__ import annotations

import numpy as np

from models.arrays import FloatArray


class DynamicObstacles:
    """The current discs ``x, y, radius`` (m, frame ``map``) of every moving obstacle."""

    def __init__(self) -> None:
        self._discs: dict[str, FloatArray] = {}
        self._names: dict[str, list[str]] = {}
        self._kinds: dict[str, list[str]] = {}
        self._cache: tuple[FloatArray, list[str]] | None = None

    def update(
        self, source: str, discs: FloatArray, names: list[str], kinds: list[str] | None = None
    ) -> None:
        """Replace the discs of ``source`` with (m, 3) ``discs`` named ``names``.

        ``kinds`` says what each disc is (``person``, ``forklift``; default ``dynamic``).
        """
        discs = np.asarray(discs, dtype=float).reshape(-1, 3)
        if len(names) != len(discs) or (kinds is not None and len(kinds) != len(discs)):
            raise ValueError(f"{source}: {len(discs)} discs but {len(names)} names")
        self._discs[source] = discs
        self._names[source] = list(names)
        self._kinds[source] = list(kinds) if kinds is not None else ["dynamic"] * len(names)
        self._cache = None

    def _union(self) -> tuple[FloatArray, list[str]]:
        if self._cache is None:
            parts = list(self._discs.values())
            discs = np.vstack(parts) if parts else np.zeros((0, 3))
            names = [name for group in self._names.values() for name in group]
            self._cache = (discs, names)
        return self._cache

    @property
    def discs(self) -> FloatArray:
        """(m, 3) discs of all sources."""
        return self._union()[0]

    @property
    def names(self) -> list[str]:
        """Names of the discs, in the order of :attr:`discs`."""
        return self._union()[1]

    def kind(self, index: int) -> str:
        """What the disc at ``index`` of :attr:`discs` is (``person``, ``dynamic``, ...)."""
        for source, names in self._names.items():
            if index < len(names):
                return self._kinds[source][index]
            index -= len(names)
        raise IndexError(index)

    def __len__(self) -> int:
        return len(self.discs)
