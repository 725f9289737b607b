"""Reading TOML files with answers that point at the line: for scenario and study files.

A TOML error names the line and shows it, with the parser's complaint after an arrow, as
compilers do (``s.toml: line 4: [robots  <- expected ']' at the end of a table
declaration``); bytes that are not UTF-8 are reported the same way.
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
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise ConfigError(toml_message(origin, text, error)) from None


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
