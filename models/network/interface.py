"""A sending interface: messages leave one after another at the link rate (FIFO)."""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from models.errors import ModelError

NS_PER_S = 1_000_000_000


class InterfaceQueue:
    """Serializes the messages a host sends, first in, first out.

    A message starts when the previous one has left and takes ``ceil(8 * nbytes / rate)``
    to leave, in integer ns. The rate is turned into an exact integer ratio
    (``float.as_integer_ratio``), so the arithmetic is exact: at 1 Mbit/s a 1,250-byte
    message takes exactly 10,000,000 ns. Rounding up means a message never leaves earlier
    than the rate allows, and a non-empty message always takes at least 1 ns.

    Args:
        rate_bps: link rate (bit/s, > 0), or ``None`` for unlimited: messages leave at once
            and the queue is never full.
        limit_packets: how many messages may wait to start (>= 0), not counting the one in
            transmission; a message arriving when that many wait is refused.

    Raises:
        ModelError: ``network.bandwidth_mbps`` (value in Mbit/s) for a rate that is not a
            finite number > 0; ``network.queue_packets`` for a negative limit.
    """

    __slots__ = ("_den", "_last_t_ns", "_leaving", "_num", "limit_packets", "rate_bps")

    def __init__(self, rate_bps: float | None, limit_packets: int) -> None:
        if rate_bps is not None and not (math.isfinite(rate_bps) and rate_bps > 0):
            raise ModelError("network.bandwidth_mbps", rate_bps / 1e6, "a number > 0, or none")
        if (
            isinstance(limit_packets, bool)
            or not isinstance(limit_packets, int | np.integer)
            or limit_packets < 0
        ):
            raise ModelError("network.queue_packets", limit_packets, "an integer >= 0")
        self.rate_bps = rate_bps
        self.limit_packets = int(limit_packets)
        # serialization of n bytes = ceil(n * 8e9 * den / num) ns for rate = num / den bit/s
        num, den = (1, 1) if rate_bps is None else float(rate_bps).as_integer_ratio()
        self._num = num
        self._den = 8 * NS_PER_S * den
        self._leaving: deque[int] = deque()  # departure times (ns) of messages not yet gone
        self._last_t_ns = -(2**63)

    def serialization_ns(self, nbytes: int) -> int:
        """Time (ns) to put ``nbytes`` on the link, rounded up; 0 when unlimited."""
        if self.rate_bps is None:
            return 0
        return -(-nbytes * self._den // self._num)

    def backlog(self, t_ns: int) -> int:
        """Messages in the interface at ``t_ns`` (waiting or in transmission)."""
        leaving = self._leaving
        while leaving and leaving[0] <= t_ns:
            leaving.popleft()
        return len(leaving)

    def enqueue(self, t_ns: int, nbytes: int) -> int | None:
        """Offer a message of ``nbytes`` at ``t_ns`` (ns).

        Args:
            t_ns: when the message is handed to the interface; never earlier than the
                previous call's.
            nbytes: message size (bytes, >= 0).

        Returns:
            The time (ns) its last bit leaves, or ``None`` when ``limit_packets`` messages
            are already waiting (the message is dropped: queue full).

        Raises:
            ValueError: if ``t_ns`` is earlier than a previous call's.
        """
        if t_ns < self._last_t_ns:
            raise ValueError(f"enqueue at {t_ns} ns after a message at {self._last_t_ns} ns")
        self._last_t_ns = t_ns
        if self.rate_bps is None:
            return t_ns
        leaving = self._leaving
        while leaving and leaving[0] <= t_ns:
            leaving.popleft()
        # the head of the queue is in transmission: it started at or before t_ns
        if len(leaving) > self.limit_packets:
            return None
        start = leaving[-1] if leaving else t_ns
        done = start + -(-nbytes * self._den // self._num)
        leaving.append(done)
        return done
