"""Child processes that do not outlive the process that started them.

A run or a study killed outright (``kill -9``, the out-of-memory killer) runs no clean-up:
the processes it started (stand-in robots, study workers) would go on for good. Linux can
kill a child when its parent dies (``prctl(PR_SET_PDEATHSIG)``); elsewhere this does
nothing and the callers watch their parent themselves.
"""

from __future__ import annotations

import ctypes
import signal
import sys

PR_SET_PDEATHSIG = 1
"""``prctl`` option: the signal this process gets when its parent thread dies (Linux)."""


def die_with_parent(sig: int = signal.SIGKILL) -> bool:
    """Ask Linux to send ``sig`` to this process when its parent dies.

    Call it in the child (e.g. as ``subprocess.Popen``'s ``preexec_fn``).

    Returns:
        Whether the kernel took it (False off Linux, or without ``prctl``).
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return int(libc.prctl(PR_SET_PDEATHSIG, int(sig), 0, 0, 0)) == 0
    except (OSError, AttributeError):
        return False
