"""Text quoted on the generated reference pages, escaped once for Markdown and HTML.

The references quote what the code says: docs of keys, columns and summary entries,
defaults, help texts. Markdown would take part of it for markup (``/<robot>/cmd_vel``
shows as ``//cmd_vel``: ``<robot>`` is an HTML tag to the browser; ``'*' any text '*'``
is emphasis; ``{robot}`` at the end of a table cell is an attribute list), so every
generator passes what it quotes through these helpers:

- :func:`text`: prose, as written; spans in backticks stay code, everything else shows
  as the very characters written;
- :func:`cell`: the same, on one line, inside a table cell (a ``|`` is no column border);
- :func:`code`: a value shown whole as inline code, whatever backticks it holds;
- :func:`fenced`: a block of preformatted text, whatever fences it holds.
"""

from __future__ import annotations

import re

_CODE_SPAN = re.compile(r"(`+)(.+?)(?<!`)\1(?!`)", re.S)
"""A code span as Markdown reads one: a run of backticks, text, the same run again."""
_TAG_START = re.compile(r"<(?=[A-Za-z/!?])")
"""A ``<`` that would open an HTML tag, comment or declaration."""
_ENTITY = re.compile(r"&(?=#?\w+;)")
"""An ``&`` that would start a character reference (``&lt;``)."""
_LINE_START = re.compile(r"^([ \t]*)([>#+-]|\d+[.)])(?=\s|$)", re.M)
"""What opens a quote, a heading or a list at the start of a line."""


def text(value: str) -> str:
    r"""Prose that shows as written: code spans kept, Markdown and HTML escaped elsewhere.

    Escaped where they would act: ``\``, ``*``, ``{``, ``}``, a ``(`` or ``[`` right
    after ``]`` (a link), a backtick no span closes, an ``_`` not between two letters or
    digits, a ``<`` that would open a tag, an ``&`` that would start an entity, and what
    opens a block at the start of a line (``>``, ``#``, ``-``, ``1.``).
    """
    out = []
    position = 0
    for span in _CODE_SPAN.finditer(value):
        out.append(_plain(value[position : span.start()]))
        out.append(span.group(0))
        position = span.end()
    out.append(_plain(value[position:]))
    return "".join(out)


def cell(value: str) -> str:
    """Text for a table cell: :func:`text` on one line, with ``|`` kept from ending it.

    A pipe inside a code span needs no escape (and would show its backslash).
    """
    one_line = " ".join(value.split("\n"))
    out = []
    position = 0
    for span in _CODE_SPAN.finditer(one_line):
        out.append(_plain(one_line[position : span.start()]).replace("|", "\\|"))
        out.append(span.group(0))
        position = span.end()
    out.append(_plain(one_line[position:]).replace("|", "\\|"))
    return "".join(out)


def code(value: str) -> str:
    """``value`` whole as inline code: fenced by more backticks than any run inside it.

    Inside a table cell too: the pipes of a code span are not column borders. A value of
    several lines is shown on one.
    """
    one_line = " ".join(value.split("\n"))
    longest = max((len(run) for run in re.findall(r"`+", one_line)), default=0)
    fence = "`" * (longest + 1)
    padded = f" {one_line} " if one_line.startswith("`") or one_line.endswith("`") else one_line
    return f"{fence}{padded}{fence}"


def fenced(value: str, language: str = "text") -> list[str]:
    """The lines of a fenced block holding ``value`` verbatim (a fence longer than any inside)."""
    longest = max((len(run) for run in re.findall(r"^\s*(`{3,})", value, flags=re.M)), default=0)
    fence = "`" * max(3, longest + 1)
    return [f"{fence}{language}", value, fence]


def _plain(value: str) -> str:
    """Markdown-escape text that holds no code span."""
    value = value.replace("\\", "\\\\")
    for char in "*{}`":
        value = value.replace(char, "\\" + char)
    value = value.replace("](", "]\\(").replace("][", "]\\[")  # no link, no reference
    value = re.sub(r"(?<![A-Za-z0-9])_|_(?![A-Za-z0-9])", r"\\_", value)
    value = _ENTITY.sub("&amp;", value)
    value = _TAG_START.sub("&lt;", value)
    return _LINE_START.sub(_escape_marker, value)


def _escape_marker(match: re.Match[str]) -> str:
    indent, marker = match.group(1), match.group(2)
    if marker == ">":
        return f"{indent}&gt;"
    return f"{indent}{marker[:-1]}\\{marker[-1]}"
