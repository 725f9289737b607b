"""How a message class's values sit on the wire, both ways (for the declaration's use).

A :class:`ClassBinding` tells the encoder generator where each field of the wire type is
found from an object (a source tree, :mod:`cosim.core.messages.encoding`) and turns a
decoded tree back into the class's constructor arguments.
"""

from __future__ import annotations

import enum
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Annotated, Any, get_args, get_origin

import numpy as np

from cosim.core.messages.cdr_layout import Source


@dataclass(frozen=True)
class ClassBinding:
    """A class's fields on the wire, both ways."""

    source: Callable[[str, Callable[[], str]], Source]
    """(the object's expression, a namer of loop variables) -> how each field is found."""
    build: Callable[[tuple[Any, ...]], dict[str, Any]]
    """The decoded struct -> the class's constructor arguments."""
    helpers: Mapping[str, Any]


def element_class(hint: Any) -> Any:
    """The declared class a field holds (or a tuple of), or None."""
    if get_origin(hint) is Annotated:
        hint = get_args(hint)[0]
    if get_origin(hint) is tuple:
        args = get_args(hint)
        hint = args[0] if len(args) == 2 and args[1] is Ellipsis else None
    if get_origin(hint) is Annotated:
        hint = get_args(hint)[0]
    return hint if hasattr(hint, "_binding") else None


def convert(value: Any, hint: Any, element: Any) -> Any:
    """A decoded value as the attribute holds it."""
    base = get_args(hint)[0] if get_origin(hint) is Annotated else hint
    if element is not None:
        if isinstance(value, list):
            return tuple(element(**element._binding.build(item)) for item in value)
        return element(**element._binding.build(value))
    origin = get_origin(base)
    if origin is tuple:
        items = value.tolist() if isinstance(value, np.ndarray) else value
        if isinstance(items, bytes):
            items = list(items)
        return tuple(tuple(i) if isinstance(i, list | tuple) else i for i in items)
    if base is bytes or origin is bytes:
        return bytes(value)
    if isinstance(base, type) and issubclass(base, enum.Enum):
        return base(value)
    return value
