"""A message's layout as a list of operations, from how each field of its type is found.

A message class tells where the value of each field of its wire type is found (a source:
:class:`Expr`, :class:`Fields`, :class:`AsTuple`, :class:`Items`); :func:`flatten` turns the
type and the sources into the flat list of what is written, in order (primitives, strings,
times, sequences, loops over sequences of structs), which
:mod:`cosim.core.messages.encoding` compiles.
"""

from __future__ import annotations

import ast
from collections.abc import Callable, Mapping
from dataclasses import dataclass

from cosim.core.errors import WireError
from cosim.core.messages.wire import UINT32, Array, Primitive, Struct, Text, WireType


# -- what feeds a value when encoding --------------------------------------------------------
@dataclass(frozen=True)
class Expr:
    """A value given by a Python expression (over ``m``, the message, and loop variables)."""

    code: str


@dataclass(frozen=True)
class Fields:
    """A struct's value field by field; a field not named is zero (or empty)."""

    by_name: Mapping[str, Source]


@dataclass(frozen=True)
class AsTuple:
    """A struct's value as a tuple of its fields in order (nested the same way)."""

    code: str


@dataclass(frozen=True)
class Items:
    """A sequence of structs: each element of ``iterable``, bound to ``var``, is ``element``."""

    iterable: str
    var: str
    element: Source


Source = Expr | Fields | AsTuple | Items
"""How the value of a field is found."""


# -- a layout as a list of operations --------------------------------------------------------
@dataclass(frozen=True)
class Prim:
    """``count`` values of a primitive: zeros without ``code``; a ``*code`` spreads a sequence."""

    kind: Primitive
    code: str | None
    count: int = 1


@dataclass(frozen=True)
class Txt:
    """A string (empty without ``code``)."""

    code: str | None


@dataclass(frozen=True)
class TimeOp:
    """A time of integer ns, written as its (sec, nanosec) fields (zero without ``code``)."""

    code: str | None
    sec: Primitive
    nanosec: Primitive


@dataclass(frozen=True)
class Seq:
    """A sequence of primitives: its count, then its elements."""

    element: Primitive
    code: str


@dataclass(frozen=True)
class Let:
    """Bind ``name`` to the value of ``code`` for what follows."""

    name: str
    code: str


@dataclass(frozen=True)
class Loop:
    """A sequence of structs: its count, then ``body`` for each element bound to ``var``."""

    iterable: str
    var: str
    body: list[Op]


Op = Prim | Txt | TimeOp | Seq | Let | Loop


def flatten(kind: WireType, source: Source | None, names: Callable[[str], str]) -> list[Op]:
    """The operations that write a value of ``kind`` found by ``source`` (None: zero)."""
    if isinstance(kind, Primitive):
        return [Prim(kind, _expr(source))]
    if isinstance(kind, Text):
        return [Txt(_expr(source))]
    if isinstance(kind, Struct):
        if kind.nanoseconds:
            return [TimeOp(_expr(source), kind.fields[0][1], kind.fields[1][1])]  # type: ignore[arg-type]
        ops: list[Op] = []
        for i, (name, field_kind) in enumerate(kind.fields):
            if source is None:
                sub: Source | None = None
            elif isinstance(source, Fields):
                sub = source.by_name.get(name)
            elif isinstance(source, AsTuple):
                at = f"{source.code}[{i}]"
                sub = AsTuple(at) if _is_struct(field_kind) else Expr(at)
            else:
                raise WireError(f"{kind.ros_type}: fields or a tuple expected, got {source!r}")
            ops += flatten(field_kind, sub, names)
        return ops
    if isinstance(kind, Array):
        element = kind.element
        code = _expr(source)
        if isinstance(element, Primitive):
            return [Prim(element, None if code is None else f"*{code}", kind.length)]
        held = names("a")
        ops = [Let(held, code or "()")]
        for k in range(kind.length):
            at = f"{held}[{k}]"
            each = None if code is None else AsTuple(at) if _is_struct(element) else Expr(at)
            ops += flatten(element, each, names)
        return ops
    element = kind.element
    if source is None:
        return [Prim(UINT32, "0")]
    if isinstance(element, Primitive):
        return [Seq(element, _expr(source) or "()")]
    if isinstance(source, Items):
        return [Loop(source.iterable, source.var, flatten(element, source.element, names))]
    var = names("e")
    item: Source = AsTuple(var) if _is_struct(element) else Expr(var)
    return [Loop(_expr(source) or "()", var, flatten(element, item, names))]


def _expr(source: Source | None) -> str | None:
    if source is None or isinstance(source, Expr):
        return None if source is None else source.code
    raise WireError(f"a single value expected, got {source!r}")


def _is_struct(kind: WireType) -> bool:
    return isinstance(kind, Struct) and not kind.nanoseconds


def literal(code: str | None) -> bytes | None:
    """The UTF-8 bytes of a string that is known now (unset, or a constant), else None."""
    if code is None:
        return b""
    try:
        value = ast.literal_eval(code)
    except (ValueError, SyntaxError):
        return None
    return value.encode("utf-8") if isinstance(value, str) else None


def needs(op: Op | None) -> int:
    """The alignment the first bytes of ``op`` need (1 after the last operation)."""
    if op is None or isinstance(op, Let):
        return 1
    if isinstance(op, Prim):
        return op.kind.size
    return 4


def fixed_body(body: list[Op]) -> bool:
    """Whether every element of a loop is primitives alone (laid out by its start mod 8)."""
    return all(isinstance(op, Prim) and not (op.code or "").startswith("*") for op in body)
