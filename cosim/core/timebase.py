"""Kernel time: integer nanoseconds.

SimPy accepts any ordered number as time; cosim uses Python ``int`` nanoseconds so that
periodic rates are exact (10 Hz is 100_000_000 ns), latency arithmetic is exact, and ROS
timestamps come for free. User-facing configuration and tables use seconds.
"""

from __future__ import annotations

NS_PER_S = 1_000_000_000
NS_PER_MS = 1_000_000


def s_to_ns(seconds: float) -> int:
    """Convert seconds to the nearest integer nanosecond."""
    return round(seconds * NS_PER_S)


def ms_to_ns(milliseconds: float) -> int:
    """Convert milliseconds to the nearest integer nanosecond."""
    return round(milliseconds * NS_PER_MS)


def ns_to_s(nanoseconds: int) -> float:
    """Convert integer nanoseconds to float seconds."""
    return nanoseconds / NS_PER_S


def period_ns(rate_hz: float) -> int:
    """Return the period of a rate in integer nanoseconds.

    Rates whose period is not a whole number of nanoseconds (e.g. 3 Hz) are rounded to
    the nearest nanosecond; the drift is below 1 ns per period.

    Raises:
        ValueError: if the rate is not positive or above 1 GHz.
    """
    if rate_hz <= 0:
        raise ValueError(f"rate must be positive, got {rate_hz} Hz")
    if rate_hz > NS_PER_S:
        raise ValueError(f"rate {rate_hz} Hz is above 1 GHz")
    return round(NS_PER_S / rate_hz)
