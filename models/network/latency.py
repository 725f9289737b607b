"""One-way latency distributions of a link.

Every model draws latencies in milliseconds and returns them as integer nanoseconds,
rounded to the nearest nanosecond with ties to even (``numpy.rint``): a draw of
0.0000005 ms becomes 0 ns, 0.0000015 ms becomes 2 ns. Draws are never negative.

``cdf`` is the cumulative distribution of the latency in ms *before* rounding, so that
``scipy.stats.kstest(sample_ns / 1e6, model.cdf)`` checks a sample against the model
(rounding to 1 ns moves a value by at most 5e-7 ms).
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np
import numpy.typing as npt
from scipy.special import ndtr

from models.arrays import FloatArray, IntArray
from models.errors import ModelError

NS_PER_MS = 1_000_000
LATENCY_KEY = "network.latency_ms"
JITTER_KEY = "network.jitter_ms"
CSV_KEY = "network.latency_csv"


class LatencyModel(Protocol):
    """A latency distribution: vectorized draws in ns, and its CDF in ms."""

    @property
    def mean_ms(self) -> float:
        """The configured mean latency (ms); see each model for what exactly it is."""
        ...

    def sample(self, rng: np.random.Generator, n: int) -> IntArray:
        """Draw ``n`` latencies (ns, >= 0) from ``rng``."""
        ...

    def cdf(self, x_ms: npt.ArrayLike) -> FloatArray:
        """P(latency <= x_ms), elementwise, for latencies in ms before rounding."""
        ...


def ms_to_ns(values_ms: npt.ArrayLike) -> IntArray:
    """Milliseconds to integer nanoseconds, round half to even (``numpy.rint``)."""
    return np.rint(np.asarray(values_ms, dtype=np.float64) * NS_PER_MS).astype(np.int64)


def _non_negative(key: str, value: float) -> float:
    value = float(value)
    if not math.isfinite(value) or value < 0.0:
        raise ModelError(key, value, "a finite number of milliseconds >= 0")
    return value


@dataclass(frozen=True)
class ConstantLatency:
    """Every message takes exactly ``latency_ms``.

    Attributes:
        latency_ms: the latency (ms, >= 0).
    """

    latency_ms: float

    def __post_init__(self) -> None:
        _non_negative(LATENCY_KEY, self.latency_ms)

    @property
    def mean_ms(self) -> float:
        """The latency (ms)."""
        return float(self.latency_ms)

    def sample(self, rng: np.random.Generator, n: int) -> IntArray:
        """``n`` copies of the latency (ns); ``rng`` is not used."""
        return np.full(n, ms_to_ns(self.latency_ms), dtype=np.int64)

    def cdf(self, x_ms: npt.ArrayLike) -> FloatArray:
        """A step from 0 to 1 at ``latency_ms``."""
        return (np.asarray(x_ms, dtype=np.float64) >= self.latency_ms).astype(np.float64)


@dataclass(frozen=True)
class NormalLatency:
    """A normal latency truncated at 0: negative draws are drawn again.

    The density is that of N(mean_ms, jitter_ms^2) restricted to [0, inf) and rescaled.
    Sampling: ``x = rng.normal(mean_ms, jitter_ms, n)``; then, while some entries are
    negative, exactly those entries are replaced by a new vectorized draw of their size.
    With ``jitter_ms == 0`` every draw is ``mean_ms`` and ``rng`` is not used.

    Attributes:
        mean_ms: mean of the normal before truncation (ms, >= 0). The draws have the
            larger mean :attr:`truncated_mean_ms`; the two agree to 1e-6 relative once
            ``mean_ms >= 5 * jitter_ms``.
        jitter_ms: standard deviation of the normal before truncation (ms, >= 0).
    """

    mean_ms: float
    jitter_ms: float

    def __post_init__(self) -> None:
        _non_negative(LATENCY_KEY, self.mean_ms)
        _non_negative(JITTER_KEY, self.jitter_ms)

    @property
    def truncated_mean_ms(self) -> float:
        """Mean of the draws (ms): ``mu + sigma * phi(a) / (1 - Phi(a))``, ``a = -mu/sigma``."""
        mu, sigma = self.mean_ms, self.jitter_ms
        if sigma == 0.0:
            return float(mu)
        a = -mu / sigma
        phi = math.exp(-0.5 * a * a) / math.sqrt(2.0 * math.pi)
        return float(mu + sigma * phi / float(ndtr(-a)))

    def sample(self, rng: np.random.Generator, n: int) -> IntArray:
        """Draw ``n`` latencies (ns) as described in the class docstring."""
        if self.jitter_ms == 0.0:
            return np.full(n, ms_to_ns(self.mean_ms), dtype=np.int64)
        x = rng.normal(self.mean_ms, self.jitter_ms, n)
        redo = np.flatnonzero(x < 0.0)
        while redo.size:
            x[redo] = rng.normal(self.mean_ms, self.jitter_ms, redo.size)
            redo = redo[x[redo] < 0.0]
        return ms_to_ns(x)

    def cdf(self, x_ms: npt.ArrayLike) -> FloatArray:
        """``(Phi((x - mu)/sigma) - Phi(-mu/sigma)) / (1 - Phi(-mu/sigma))`` for x >= 0."""
        x = np.asarray(x_ms, dtype=np.float64)
        if self.jitter_ms == 0.0:
            return (x >= self.mean_ms).astype(np.float64)
        mu, sigma = self.mean_ms, self.jitter_ms
        below = float(ndtr(-mu / sigma))
        inside = (ndtr((x - mu) / sigma) - below) / (1.0 - below)
        return np.where(x < 0.0, 0.0, np.clip(inside, 0.0, 1.0)).astype(np.float64)


@dataclass(frozen=True)
class LognormalLatency:
    """A lognormal latency whose mean and standard deviation are ``mean_ms`` and ``jitter_ms``.

    With m = mean_ms and s = jitter_ms, the underlying normal of ln(latency / 1 ms) has

    * ``sigma^2 = ln(1 + (s/m)^2)``,
    * ``mu = ln(m) - sigma^2 / 2``,

    which inverts ``E = exp(mu + sigma^2/2)`` and ``Var = (exp(sigma^2) - 1) * E^2``.
    With ``jitter_ms == 0`` every draw is ``mean_ms`` and ``rng`` is not used.

    Attributes:
        mean_ms: mean latency (ms); > 0 when ``jitter_ms > 0``.
        jitter_ms: standard deviation of the latency (ms, >= 0).
    """

    mean_ms: float
    jitter_ms: float

    def __post_init__(self) -> None:
        _non_negative(LATENCY_KEY, self.mean_ms)
        _non_negative(JITTER_KEY, self.jitter_ms)
        if self.jitter_ms > 0.0 and self.mean_ms == 0.0:
            raise ModelError(LATENCY_KEY, self.mean_ms, "> 0 for a lognormal latency with jitter")

    @property
    def sigma(self) -> float:
        """Standard deviation of ln(latency) (dimensionless)."""
        if self.jitter_ms == 0.0:
            return 0.0
        return math.sqrt(math.log1p((self.jitter_ms / self.mean_ms) ** 2))

    @property
    def mu(self) -> float:
        """Mean of ln(latency / 1 ms)."""
        return math.log(self.mean_ms) - 0.5 * self.sigma**2

    def sample(self, rng: np.random.Generator, n: int) -> IntArray:
        """Draw ``n`` latencies (ns) with ``rng.lognormal(mu, sigma, n)``."""
        if self.jitter_ms == 0.0:
            return np.full(n, ms_to_ns(self.mean_ms), dtype=np.int64)
        return ms_to_ns(rng.lognormal(self.mu, self.sigma, n))

    def cdf(self, x_ms: npt.ArrayLike) -> FloatArray:
        """``Phi((ln x - mu) / sigma)`` for x > 0, 0 below."""
        x = np.asarray(x_ms, dtype=np.float64)
        if self.jitter_ms == 0.0:
            return (x >= self.mean_ms).astype(np.float64)
        with np.errstate(divide="ignore", invalid="ignore"):
            z = (np.log(np.where(x > 0.0, x, 1.0)) - self.mu) / self.sigma
        return np.where(x > 0.0, ndtr(z), 0.0).astype(np.float64)


class EmpiricalLatency:
    """Bootstrap latencies: each draw is one of the measured samples, uniformly at random.

    Sampling: ``samples[rng.integers(0, len(samples), n)]`` over the samples in the order
    given, converted to ns.

    Args:
        samples_ms: measured one-way delays (ms): at least one, all finite and >= 0.

    Raises:
        ModelError: ``network.latency_csv`` if there is no sample or one is negative,
            infinite or NaN.
    """

    def __init__(self, samples_ms: npt.ArrayLike) -> None:
        samples = np.array(samples_ms, dtype=np.float64).ravel()
        if samples.size == 0:
            raise ModelError(CSV_KEY, "[]", "at least one delay sample")
        bad = np.flatnonzero(~np.isfinite(samples) | (samples < 0.0))
        if bad.size:
            raise ModelError(CSV_KEY, float(samples[bad[0]]), "delays in ms, finite and >= 0")
        samples.setflags(write=False)
        self._samples_ms = samples
        self._samples_ns = ms_to_ns(samples)
        self._sorted_ms = np.sort(samples)

    @classmethod
    def from_csv(cls, path: str | Path) -> EmpiricalLatency:
        """Build from a CSV of delays (see :func:`load_delay_csv`)."""
        return cls(load_delay_csv(path))

    @property
    def samples_ms(self) -> FloatArray:
        """The measured samples (ms), read-only, in the order given."""
        return self._samples_ms

    @property
    def mean_ms(self) -> float:
        """Mean of the samples (ms)."""
        return float(self._samples_ms.mean())

    def sample(self, rng: np.random.Generator, n: int) -> IntArray:
        """Draw ``n`` latencies (ns) with replacement from the samples."""
        return self._samples_ns[rng.integers(0, self._samples_ns.size, n)]

    def cdf(self, x_ms: npt.ArrayLike) -> FloatArray:
        """The empirical CDF of the samples: the fraction of samples <= x."""
        x = np.asarray(x_ms, dtype=np.float64)
        below = np.searchsorted(self._sorted_ms, x, side="right")
        return (below / self._sorted_ms.size).astype(np.float64)

    def __repr__(self) -> str:
        return f"EmpiricalLatency({self._samples_ms.size} samples, mean {self.mean_ms:g} ms)"


def load_delay_csv(path: str | Path) -> FloatArray:
    """Read measured one-way delays (ms) from a CSV file.

    The file holds one delay per row. An optional first row is a header: it is taken to be
    one when any of its cells is not a number; the column named ``delay_ms`` is then read,
    or the only column if there is just one. Blank lines are ignored anywhere.

    Args:
        path: the CSV file (UTF-8, a byte-order mark is accepted).

    Returns:
        The delays (ms) in file order.

    Raises:
        ModelError: ``network.latency_csv`` = the path, when the file is missing or
            unreadable, holds no delay, has a header without a ``delay_ms`` column, or a
            value that is not a finite number >= 0 (the message names the line).
    """
    path = Path(path)
    where = str(path)
    try:
        with path.open(newline="", encoding="utf-8-sig") as handle:
            reader = csv.reader(handle)
            # reader.line_num is the physical line of the row just read (1-based)
            rows = [(reader.line_num, row) for row in reader if any(c.strip() for c in row)]
    except (OSError, UnicodeDecodeError, csv.Error) as error:
        raise ModelError(CSV_KEY, where, f"a readable CSV file of delays in ms ({error})") from None
    if not rows:
        raise ModelError(CSV_KEY, where, "at least one delay in ms, one per row")
    column = 0
    first_line, header = rows[0]
    if not all(_is_number(cell) for cell in header):
        names = [cell.strip() for cell in header]
        if "delay_ms" in names:
            column = names.index("delay_ms")
        elif len(names) != 1:
            raise ModelError(
                CSV_KEY, where, f"a header with a column named delay_ms on line {first_line}"
            )
        rows = rows[1:]
    elif len(header) != 1:
        raise ModelError(
            CSV_KEY, where, f"one delay per row, or a header naming delay_ms, on line {first_line}"
        )
    if not rows:
        raise ModelError(CSV_KEY, where, "at least one delay in ms below the header")
    values = np.empty(len(rows), dtype=np.float64)
    for k, (line, row) in enumerate(rows):
        cell = row[column].strip() if column < len(row) else ""
        try:
            value = float(cell)
        except ValueError:
            raise ModelError(
                CSV_KEY, where, f"a delay in ms on line {line}, got {cell!r}"
            ) from None
        if not math.isfinite(value) or value < 0.0:
            raise ModelError(CSV_KEY, where, f"a finite delay >= 0 ms on line {line}, got {cell!r}")
        values[k] = value
    return values


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True
