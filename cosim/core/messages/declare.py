"""Messages declared once: one frozen dataclass with typed fields is all a message needs.

From the declaration come the bus message, its wire size, its CDR encoding and decoding,
its ``.msg`` text and its DDS type.

A message of a type of one's own lists its fields with their wire types; its ``.msg``
text is made from them::

    @ros_message("labkit_msgs/msg/BidTable")
    class BidTable(Message):
        stamp_ns: Header          # std_msgs/Header header, frame_id "map"
        epoch: uint32
        robot: string
        bids: Float64s            # float64[] bids

A field's name on the wire is its name without its unit suffix (``cost_m`` is ``cost``,
``ranges_m`` is ``ranges``: ROS messages carry SI units implicitly, REP 103), or the
``wire`` name its ``field(metadata=...)`` gives. A field annotated :data:`Header` is the
stamp of a ``std_msgs/Header header`` whose frame is the decorator's ``frame_id`` (or the
field annotated :data:`FrameId`); a field of another declared class nests it; ``tuple[X,
...]`` of a declared class or a wire type is a sequence. Plain ``float``, ``str``, ``bool``
and ``bytes`` are ``float64``, ``string``, ``bool`` and ``uint8[]``; an ``int`` must say
its width (``uint32``, ``int32``, ...).

A planar view of one of ROS 2's standard types binds its fields onto the declared type
instead (:mod:`cosim.core.messages.std`), by path; what it does not bind is zero::

    @ros_message(std.TWIST, wire={"linear.x": "linear_x_mps", "angular.z": "angular_z_radps"})
    class Twist(Message):
        linear_x_mps: float
        angular_z_radps: float

Bindings are an attribute's name, :class:`Const`, :class:`Planar` (a ``Pose`` or
``Transform`` from x, y and yaw), :class:`Each` (a sequence of structs from a tuple of
declared objects) and :class:`Rows` (a sequence of structs from a function of the message,
for what does not bind field by field). Decoding inverts every binding but
:class:`Const` and :class:`Rows`'s one-way functions.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, ClassVar, TypeVar, dataclass_transform

from cosim.core.errors import WireError
from cosim.core.messages.binding import ClassBinding
from cosim.core.messages.decoding import decode_tree
from cosim.core.messages.encoding import Compiled, compile_encoder
from cosim.core.messages.own_types import own_binding
from cosim.core.messages.views import Binding, view_binding
from cosim.core.messages.wire import Struct

M = TypeVar("M")

DERIVED = ("size_bytes", "to_cdr", "from_cdr")
"""What a declaration makes of a message class, and the class must not define itself."""


class Message:
    """Base of every bus message (declare one with :func:`ros_message`).

    Attributes:
        ros_type: the ROS 2 type, ``pkg/msg/Type``.
        wire: the declared type it is sent as.
    """

    ros_type: ClassVar[str]
    wire: ClassVar[Struct]

    def size_bytes(self) -> int:
        """Bytes on the wire: the CDR body and its 4-byte encapsulation header."""
        raise WireError(f"{type(self).__name__} is not declared with @ros_message")

    def to_cdr(self) -> bytes:
        """The message as ROS 2 serializes it (CDR with its encapsulation header).

        ``len(m.to_cdr()) == m.size_bytes()`` for every message.
        """
        raise WireError(f"{type(self).__name__} is not declared with @ros_message")

    @classmethod
    def from_cdr(cls: type[M], data: bytes | bytearray | memoryview) -> M:
        """The message CDR ``data`` holds.

        Raises:
            WireError: the bytes are not such a message.
        """
        raise WireError(f"{cls.__name__} is not declared with @ros_message")


@dataclass_transform(frozen_default=True, field_specifiers=(dataclasses.field,))
def ros_message(
    ros_type: str | Struct,
    *,
    frame_id: str = "map",
    wire: Mapping[str, Binding] | None = None,
) -> Callable[[type[M]], type[M]]:
    """Declare a message class (made a frozen, slotted dataclass) and compile its CDR.

    Args:
        ros_type: ``pkg/msg/Name`` of a type of one's own, whose fields are the class's;
            or a declared standard type (:mod:`cosim.core.messages.std`) the class views.
        frame_id: the frame of a :data:`Header` field without a :data:`FrameId` field.
        wire: a view's bindings, path -> binding (see the module).

    Raises:
        WireError: a field without a wire type, a binding to no field, a path the type
            does not have; a class defining its own size, encoding or decoding (they come
            from the declaration: a size of one's own could disagree with the bytes).
    """

    def declare(cls: type[M]) -> type[M]:
        for derived in DERIVED:
            if derived in vars(cls):
                raise WireError(
                    f"{cls.__module__}.{cls.__qualname__} defines {derived}(): a declared "
                    "message's size, encoding and decoding come from its declaration; "
                    f"expected no {derived} of its own"
                )
        made: Any = dataclass(frozen=True, slots=True)(cls)
        if isinstance(ros_type, Struct):
            kind, binding = ros_type, view_binding(made, ros_type, wire or {})
        else:
            kind, binding = own_binding(made, ros_type, frame_id)
        _install(made, kind, binding)
        return made  # type: ignore[no-any-return]

    return declare


def _install(cls: Any, kind: Struct, binding: ClassBinding) -> None:
    counter = iter(range(1, 1_000_000))
    compiled: Compiled = compile_encoder(
        kind, binding.source("m", lambda: f"_v{next(counter)}"), binding.helpers
    )
    build = binding.build

    def from_cdr(target: type[Any], data: bytes | bytearray | memoryview) -> Any:
        tree = decode_tree(kind, data)
        try:
            return target(**build(tree))
        except (TypeError, ValueError) as error:
            raise WireError(f"{kind.ros_type}: {error}") from None

    cls.ros_type = kind.ros_type
    cls.wire = kind
    cls.to_cdr = compiled.encode
    cls.size_bytes = compiled.size
    cls.from_cdr = classmethod(from_cdr)
    cls._binding = binding
    cls._cdr_source = compiled.source
