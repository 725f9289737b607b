"""A live motion-capture system through the ``motioncapture`` library (libmotioncapture).

The library speaks to Vicon, OptiTrack, Qualisys, VRPN and other systems (whatever its
build supports) and offers a ``mock`` backend whose rigid bodies are given as
``name(x,y,z,qw,qx,qy,qz);...``. Its calls block in C++ holding the GIL (a Vicon server
that refuses the connection is retried forever), so the connection lives in a process of
its own (:mod:`adapters.mocap.feed_worker`): the run's process only reads lines from a
pipe, on a daemon thread, and can always give up on the system, stop on Ctrl-C and kill
the worker. Per tracked body the poses are kept in arrival order, stamped with the wall
clock when the frame came in; the simulation drains them from its own thread. Occluded
bodies (NaN positions) are counted and skipped.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import tempfile
import threading
from collections import deque
from collections.abc import Sequence
from pathlib import Path
from types import TracebackType
from typing import IO, Any

from adapters.mocap import feed_worker
from cosim.core.errors import BridgeError
from models.geometry.se2 import yaw_of_quaternion

__all__ = ["SYSTEMS", "MotionCaptureFeed", "mock_bodies", "quaternion_yaw"]

SYSTEMS = ("vicon", "optitrack", "qualisys", "vrpn", "mock")
"""Backends the motioncapture 1.1 wheel supports (others: "Unknown motion capture type!")."""

BUFFER = 4096
"""Poses kept between two drains; older ones are dropped and counted."""

STOP_WAIT_S = 0.5
"""How long a closed feed's worker gets to end on SIGTERM before it is killed (s)."""

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
    """Rigid-body poses from a live mocap system, read from a worker process.

    Connecting does not wait: :attr:`connected`, :attr:`frames` and :meth:`failure` say
    how far the system got, so the caller decides how long to wait for it.

    Args:
        system: the backend (``vicon``, ``optitrack``, ``qualisys``, ``vrpn``, ``mock``).
        hostname: the mocap server's address ("" for the backend's default).
        bodies: the rigid bodies to keep.
        options: further backend options (e.g. ``rigid_bodies`` for ``mock``).

    Raises:
        BridgeError: an unknown backend, or the worker process cannot be started.
    """

    def __init__(
        self,
        system: str,
        *,
        hostname: str = "",
        bodies: Sequence[str],
        options: dict[str, str] | None = None,
    ) -> None:
        self.system = system
        self.hostname = hostname
        if system not in SYSTEMS:
            raise BridgeError(
                f"motion capture {system!r}{self._at()}: unknown system (expected one of "
                f"{', '.join(SYSTEMS)}, as this build of motioncapture supports)"
            )
        self.bodies = tuple(bodies)
        self._seen: set[str] = set()
        self._buffer: deque[Sample] = deque()
        self._lock = threading.Lock()
        self.connected = False
        """Whether the system accepted the connection."""
        self.frames = 0
        self.occluded = 0
        self.overflow = 0
        self._failure: str | None = None
        self._closed = False
        # the worker's standard error, quoted when it fails; closed by close()
        self._stderr: IO[bytes] = tempfile.TemporaryFile()  # noqa: SIM115
        command = [
            sys.executable,
            "-P",
            str(Path(feed_worker.__file__)),
            system,
            hostname,
            json.dumps(list(self.bodies)),
            json.dumps(dict(options or {})),
        ]
        try:
            self._process = subprocess.Popen(
                command,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE,
                stderr=self._stderr,
                start_new_session=True,  # Ctrl-C at the terminal is the run's to handle
            )
        except OSError as error:
            self._stderr.close()
            raise BridgeError(
                f"motion capture {system!r}{self._at()}: cannot start its worker process ({error})"
            ) from None
        self._thread = threading.Thread(target=self._read, name=f"mocap-{system}", daemon=True)
        self._thread.start()

    def _at(self) -> str:
        return f" at {self.hostname!r}" if self.hostname else ""

    def _read(self) -> None:
        """Take the worker's lines until it ends (its pipe closes)."""
        stdout = self._process.stdout
        assert stdout is not None
        for line in stdout:
            try:
                record: dict[str, Any] = json.loads(line)
            except ValueError:
                continue  # not the worker's (nothing else writes there), never trusted
            if "error" in record:
                with self._lock:
                    self._failure = str(record["error"])
            elif record.get("connected"):
                self.connected = True
            else:
                self._frame(record)
        code = self._process.wait()
        with self._lock:
            if self._failure is None and not self._closed:
                self._failure = f"its worker process ended (status {code}){self._said()}"

    def _frame(self, record: dict[str, Any]) -> None:
        now = int(record["t"])
        samples = [
            (now, str(name), float(x), float(y), float(yaw)) for name, x, y, yaw in record["poses"]
        ]
        with self._lock:
            self.frames += 1
            self.occluded += int(record["occluded"])
            self._seen.update(s[1] for s in samples)
            self._buffer.extend(samples)
            while len(self._buffer) > BUFFER:
                self._buffer.popleft()
                self.overflow += 1

    def _said(self) -> str:
        """The worker's last line on standard error, quoted (or nothing)."""
        self._stderr.seek(0)
        lines = [
            ln.strip()
            for ln in self._stderr.read()[-2000:].decode(errors="replace").splitlines()
            if ln.strip()
        ]
        return f": {lines[-1]!r}" if lines else ""

    def failure(self) -> str | None:
        """Why the feed delivers nothing more (the library's words), or None while it runs."""
        with self._lock:
            return self._failure

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
        """End the worker (SIGTERM, then SIGKILL) and the reading thread."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
        process = self._process
        if process.poll() is None:
            process.terminate()
            try:
                process.wait(timeout=STOP_WAIT_S)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
        self._thread.join(timeout=1.0)
        if process.stdout is not None:
            process.stdout.close()
        self._stderr.close()

    def __enter__(self) -> MotionCaptureFeed:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        value: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()
