"""The one-slice cut: every row, once, on the calling thread."""

from __future__ import annotations

from models.slicing import whole


def test_the_whole_cut_hands_every_row_over_in_one_slice() -> None:
    calls: list[tuple[int, int]] = []
    whole(7, lambda start, stop: calls.append((start, stop)))
    assert calls == [(0, 7)]
    whole(0, lambda start, stop: calls.append((start, stop)))
    assert calls[-1] == (0, 0)
