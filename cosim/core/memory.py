"""The memory a run may take, and the one-line refusal of settings that would need more.

A grid sized from a cell-size key (``navigation.resolution_m``, ``mapping.resolution_m``)
grows with the inverse square of the key; a value near its bound can ask for gigabytes,
which numpy refuses with a ``MemoryError`` in the middle of the run (or the kernel's
out-of-memory killer ends it without a word). A capability estimates what its grids will
take before anything is built (``check_scenario``), and refuses a value that does not fit
in the memory this process has left, naming the key, the value, the estimate, the room and
a value that fits.

The room is the least of: the memory the system can give without swapping
(``MemAvailable`` of ``/proc/meminfo``), what the process's control group allows beyond
what it uses (cgroup v2 ``memory.max``, v1 ``memory.limit_in_bytes``), and what
``ulimit -v`` (``RLIMIT_AS``) and ``ulimit -d`` (``RLIMIT_DATA``) leave beyond what the
process maps already. Where none of these can be read, nothing is refused.
"""

from __future__ import annotations

import math
import os
import resource
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

NO_LIMIT = 1 << 60
"""A cgroup limit at or above this is none (cgroup v1 writes a huge number)."""


@dataclass(frozen=True)
class Room:
    """Memory this process may still take.

    Attributes:
        bytes: how much (bytes).
        source: what limits it, as messages say it (``MemAvailable``, ``ulimit -v``).
    """

    bytes: int
    source: str


def _read_int(path: Path) -> int | None:
    try:
        text = path.read_text(encoding="ascii").strip()
    except (OSError, UnicodeDecodeError):
        return None
    return int(text) if text.isdigit() else None


def _proc_kib(path: Path, field: str) -> int | None:
    """A ``Field:  123 kB`` line of a /proc file, in bytes."""
    try:
        lines = path.read_text(encoding="ascii").splitlines()
    except (OSError, UnicodeDecodeError):
        return None
    for line in lines:
        name, _, rest = line.partition(":")
        if name == field and rest.split() and rest.split()[0].isdigit():
            return int(rest.split()[0]) * 1024
    return None


def _rooms() -> list[Room]:
    rooms = []
    free = _proc_kib(Path("/proc/meminfo"), "MemAvailable")
    if free is not None:
        rooms.append(Room(free, "MemAvailable in /proc/meminfo"))
    for limit_file, usage_file, name in (
        ("memory.max", "memory.current", "the cgroup's memory.max"),
        ("memory/memory.limit_in_bytes", "memory/memory.usage_in_bytes", "the cgroup's limit"),
    ):
        limit = _read_int(Path("/sys/fs/cgroup") / limit_file)
        usage = _read_int(Path("/sys/fs/cgroup") / usage_file)
        if limit is not None and usage is not None and limit < NO_LIMIT:
            rooms.append(Room(max(limit - usage, 0), name))
    for kind, field, name in (
        (resource.RLIMIT_AS, "VmSize", "ulimit -v"),
        (resource.RLIMIT_DATA, "VmData", "ulimit -d"),
    ):
        soft, _hard = resource.getrlimit(kind)
        used = _proc_kib(Path("/proc/self/status"), field)
        if soft != resource.RLIM_INFINITY and used is not None:
            rooms.append(Room(max(soft - used, 0), name))
    if not rooms:
        try:
            pages = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        except (ValueError, OSError):
            return []
        rooms.append(Room(pages, "free physical memory"))
    return rooms


def available() -> Room | None:
    """The memory this process may still take, and what limits it; None if unknown."""
    rooms = _rooms()
    return min(rooms, key=lambda room: room.bytes) if rooms else None


def size_text(count: int | float) -> str:
    """Bytes as people read them: ``611 MiB``, ``7.7 GiB``."""
    for unit, scale in (("TiB", 1 << 40), ("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)):
        if count >= scale:
            value = count / scale
            return f"{value:.1f} {unit}" if value < 100 else f"{value:,.0f} {unit}"
    return f"{int(count)} bytes"


def _round_up(value: float) -> float:
    """``value`` rounded up to two significant digits (0.01234 -> 0.013)."""
    if value <= 0:
        return value
    step = 10.0 ** (math.floor(math.log10(value)) - 1)
    return round(math.ceil(value / step - 1e-9) * step, 12)


def smallest_fitting(
    need: Callable[[float], int], low: float, high: float, room: int
) -> float | None:
    """The smallest cell size in ``[low, high]`` (two digits, rounded up) whose ``need`` fits.

    Args:
        need: bytes needed at a cell size (m); it must not grow with the cell size.
        low: a cell size that does not fit (m).
        high: the largest cell size the key allows (m).
        room: the bytes available.

    Returns:
        The cell size (m), or None when even ``high`` does not fit.
    """
    if need(high) > room:
        return None
    for _ in range(60):  # bisection on a log scale: far finer than two digits
        middle = math.sqrt(low * high)
        if need(middle) > room:
            low = middle
        else:
            high = middle
    fits = _round_up(high)
    return fits if need(fits) <= room else high


__all__ = ["Room", "available", "size_text", "smallest_fitting"]
