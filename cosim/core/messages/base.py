"""The base of all bus messages."""

from __future__ import annotations

from typing import ClassVar


class Message:
    """Base of all bus messages."""

    ros_type: ClassVar[str]
    """ROS 2 type name, ``pkg/msg/Type``."""

    ros_definition: ClassVar[str | None] = None
    """The ``.msg`` text of a type that is neither a ROS 2 standard one nor cosim's own
    (a plugin's), so that bags and the live view can describe it; None otherwise."""

    def size_bytes(self) -> int:
        """Serialized size on the wire in bytes (CDR body + encapsulation header)."""
        raise NotImplementedError

    def to_cdr(self) -> bytes:
        """The message as ROS 2 serializes it (CDR with its encapsulation header).

        ``len(m.to_cdr()) == m.size_bytes()`` for every message.
        """
        raise NotImplementedError
