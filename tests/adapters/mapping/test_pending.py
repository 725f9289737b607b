"""Each thread maps with its own scratch: the same one every time on a thread, none shared."""

from __future__ import annotations

import threading

import pytest

from adapters.mapping.pending import ThreadScratch
from models.mapping.grid import LogOddsMap, MapGeometry


def _geometry() -> MapGeometry:
    return MapGeometry.covering((0.0, 0.0, 4.0, 3.0), 0.1)


def test_a_thread_gets_the_same_scratch_each_time_and_another_thread_its_own() -> None:
    scratches = ThreadScratch(_geometry())
    mine = scratches.mine()
    assert scratches.mine() is mine
    theirs: list[object] = []
    other = threading.Thread(target=lambda: theirs.append(scratches.mine()))
    other.start()
    other.join()
    assert theirs[0] is not mine


def test_a_map_takes_a_scratch_of_its_shape_and_refuses_another() -> None:
    geometry = _geometry()
    grid = LogOddsMap(geometry)
    scratch = ThreadScratch(geometry).mine()
    grid.scratch = scratch
    assert grid.scratch is scratch
    wrong = ThreadScratch(MapGeometry.covering((0.0, 0.0, 8.0, 3.0), 0.1)).mine()
    with pytest.raises(ValueError, match="a scratch of shape"):
        grid.scratch = wrong
