"""A live motion-capture system through the ``motioncapture`` library (libmotioncapture).

The library speaks to Vicon, OptiTrack, Qualisys, VRPN and other systems (whatever its
build supports) and offers a ``mock`` backend whose rigid bodies are given as
``name(x,y,z,qw,qx,qy,qz);...``. A daemon thread waits for frames and keeps, per tracked
body, the poses in arrival order, stamped with the wall clock when the frame came in; the
simulation drains them from its own thread. Occluded bodies (NaN positions) are counted
and skipped.
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from collections.abc import Sequence
from types import TracebackType

import motioncapture

from cosim.core.errors import BridgeError
from models.mapping.se2 import yaw_of_quaternion

SYSTEMS = ("vicon", "optitrack", "qualisys", "vrpn", "mock")
"""Backends the motioncapture 1.1 wheel supports (others: "Unknown motion capture type!")."""

BUFFER = 4096
"""Poses kept between two drains; older ones are dropped and counted."""

Sample = tuple[int, str, float, float, float]
"""(wall-clock ns, body, x_m, y_m, yaw_rad) in the mocap system's frame."""


def quaternion_yaw(w: float, x: float, y: float, z: float) -> float:
    """Yaw (rad) of a rotation quaternion in libmotioncapture's order (w, x, y, z)."""
    return yaw_of_quaternion(x, y, z, w)


def mock_bodies(poses: dict[str, tuple[float, float, float]]) -> str:
    """The ``rigid_bodies`` option of the mock backend holding bodies at planar poses."""
    parts = []
    for name, (x, y, yaw) in poses.items():
        w, z = math.cos(yaw / 2), math.sin(yaw / 2)
        values = ",".join(repr(float(v)) for v in (x, y, 0.0, w, 0.0, 0.0, z))
        parts.append(f"{name}({values})")
    return ";".join(parts)


class MotionCaptureFeed:
    """Rigid-body poses from a live mocap system, gathered on a background thread.

    Args:
        system: the backend (``vicon``, ``optitrack``, ``qualisys``, ``vrpn``, ``mock``, ...).
        hostname: the mocap server's address ("" for the backend's default).
        bodies: the rigid bodies to keep.
        options: further backend options (e.g. ``rigid_bodies`` for ``mock``).

    Raises:
        BridgeError: unknown backend, or the system cannot be reached.
    """

    def __init__(
        self,
        system: str,
        *,
        hostname: str = "",
        bodies: Sequence[str],
        options: dict[str, str] | None = None,
    ) -> None:
        config = dict(options or {})
        if hostname:
            config["hostname"] = hostname
        try:
            self._mocap = motioncapture.connect(system, config)
        except Exception as error:  # the library raises RuntimeError with a short text
            where = f" at {hostname!r}" if hostname else ""
            raise BridgeError(
                f"motion capture {system!r}{where}: {error} (expected one of "
                f"{', '.join(SYSTEMS)}, as this build of motioncapture supports, and a "
                "reachable server)"
            ) from None
        self.bodies = tuple(bodies)
        self._wanted = set(self.bodies)
        self._seen: set[str] = set()
        self._buffer: deque[Sample] = deque()
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self.frames = 0
        self.occluded = 0
        self.overflow = 0
        self._thread = threading.Thread(target=self._loop, name=f"mocap-{system}", daemon=True)
        self._thread.start()

    def _loop(self) -> None:
        mocap = self._mocap
        while not self._stop.is_set():
            try:
                mocap.waitForNextFrame()
                bodies = mocap.rigidBodies
            except Exception:  # a dropped connection ends the feed; stale poses stop robots
                return
            now = time.time_ns()
            samples = []
            for name, body in bodies.items():
                if name not in self._wanted:
                    continue
                x, y = (float(v) for v in list(body.position)[:2])
                q = body.rotation
                if not all(math.isfinite(v) for v in (x, y, q.w, q.x, q.y, q.z)):
                    self.occluded += 1
                    continue
                samples.append((now, name, x, y, quaternion_yaw(q.w, q.x, q.y, q.z)))
            with self._lock:
                self.frames += 1
                self._seen.update(s[1] for s in samples)
                self._buffer.extend(samples)
                while len(self._buffer) > BUFFER:
                    self._buffer.popleft()
                    self.overflow += 1

    def drain(self) -> list[Sample]:
        """The poses gathered since the last call, in arrival order."""
        with self._lock:
            samples = list(self._buffer)
            self._buffer.clear()
        return samples

    def missing_bodies(self) -> list[str]:
        """Tracked bodies never seen in a frame."""
        with self._lock:
            return [b for b in self.bodies if b not in self._seen]

    def close(self) -> None:
        """Stop the thread (it ends after the frame it is waiting for)."""
        self._stop.set()
        self._thread.join(timeout=1.0)

    def __enter__(self) -> MotionCaptureFeed:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()
