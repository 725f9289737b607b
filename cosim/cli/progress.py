"""A one-line progress display for long runs (only on a terminal)."""

from __future__ import annotations

import sys
from typing import TextIO


class ProgressLine:
    """Rewrites one terminal line with sim time, percentage and real-time factor.

    Args:
        stream: where to write; nothing is written unless it is a terminal.
        label: text in front of the figures.
    """

    def __init__(self, stream: TextIO | None = None, label: str = "") -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.enabled = self.stream.isatty()
        self.label = label
        self._width = 0

    def __call__(self, sim_s: float, duration_s: float, wall_s: float) -> None:
        """Show progress: simulated time of the total, and the real-time factor so far."""
        if not self.enabled:
            return
        rtf = sim_s / wall_s if wall_s > 0 else 0.0
        pct = 100.0 * sim_s / duration_s if duration_s > 0 else 100.0
        text = (
            f"{self.label}t = {sim_s:8.2f} / {duration_s:g} s  {pct:5.1f} %  "
            f"{rtf:8.1f}x real time  {wall_s:6.1f} s wall"
        )
        pad = max(0, self._width - len(text))
        self.stream.write("\r" + text + " " * pad)
        self.stream.flush()
        self._width = len(text)

    def close(self) -> None:
        """End the progress line."""
        if self.enabled and self._width:
            self.stream.write("\n")
            self.stream.flush()
