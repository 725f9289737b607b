"""The wire types as annotations of a declared message's fields.

``epoch: uint32`` is an ``int`` to the type checker and a ``uint32`` on the wire; a field
annotated :data:`Header` is the stamp (integer ns) of a ``std_msgs/Header`` whose frame is
the declaration's (or the field annotated :data:`FrameId`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated

import numpy as np
import numpy.typing as npt

from cosim.core.messages import std
from cosim.core.messages.wire import (
    BOOL,
    FLOAT32,
    FLOAT64,
    INT8,
    INT16,
    INT32,
    INT64,
    STRING,
    UINT8,
    UINT16,
    UINT32,
    UINT64,
    Sequence,
)


@dataclass(frozen=True)
class HeaderStamp:
    """Marks the field that is a ``std_msgs/Header``'s stamp."""


@dataclass(frozen=True)
class HeaderFrame:
    """Marks the field that is a ``std_msgs/Header``'s frame_id."""


Header = Annotated[int, HeaderStamp()]
"""A ``std_msgs/Header header`` whose stamp is this field (integer ns)."""
FrameId = Annotated[str, HeaderFrame()]
"""The frame_id of the message's :data:`Header`."""
Time = Annotated[int, std.TIME]
"""A ``builtin_interfaces/Time`` (integer ns)."""
Duration = Annotated[int, std.DURATION]
"""A ``builtin_interfaces/Duration`` (integer ns)."""
bool_ = Annotated[bool, BOOL]
int8 = Annotated[int, INT8]
uint8 = Annotated[int, UINT8]
int16 = Annotated[int, INT16]
uint16 = Annotated[int, UINT16]
int32 = Annotated[int, INT32]
uint32 = Annotated[int, UINT32]
int64 = Annotated[int, INT64]
uint64 = Annotated[int, UINT64]
float32 = Annotated[float, FLOAT32]
float64 = Annotated[float, FLOAT64]
string = Annotated[str, STRING]
Float32s = Annotated[npt.NDArray[np.float32], Sequence(FLOAT32)]
"""A ``float32[]`` held as a NumPy array."""
Float64s = Annotated[tuple[float, ...], Sequence(FLOAT64)]
"""A ``float64[]`` held as a tuple."""
Int32s = Annotated[tuple[int, ...], Sequence(INT32)]
"""An ``int32[]`` held as a tuple."""
Strings = Annotated[tuple[str, ...], Sequence(STRING)]
"""A ``string[]`` held as a tuple."""
Bytes = Annotated[bytes, Sequence(UINT8)]
"""A ``uint8[]`` held as bytes."""
