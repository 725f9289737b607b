"""A test client behaving as Unity's ROS-TCP-Connector 0.7 does in ROS 2 mode.

Written from the Connector's sources (``ROSConnection.cs``, ``MessageSerializer.cs``,
``SysCommand.cs``): it writes its destination and JSON strings with a trailing NUL and a
length counting it, sends 8 zero bytes as a keepalive, expects ``__handshake`` first, and
re-sends every registration when it reconnects.
"""

from __future__ import annotations

import json
import math
import socket
import struct
import time
from typing import Any

U32 = struct.Struct("<I")


def connector_string(text: str) -> bytes:
    """A string as the Connector writes it in ROS 2 mode: length + UTF-8 + NUL."""
    data = text.encode("utf-8") + b"\x00"
    return U32.pack(len(data)) + data


class Connector:
    """One connection of a Unity scene to an endpoint on ``port``."""

    def __init__(self, port: int, host: str = "127.0.0.1") -> None:
        self.host, self.port = host, port
        self.registrations: list[tuple[str, dict[str, Any]]] = []
        self.sock = self._open()

    def _open(self) -> socket.socket:
        deadline = time.monotonic() + 60.0  # the run may still be assembling
        while True:
            try:
                sock = socket.create_connection((self.host, self.port), timeout=5.0)
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.05)
        sock.sendall(b"\x00" * 8)  # the Connector's first bytes: a keepalive
        return sock

    def reconnect(self) -> None:
        """Drop the connection and open another, registering everything again."""
        self.close()
        self.sock = self._open()
        for name, params in self.registrations:
            self.command(name, params, remember=False)

    def command(self, name: str, params: dict[str, Any], *, remember: bool = True) -> None:
        """Send a system command; registrations are kept for a reconnection."""
        if remember and name in ("__subscribe", "__publish"):
            self.registrations.append((name, params))
        self.sock.sendall(connector_string(name) + connector_string(json.dumps(params)))

    def publish(self, topic: str, cdr: bytes) -> None:
        """Send a message (CDR with its 00 01 00 00 header) on ``topic``."""
        self.sock.sendall(connector_string(topic) + U32.pack(len(cdr)) + cdr)

    def _exactly(self, size: int) -> bytes:
        data = b""
        while len(data) < size:
            chunk = self.sock.recv(size - len(data))
            if not chunk:
                raise ConnectionError("the endpoint closed the connection")
            data += chunk
        return data

    def read(self) -> tuple[str, bytes]:
        """The next frame (keepalives included: destination ``""``)."""
        (size,) = U32.unpack(self._exactly(4))
        destination = self._exactly(size).decode("ascii")
        (length,) = U32.unpack(self._exactly(4))
        return destination, self._exactly(length)

    def until(self, destination: str, timeout_s: float = 10.0) -> bytes:
        """The payload of the next frame sent to ``destination`` (others skipped)."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            got, payload = self.read()
            if got == destination:
                return payload
        raise TimeoutError(f"no frame for {destination} in {timeout_s} s")

    def close(self) -> None:
        self.sock.close()


def goal_pose_cdr(x: float, y: float, frame_id: str = "map", yaw: float = 0.0) -> bytes:
    """A geometry_msgs/PoseStamped as a scene publishes it (CDR, rosbags' typestore)."""
    from cosim.recording.schemas import typestore

    store = typestore()
    t = store.types
    msg = t["geometry_msgs/msg/PoseStamped"](
        header=t["std_msgs/msg/Header"](
            stamp=t["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id=frame_id
        ),
        pose=t["geometry_msgs/msg/Pose"](
            position=t["geometry_msgs/msg/Point"](x=x, y=y, z=0.0),
            orientation=t["geometry_msgs/msg/Quaternion"](
                x=0.0, y=0.0, z=math.sin(yaw / 2), w=math.cos(yaw / 2)
            ),
        ),
    )
    return bytes(store.serialize_cdr(msg, "geometry_msgs/msg/PoseStamped"))


def twist_cdr(linear_x: float, angular_z: float, *, linear_y: float = 0.0) -> bytes:
    """A geometry_msgs/Twist as a scene publishes it (CDR, rosbags' typestore)."""
    from cosim.recording.schemas import typestore

    store = typestore()
    vector = store.types["geometry_msgs/msg/Vector3"]
    msg = store.types["geometry_msgs/msg/Twist"](
        linear=vector(x=linear_x, y=linear_y, z=0.0), angular=vector(x=0.0, y=0.0, z=angular_z)
    )
    return bytes(store.serialize_cdr(msg, "geometry_msgs/msg/Twist"))
