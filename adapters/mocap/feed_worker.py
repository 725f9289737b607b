"""The motion-capture connection, in a process of its own (started by the feed).

``motioncapture.connect`` and ``waitForNextFrame`` block inside C++ without releasing the
GIL: the Vicon backend retries a refused connection forever, OptiTrack waits for a server
that never answers. In the run's process that would freeze the kernel and Ctrl-C. Here it
freezes only this process, which the run kills when it ends or gives up on it.

Run as a script, ``python -P feed_worker.py SYSTEM HOSTNAME BODIES OPTIONS`` (``-P``: its
folder shadows no module; ``BODIES`` a JSON list of names, ``OPTIONS`` a JSON object of
backend options). It writes one JSON object per line on its standard output:
``{"connected": true}`` once connected, then per frame ``{"t": wall-clock ns, "poses":
[[body, x_m, y_m, yaw_rad], ...], "occluded": n}`` with only the wanted bodies (in the mocap
system's frame), or ``{"error": text}`` before it exits.
Anything the library prints goes to standard error. It imports nothing of cosim.
"""

from __future__ import annotations

import contextlib
import ctypes
import json
import math
import os
import signal
import sys
import time
from typing import IO, Any

PR_SET_PDEATHSIG = 1
"""Linux prctl option: a signal to receive when the parent dies."""


def yaw_of(w: float, x: float, y: float, z: float) -> float:
    """Yaw (rad) of a unit quaternion in libmotioncapture's order (w, x, y, z)."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _die_with_parent() -> None:
    """Be killed when the run's process dies, even by SIGKILL (Linux; elsewhere nothing)."""
    with contextlib.suppress(AttributeError, OSError):
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, signal.SIGKILL)


def _emit(out: IO[str], record: dict[str, Any]) -> None:
    out.write(json.dumps(record) + "\n")
    out.flush()


def frame_record(rigid_bodies: Any, wanted: set[str], now_ns: int) -> dict[str, Any]:
    """One frame's line: the wanted bodies' planar poses; non-finite ones counted occluded."""
    poses = []
    occluded = 0
    for name, body in rigid_bodies.items():
        if name not in wanted:
            continue
        x, y = (float(v) for v in list(body.position)[:2])
        q = body.rotation
        values = (x, y, float(q.w), float(q.x), float(q.y), float(q.z))
        if not all(math.isfinite(v) for v in values):
            occluded += 1
            continue
        poses.append([name, x, y, yaw_of(*values[2:])])
    return {"t": now_ns, "poses": poses, "occluded": occluded}


def serve(system: str, hostname: str, bodies: list[str], options: dict[str, str]) -> int:
    """Connect, then write frames until the connection or the reader goes away."""
    # the protocol keeps the real standard output; the library's prints go to stderr
    out = os.fdopen(os.dup(1), "w")
    os.dup2(2, 1)
    import motioncapture

    config = dict(options)
    if hostname:
        config["hostname"] = hostname
    try:
        try:
            mocap = motioncapture.connect(system, config)
        except Exception as error:  # the library raises RuntimeError with a short text
            _emit(out, {"error": str(error) or type(error).__name__})
            return 3
        _emit(out, {"connected": True})
        wanted = set(bodies)
        while True:
            try:
                mocap.waitForNextFrame()
                rigid = mocap.rigidBodies
            except Exception as error:
                _emit(out, {"error": f"connection lost: {error or type(error).__name__}"})
                return 4
            _emit(out, frame_record(rigid, wanted, time.time_ns()))
    except BrokenPipeError:  # the run stopped reading: it has closed the feed
        return 0


def main(argv: list[str]) -> int:
    """``feed_worker.py SYSTEM HOSTNAME BODIES OPTIONS``."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the run decides when the feed ends
    _die_with_parent()
    system, hostname, bodies, options = argv
    return serve(system, hostname, json.loads(bodies), json.loads(options))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
