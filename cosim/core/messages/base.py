"""The base of all bus messages."""

from __future__ import annotations

from typing import ClassVar


class Message:
    """Base of all bus messages."""

    ros_type: ClassVar[str]
    """ROS 2 type name, ``pkg/msg/Type``."""

    def size_bytes(self) -> int:
        """Serialized size on the wire in bytes (CDR body + encapsulation header)."""
        raise NotImplementedError

    def to_cdr(self) -> bytes:
        """The message as ROS 2 serializes it (CDR with its encapsulation header).

        ``len(m.to_cdr()) == m.size_bytes()`` for every message.
        """
        raise NotImplementedError
