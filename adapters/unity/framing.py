"""The ROS-TCP-Endpoint wire format (ROS-TCP-Connector 0.7, ROS 2 mode), both ways.

Every frame is a u32 little-endian length and that many bytes of destination (a topic,
or a system command starting with ``__``), then a u32 length and the payload: a ROS 2
CDR message (with its ``00 01 00 00`` encapsulation header) or a command's JSON. The
Connector writes both strings with a trailing NUL (its ROS 2 string encoding); the
endpoint strips it, and sends its own strings without one. An empty destination with an
empty payload (8 zero bytes) is a keepalive.
"""

from __future__ import annotations

import json
import re
import socket
import struct
from collections.abc import Mapping
from typing import Any

VERSION = "v0.7.0"
"""The endpoint version the Connector 0.7 accepts (it checks the ``v0.7`` prefix)."""
KEEPALIVE = b"\x00" * 8
"""An empty destination and an empty payload."""
MAX_DESTINATION_BYTES = 1024
"""Longest destination accepted; a longer length prefix means the stream is garbage."""
MAX_PAYLOAD_BYTES = 16 * 1024 * 1024
"""Largest payload accepted (16 MiB: a PoseStamped or Twist is under 100 bytes)."""
MAX_COMMAND_BYTES = 64 * 1024
"""Largest JSON of a command accepted (the Connector's are under 1 KiB)."""
MAX_JSON_DEPTH = 32
"""Deepest nesting of arrays and objects accepted in a command's JSON (the Connector's: 1).

Python's JSON parser recurses once per level and raises ``RecursionError`` past about a
thousand; the depth is measured before parsing, so a deeper payload is refused as any
malformed one."""
_U32 = struct.Struct("<I")
_JSON_TOKEN = re.compile(rb'"(?:[^"\\]+|\\.)*"?|[][{}]', re.DOTALL)
"""A JSON string, escapes included (its brackets are text, not nesting), or a bracket.

An unterminated string runs to the end: the match never fails once it has begun, so it
never backtracks (requiring the closing quote, a run of escaped quotes took quadratic time)."""


class FrameError(Exception):
    """A frame breaking the protocol (the stream cannot be followed after it)."""


def frame(destination: str, payload: bytes) -> bytes:
    """One frame: the destination and the payload, each behind its u32 LE length."""
    name = destination.encode("utf-8")
    return b"".join((_U32.pack(len(name)), name, _U32.pack(len(payload)), payload))


def command(name: str, params: Mapping[str, Any]) -> bytes:
    """A system command frame (``__handshake``, ``__error``, ...) with its JSON."""
    return frame(name, json.dumps(params).encode("utf-8"))


def handshake() -> bytes:
    """The first frame of every connection: the version and the ROS 2 protocol."""
    return command(
        "__handshake", {"version": VERSION, "metadata": json.dumps({"protocol": "ROS2"})}
    )


def error(text: str) -> bytes:
    """An ``__error`` frame: the Connector logs ``text`` as an error in Unity's console."""
    return command("__error", {"text": text})


def _exactly(sock: socket.socket, size: int) -> bytes | None:
    """``size`` bytes from ``sock``; None when it closes before the first of them."""
    buffer = bytearray(size)
    view = memoryview(buffer)
    got = 0
    while got < size:
        read = sock.recv_into(view[got:], size - got)
        if not read:
            if got == 0:
                return None
            raise FrameError(f"connection closed {got} bytes into a {size}-byte field")
        got += read
    return bytes(buffer)


def _length(sock: socket.socket, what: str, limit: int, *, first: bool = False) -> int | None:
    raw = _exactly(sock, 4)
    if raw is None:
        if first:
            return None
        raise FrameError(f"connection closed before the {what} length")
    (size,) = _U32.unpack(raw)
    if size > limit:
        raise FrameError(f"{what} of {size} bytes; expected at most {limit}")
    return int(size)


def read_frame(sock: socket.socket) -> tuple[str, bytes] | None:
    """The next frame's (destination without its NUL, payload); None at a clean close.

    Raises:
        FrameError: an oversized length, a destination that is not UTF-8, a close mid-frame.
        OSError: the connection failed.
    """
    size = _length(sock, "destination", MAX_DESTINATION_BYTES, first=True)
    if size is None:
        return None
    raw = _exactly(sock, size) if size else b""
    if raw is None:
        raise FrameError("connection closed inside a destination")
    try:
        destination = raw.decode("utf-8").rstrip("\x00")
    except UnicodeDecodeError:
        raise FrameError(f"destination {raw[:40]!r} is not UTF-8") from None
    length = _length(sock, "payload", MAX_PAYLOAD_BYTES)
    assert length is not None
    payload = _exactly(sock, length) if length else b""
    if payload is None:
        raise FrameError("connection closed inside a payload")
    return destination, payload


def json_depth(data: bytes) -> int:
    """How deep arrays and objects nest in the JSON text ``data`` (0 for a scalar).

    Brackets inside strings are not counted; unbalanced ones are counted as they open,
    so the result is an upper bound for malformed text (which the parser refuses anyway).
    """
    depth = deepest = 0
    for token in _JSON_TOKEN.findall(data):
        if token in (b"[", b"{"):
            depth += 1
            deepest = max(deepest, depth)
        elif token in (b"]", b"}"):
            depth -= 1
    return deepest


def parse_json(destination: str, payload: bytes) -> dict[str, Any]:
    """A command's JSON object (its trailing NUL stripped).

    Raises:
        ValueError: naming the command, when the payload is not a JSON object, is larger
            than :data:`MAX_COMMAND_BYTES` or nests deeper than :data:`MAX_JSON_DEPTH`.
    """
    if len(payload) > MAX_COMMAND_BYTES:
        raise ValueError(
            f"{destination}: a JSON payload of {len(payload)} bytes; expected at most "
            f"{MAX_COMMAND_BYTES} (a command is a small flat object)"
        )
    depth = json_depth(payload)
    if depth > MAX_JSON_DEPTH:
        raise ValueError(
            f"{destination}: JSON nested {depth} levels deep; expected at most "
            f"{MAX_JSON_DEPTH} (a command is a flat object)"
        )
    try:
        value = json.loads(payload.rstrip(b"\x00").decode("utf-8") or "{}")
    except (UnicodeDecodeError, ValueError, RecursionError) as problem:
        reason = " ".join(str(problem).split())[:200]
        raise ValueError(f"{destination}: the payload is not JSON ({reason})") from None
    if not isinstance(value, dict):
        raise ValueError(f"{destination}: expected a JSON object, got {type(value).__name__}")
    return value


def text_field(params: Mapping[str, Any], key: str, command_name: str) -> str:
    """A non-empty string field of a command.

    Raises:
        ValueError: naming the command and the key.
    """
    value = params.get(key)
    if not isinstance(value, str) or not value:
        raise ValueError(f"{command_name}: {key!r} is {value!r}; expected a non-empty string")
    return value
