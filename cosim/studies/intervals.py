"""Intervals of a mean that stay inside what the runs could give.

A Student t interval over 2 or 3 seeds is wider than the runs themselves: it puts tasks per
minute below 0 and a share of free space above 1. A percentile bootstrap interval of the mean
is made of means of resampled runs, so it never leaves the range ``[min, max]`` of the runs.
Resampling is seeded (the same runs give the same interval, figure after figure).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

RESAMPLES = 2000
SEED = 0
CONFIDENCE = 0.95
POINTS_UP_TO = 10
"""Figures draw each run's value as a point when a group has at most this many runs."""


def bootstrap_interval(
    values: ArrayLike,
    *,
    confidence: float = CONFIDENCE,
    resamples: int = RESAMPLES,
    seed: int = SEED,
) -> tuple[float, float]:
    """Percentile bootstrap ``confidence`` interval of the mean of ``values`` (NaN dropped).

    Args:
        values: one value per run, in the metric's unit.
        confidence: the interval's level, in (0, 1).
        resamples: bootstrap resamples of the runs (with replacement).
        seed: seed of ``numpy.random.default_rng`` for the resamples.

    Returns:
        ``(low, high)`` in the metric's unit, inside ``[min, max]`` of the values and around
        their mean; ``(v, v)`` for one value or equal values, ``(nan, nan)`` for none.
    """
    data = np.asarray(values, dtype=float).ravel()
    data = data[~np.isnan(data)]
    if data.size == 0:
        return float("nan"), float("nan")
    mean, lo, hi = float(data.mean()), float(data.min()), float(data.max())
    if lo == hi:
        return lo, hi
    rng = np.random.default_rng(seed)
    means = data[rng.integers(0, data.size, size=(resamples, data.size))].mean(axis=1)
    tail = (1.0 - confidence) / 2.0
    low, high = np.quantile(means, [tail, 1.0 - tail])
    # A mean of n equal floats can round past them; the band must also hold the mean drawn.
    low, high = min(float(low), mean), max(float(high), mean)
    return float(np.clip(low, lo, hi)), float(np.clip(high, lo, hi))


def band_caption(
    counts: Sequence[int] | np.ndarray, *, unit: str = "seeds", dots: bool = True
) -> str:
    """The line a figure carries to say what its band is and how many values it has.

    ``"band: 95 % bootstrap interval of the mean, n = 5 seeds per point"`` (``n = 3-5`` when
    the points have different counts), and ``"; dots: each run"`` when ``dots`` and no point
    has more than :data:`POINTS_UP_TO` values (the figure then draws them).
    """
    n = np.asarray(counts, dtype=int)
    n = n[n > 0]
    lo, hi = (int(n.min()), int(n.max())) if n.size else (0, 0)
    many = f"{lo}" if lo == hi else f"{lo}-{hi}"
    text = f"band: {CONFIDENCE:.0%} bootstrap interval of the mean, n = {many} {unit} per point"
    text = text.replace("95%", "95 %")
    return text + ("; dots: each run" if dots and 0 < hi <= POINTS_UP_TO else "")


def y_limits(values: ArrayLike) -> tuple[float, float] | None:
    """Limits for a y axis whose drawn values are all equal, else None (autoscale).

    Matplotlib stretches a flat line at 0 to about ±0.05, inventing negative counts; a
    constant ``c`` gets ``(0, 1)`` at 0 and ``(c / 2, 3c / 2)`` otherwise (valid on log axes).
    """
    data = np.asarray(values, dtype=float).ravel()
    data = data[np.isfinite(data)]
    if data.size == 0 or data.min() != data.max():
        return None
    c = float(data[0])
    if c == 0.0:
        return 0.0, 1.0
    return (0.5 * c, 1.5 * c) if c > 0 else (1.5 * c, 0.5 * c)
