"""CDR encoders and sizes of every declared message, compiled from its layout.

ROS 2 puts a message on the wire as CDR (XCDR1, little endian) behind the 4-byte
encapsulation header ``00 01 00 00``: a primitive is aligned to its own size counted from
the end of that header, a string is a uint32 length (counting the NUL), its UTF-8 bytes
and the NUL, a sequence a uint32 count and its elements (an 8-byte element aligned only
when there is one), a fixed array only its elements. rosbag2 stores exactly these bytes.

A message class binds its values to a :class:`~cosim.core.messages.wire.Struct`
(:mod:`cosim.core.messages.declare`); from the binding this module generates, once per
class, a Python encoder and a size function specialised to the layout, as rosbags does
for its own serializer: runs of fields whose padding is known in advance are packed by
one precompiled :class:`struct.Struct` (unset fields are pad bytes of zeros); alignment
is worked out at run time only after a string or a sequence. The recording runs on the
hot path (a 50-robot run records thousands of messages per simulated second), so this is
several times faster than a generic walk over the layout (``make bench``: ``cdr_encoding``).

Decoding is :mod:`cosim.core.messages.decoding`'s.
"""

from __future__ import annotations

import math
import re
import struct as _struct
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np

from cosim.core.messages.cdr_layout import (
    Let,
    Loop,
    Op,
    Prim,
    Seq,
    Source,
    TimeOp,
    Txt,
    fixed_body,
    flatten,
    literal,
    needs,
)
from cosim.core.messages.wire import (
    HEADER,
    NS_PER_S,
    UINT32,
    Primitive,
    Struct,
)

# -- runtime helpers the generated code calls ------------------------------------------------
_PAD = tuple(bytes(n) for n in range(8))
_U32 = _struct.Struct("<I")


def _seq_bytes(values: Any, dtype: str, code: str) -> bytes:
    """The elements of a numeric sequence as little-endian bytes."""
    if isinstance(values, np.ndarray):
        return np.ascontiguousarray(values, dtype=dtype).tobytes()
    if isinstance(values, bytes | bytearray | memoryview) and dtype in ("u1", "i1"):
        return bytes(values)
    return _struct.pack(f"<{len(values)}{code}", *values)


@lru_cache(maxsize=65536)
def _strings(start: int, texts: tuple[str, ...], then: int) -> bytes:
    """Consecutive string fields from data offset ``start`` (mod 8), padded for ``then``.

    The padding aligns what follows to ``then`` bytes. Strings repeat (frame ids, robot
    names), so the block of each is built once.
    """
    out = bytearray(start)
    for text in texts:
        raw = text.encode("utf-8")
        out += _PAD[-len(out) % 4]
        out += _U32.pack(len(raw) + 1)
        out += raw
        out.append(0)
    out += _PAD[-len(out) % then]
    return bytes(out[start:])


def _fixed_items(offset: int, count: int, table: tuple[tuple[int, int], ...]) -> int:
    """The data offset after ``count`` fixed-layout elements from ``offset``.

    ``table[r]`` is (bytes, residue after) of one element starting at residue ``r`` mod 8.
    """
    r = offset & 7
    for _ in range(count):
        length, r = table[r]
        offset += length
    return offset


# -- writing the code ------------------------------------------------------------------------
@dataclass
class _Code:
    """Two functions written together: the encoder (``b``) and the sizer (``n``)."""

    namespace: dict[str, Any]
    enc: list[str] = field(default_factory=list)
    size: list[str] = field(default_factory=list)
    depth: int = 1
    mod: int = 8
    """The data offset is known modulo this (1: unknown) ..."""
    res: int = 0
    """... to be this."""
    fmt: list[str] = field(default_factory=list)
    args: list[str] = field(default_factory=list)
    run: int = 0
    count: int = 0

    def line(self, enc: str | None = None, size: str | None = None) -> None:
        pad = "    " * self.depth
        if enc is not None:
            self.enc.append(pad + enc)
        if size is not None:
            self.size.append(pad + size)

    def name(self, prefix: str, value: Any = None) -> str:
        self.count += 1
        name = f"_{prefix}{self.count}"
        if value is not None:
            self.namespace[name] = value
        return name

    def flush(self) -> None:
        """Write out the pending run of statically laid out fields."""
        if self.fmt:
            packer = self.name("P", _struct.Struct("<" + "".join(self.fmt)))
            self.line(enc=f"b += {packer}.pack({', '.join(self.args)})")
            self.fmt, self.args = [], []
        if self.run:
            self.line(size=f"n += {self.run}")
            self.run = 0

    def bytes_(self, count: int, fmt: str, arg: str | None = None) -> None:
        """``count`` bytes of the static run (format ``fmt``, with ``arg`` if one)."""
        self.fmt.append(fmt)
        if arg is not None:
            self.args.append(arg)
        self.run += count
        self.res = (self.res + count) % self.mod

    def align(self, a: int) -> None:
        if a == 1:
            return
        if self.mod >= a:
            pad = -self.res % a
            if pad:
                self.bytes_(pad, f"{pad}x")
            return
        self.flush()
        self.line(enc=f"b += _PAD[(4 - len(b)) % {a}]", size=f"n += -n % {a}")
        self.mod, self.res = a, 0

    def primitive(self, kind: Primitive, code: str | None, count: int = 1) -> None:
        """``count`` values of a primitive (zeros for no code; a ``*`` code spreads)."""
        self.align(kind.size)
        if code is None:
            self.bytes_(kind.size * count, f"{kind.size * count}x")
        else:
            self.bytes_(kind.size * count, f"{count}{kind.code}" if count > 1 else kind.code, code)

    def residue(self) -> str:
        """The data offset mod 8, as the encoder (and the sizer) know it now."""
        self.flush()
        if self.mod == 8:
            return str(self.res)
        return "(len(b) - 4) & 7"


def _emit(out: _Code, ops: list[Op]) -> None:
    k = 0
    while k < len(ops):
        op = ops[k]
        if isinstance(op, Let):
            out.line(enc=f"{op.name} = {op.code}", size=f"{op.name} = {op.code}")
        elif isinstance(op, Prim):
            out.primitive(op.kind, op.code, op.count)
        elif isinstance(op, TimeOp):
            if op.code is None:
                out.primitive(UINT32, None, 2)
            else:
                sec, nanosec = out.name("t"), out.name("u")
                out.line(enc=f"{sec}, {nanosec} = divmod({op.code}, {NS_PER_S})")
                out.primitive(op.sec, sec)
                out.primitive(op.nanosec, nanosec)
        elif isinstance(op, Txt):
            k = _emit_texts(out, ops, k)
            continue
        elif isinstance(op, Seq):
            _emit_sequence(out, op)
        else:
            _emit_loop(out, op)
        k += 1


def _emit_texts(out: _Code, ops: list[Op], k: int) -> int:
    """Strings from ``ops[k]``; returns the index of the operation after them.

    A constant string joins the static run; a run of others is one cached block.
    """
    first = ops[k]
    assert isinstance(first, Txt)
    fixed = literal(first.code)
    if fixed is not None:
        out.primitive(UINT32, str(len(fixed) + 1))
        if fixed:
            out.bytes_(len(fixed), f"{len(fixed)}s", out.name("c", fixed))
        out.bytes_(1, "x")
        return k + 1
    codes: list[str] = []
    while k < len(ops):
        op = ops[k]
        if not isinstance(op, Txt) or literal(op.code) is not None:
            break
        codes.append(op.code or "''")
        k += 1
    then = needs(ops[k] if k < len(ops) else None)
    start = out.residue()
    start_n = start.replace("(len(b) - 4)", "n")
    texts = f"({', '.join(codes)},)"
    block = out.name("k")
    out.line(
        enc=f"{block} = _strings({start}, {texts}, {then})",
        size=f"n += len(_strings({start_n}, {texts}, {then}))",
    )
    out.line(enc=f"b += {block}")
    out.mod, out.res = (then, 0) if then > 1 else (1, 0)
    return k


def _emit_sequence(out: _Code, op: Seq) -> None:
    held = out.name("q")
    out.line(enc=f"{held} = {op.code}", size=f"{held} = {op.code}")
    out.primitive(UINT32, f"len({held})")
    out.flush()
    element = op.element
    if element.size == 8:
        out.line(enc=f"if {held}:", size=f"if {held}:")
        out.depth += 1
        out.line(enc="b += _PAD[(4 - len(b)) % 8]", size="n += -n % 8")
        out.depth -= 1
    out.line(
        enc=f"b += _seq_bytes({held}, {element.numpy!r}, {element.code!r})",
        size=f"n += {element.size} * len({held})",
    )
    out.mod, out.res = (4, 0) if element.size >= 4 else (element.size, 0)


def _emit_loop(out: _Code, op: Loop) -> None:
    held = out.name("q")
    out.line(enc=f"{held} = {op.iterable}", size=f"{held} = {op.iterable}")
    out.primitive(UINT32, f"len({held})")
    out.flush()
    if fixed_body(op.body):
        layouts, table = [], []
        for start in range(8):
            element = _Code({}, mod=8, res=start)
            _emit(element, op.body)
            length = element.run
            layouts.append(_struct.Struct("<" + "".join(element.fmt)))
            table.append((length, (start + length) % 8))
        args = [p.code for p in op.body if isinstance(p, Prim) and p.code is not None]
        packers = out.name("L", tuple(layouts))
        sizes = out.name("T", tuple(table))
        out.line(enc=f"for {op.var} in {held}:")
        out.line(enc=f"    b += {packers}[(len(b) - 4) & 7].pack({', '.join(args)})")
        out.line(size=f"n = _fixed_items(n, len({held}), {sizes})")
        out.mod, out.res = 1, 0
        return
    body = list(op.body)
    for k, item in enumerate(body):  # the same for every element (an enclosing stamp)
        if isinstance(item, TimeOp) and item.code is not None and op.var not in item.code:
            sec, nanosec = out.name("t"), out.name("u")
            out.line(enc=f"{sec}, {nanosec} = divmod({item.code}, {NS_PER_S})")
            body[k] = TimeOp(None, item.sec, item.nanosec)
            body[k] = Prim(item.sec, sec), Prim(item.nanosec, nanosec)  # type: ignore[call-overload]
    body = [o for item in body for o in (item if isinstance(item, tuple) else (item,))]
    out.mod, out.res = _entry(out.mod, out.res, body)
    out.line(enc=f"for {op.var} in {held}:", size=f"for {op.var} in {held}:")
    out.depth += 1
    _emit(out, body)
    out.flush()
    out.depth -= 1
    out.mod, out.res = 1, 0


def _entry(mod: int, res: int, body: list[Op]) -> tuple[int, int]:
    """What is known of the offset at the start of every element of a loop.

    The first element starts where the count ends, the others where an element ends:
    only what holds at both is known, found by laying the body out until it settles.
    """
    for _ in range(8):
        trial = _Code({}, mod=mod, res=res)
        _emit(trial, body)
        end_mod, end_res = trial.mod, trial.res
        known = mod
        while known > 1 and (end_mod % known or end_res % known != res % known):
            known //= 2
        if known == mod:
            return mod, res
        mod, res = known, res % known
    return 1, 0


_ASSIGN = re.compile(r"^    [\w, ]+ = ")
_USES_N = re.compile(r"\bn\b")


def _encoder(lines: list[str]) -> list[str]:
    """The encoder's code: one ``b"".join`` where every piece is laid out in advance.

    Where a piece's padding depends on how long the bytes are so far (``len(b)``) or a
    loop writes them, the bytes grow in a ``bytearray`` instead.
    """
    pieces, steps = ["_HEADER"], []
    for line in lines:
        if line.startswith("    b += ") and "len(b)" not in line:
            pieces.append(line.removeprefix("    b += "))
        elif _ASSIGN.match(line) and "len(b)" not in line and not line.startswith("     "):
            steps.append(line)
        else:
            return ["def encode(m):", "    b = bytearray(_HEADER)", *lines, "    return bytes(b)"]
    return ["def encode(m):", *steps, f"    return b''.join(({', '.join(pieces)},))"]


def _sizer(lines: list[str]) -> list[str]:
    """The size function's code: one sum where no term needs the size so far."""
    fixed, terms, steps = 4, [], []
    for line in lines:
        if line.startswith("    n += ") and not _USES_N.search(line.removeprefix("    n += ")):
            term = line.removeprefix("    n += ")
            if term.isdigit():
                fixed += int(term)
            else:
                terms.append(term)
        elif _ASSIGN.match(line) and not line.startswith("     ") and not _USES_N.search(line):
            steps.append(line)
        else:
            return ["def size(m):", "    n = 0", *lines, "    return n + 4"]
    return ["def size(m):", *steps, f"    return {' + '.join([str(fixed), *terms])}"]


@dataclass(frozen=True)
class Compiled:
    """A message class's encoder and size function.

    Attributes:
        encode: the message -> its CDR bytes, encapsulation header included.
        size: the message -> ``len(encode(message))``, without encoding it.
        source: the generated code (for the curious and for errors).
    """

    encode: Callable[[Any], bytes]
    size: Callable[[Any], int]
    source: str


def compile_encoder(kind: Struct, source: Source, helpers: Mapping[str, Any]) -> Compiled:
    """Generate the encoder and size function of values of ``kind`` that ``source`` binds.

    Args:
        kind: the message type.
        source: how each field is found from the message ``m``.
        helpers: names the expressions use (functions, constants).
    """
    namespace: dict[str, Any] = {
        "_PAD": _PAD,
        "_seq_bytes": _seq_bytes,
        "_strings": _strings,
        "_fixed_items": _fixed_items,
        "_HEADER": HEADER,
        "_sin": math.sin,
        "_cos": math.cos,
        **helpers,
    }
    out = _Code(namespace)
    _emit(out, flatten(kind, source, out.name))
    out.flush()
    text = "\n".join([*_encoder(out.enc), "", *_sizer(out.size), ""])
    exec(compile(text, f"<cdr {kind.ros_type}>", "exec"), namespace)
    return Compiled(namespace["encode"], namespace["size"], text)
