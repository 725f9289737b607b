"""How a batch kernel lets its caller spread the rows of one call over threads.

A model's batch function (every robot's lidar, every robot's control) takes an optional
``slices`` argument: a function that is handed the row count and a ``rows(start, stop)``
function, and calls ``rows`` over slices that cover every row once, possibly on several
threads at once. Each row's result depends only on its own inputs, so the output is the
same whatever the cut. Models stay free of threads: the caller (an adapter holding the
run's workers) decides how to cut and where the slices run.
"""

from __future__ import annotations

from collections.abc import Callable

Rows = Callable[[int, int], None]
"""Computes rows ``[start, stop)`` of a batch into their own rows of the output."""

Slices = Callable[[int, Rows], None]
"""Calls ``rows(start, stop)`` over slices covering ``range(count)``, each exactly once."""


def whole(count: int, rows: Rows) -> None:
    """The one-slice cut: ``rows(0, count)`` on the calling thread."""
    rows(0, count)


__all__ = ["Rows", "Slices", "whole"]
