"""Reading TOML files with answers that point at the line: for scenario and study files.

A TOML error names the line and shows it, with the parser's complaint after an arrow, as
compilers do (``s.toml: line 4: [robots  <- expected ']' at the end of a table
declaration``); bytes that are not UTF-8 are reported the same way. Arrays and tables
nested deeper than :data:`MAX_DEPTH` are refused in one line: the reader (and whatever
walks the values after it) recurses once per level, and Python's stack is not deep.
"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path
from typing import Any

from cosim.core.errors import ConfigError

_AT = re.compile(r"\s*\(at line (\d+), column (\d+)\)$")
SHOWN_CHARS = 60
"""Longest part of the offending line that a message shows."""
MAX_DEPTH = 100
"""Deepest nesting of tables and arrays a file may have (the top level is 1; a scenario's
``[world] obstacles = [[...]]`` is 4)."""
_LONG_KEY = re.compile(
    # from the start of a key only (not inside one), parts never given back: linear time
    r"(?<![\w.\"'-])(?:(?:[A-Za-z0-9_-]++|\"[^\"\n]*+\"|'[^'\n]*+')[ \t]*+\.[ \t]*+)"
    + f"{{{MAX_DEPTH}}}"
)
"""A dotted key of more than :data:`MAX_DEPTH` parts: Python's reader takes time growing with
the square of its parts (20,000 take 5 s), so such a key is refused before reading."""


def read_toml_file(path: Path, what: str) -> dict[str, Any]:
    """Parse the TOML file ``path`` (a ``what``: "scenario file", "study file").

    Raises:
        ConfigError: the file cannot be read, is not UTF-8, or is not TOML; one line naming
            the file, the line number, the line and what was expected.
    """
    try:
        data = path.read_bytes()
    except OSError as error:
        raise ConfigError(f"{path}: cannot read {what} ({error.strerror or error})") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        line = data.count(b"\n", 0, error.start) + 1
        raise ConfigError(
            f"{path}: line {line}: byte 0x{data[error.start]:02x} is not UTF-8; expected a "
            f"UTF-8 text {what}"
        ) from None
    return parse_toml(text, str(path))


def parse_toml(text: str, origin: str) -> dict[str, Any]:
    """Parse TOML ``text`` from ``origin`` (a file name, a preset).

    Raises:
        ConfigError: one line naming the origin, the line number, the line and the problem.
    """
    refuse_long_keys(text, origin)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ConfigError(toml_message(origin, text, error)) from None
    except RecursionError:  # arrays or inline tables in each other, a thousand deep
        raise ConfigError(too_deep(origin)) from None
    if deeper_than(data, MAX_DEPTH):  # dotted keys nest without recursing in the reader
        raise ConfigError(too_deep(origin))
    return data


def refuse_long_keys(text: str, origin: str) -> None:
    """Refuse a dotted key of more than :data:`MAX_DEPTH` parts before reading ``text``.

    Raises:
        ConfigError: naming the origin and the line.
    """
    long_key = _LONG_KEY.search(text)
    if long_key is not None:
        where = f"line {text.count(chr(10), 0, long_key.start()) + 1}: " if "\n" in text else ""
        raise ConfigError(
            f"{origin}: {where}a dotted key of more than {MAX_DEPTH} parts; expected tables "
            f"nested at most {MAX_DEPTH} levels deep"
        )


def too_deep(origin: str) -> str:
    """The one-line answer to a value nested deeper than :data:`MAX_DEPTH`."""
    return (
        f"{origin}: tables or arrays nested deeper than {MAX_DEPTH} levels; expected at "
        f"most {MAX_DEPTH} (a scenario needs 4)"
    )


def deeper_than(value: Any, limit: int) -> bool:
    """Whether tables (dicts) and arrays (lists) nest in ``value`` more than ``limit`` levels.

    Walks without recursing, so that any depth can be measured.
    """
    stack: list[tuple[Any, int]] = [(value, 1)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict):
            children: Any = item.values()
        elif isinstance(item, list):
            children = item
        else:
            continue
        if depth > limit:
            return True
        stack.extend((child, depth + 1) for child in children)
    return False


def toml_message(origin: str, text: str, error: tomllib.TOMLDecodeError) -> str:
    """``origin: line N: <the line>  <- <the parser's complaint>``."""
    message = str(error)
    found = _AT.search(message)
    if found is None:
        return f"{origin}: malformed TOML: {message}"
    number = int(found.group(1))
    complaint = message[: found.start()]
    complaint = complaint[:1].lower() + complaint[1:]
    lines = text.splitlines()
    shown = lines[number - 1].strip() if 0 < number <= len(lines) else ""
    if len(shown) > SHOWN_CHARS:
        shown = shown[: SHOWN_CHARS - 3] + "..."
    shown = shown.replace("\t", " ")
    return f"{origin}: line {number}: {shown}  <- {complaint} (malformed TOML)"
