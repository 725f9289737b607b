"""Names that become folder names: a scenario's (``runs/NAME-seedN``) and a study's.

A name is written in any script: letters and digits of every language (``仓库-1``,
``склад``, ``गोदाम``), the combining marks that some scripts need within a word (Devanagari
and Thai vowel signs, an accent typed as a separate mark: ``Zu\u0308rich``) and the zero-width
joiners that Persian and Indic words hold; spaces between words (``Zürich hall``); and
``_``, ``-``, ``.``, ``+``. What a folder name cannot hold, or holds only to surprise, is
refused: a path separator, a control or invisible formatting character (a bidirectional
override can make a name read as another), a name that is empty, begins with ``.`` (a hidden
folder; ``.`` and ``..`` are no folder of their own) or with a space, or ends with a space.

The scenario's name also names the world of ``cosim world --sdf``: SDFormat reserves names
that begin and end with ``__``, which are refused too. No ROS topic, frame or bag file is
named after a scenario.
"""

from __future__ import annotations

import unicodedata

NAME_BYTES = 100
"""Longest name in UTF-8 bytes: ``NAME-seedN`` must stay within a folder name's 255 bytes."""

PUNCTUATION = "_-.+ "
"""Characters besides letters, marks and digits that a name may hold."""

JOINERS = "\u200c\u200d"
"""Zero-width non-joiner and joiner: part of the spelling of Persian and Indic words."""

NAME_RULE = (
    f"one folder name of at most {NAME_BYTES} bytes: letters and digits of any script, "
    "'_', '-', '.', '+' and spaces between words (no '/', no control characters; not "
    "starting with '.')"
)
"""What a name must be, as the messages say it."""


def _allowed(char: str) -> bool:
    return char in PUNCTUATION or char in JOINERS or unicodedata.category(char)[0] in "LMN"


def name_problem(name: str) -> str | None:
    """Why ``name`` cannot name a folder (one clause), or None when it can.

    Args:
        name: a scenario's or a study's name.
    """
    if not name:
        return "it is empty"
    bad = next((c for c in name if not _allowed(c)), None)
    if bad is not None:
        return f"{bad!r} (U+{ord(bad):04X}) is not one"
    if name.startswith("."):
        return "it starts with '.' (a hidden folder)"
    if name[0] == " " or name[-1] == " ":
        return "it starts or ends with a space"
    if len(name) >= 4 and name.startswith("__") and name.endswith("__"):
        return "SDFormat reserves names between '__' (cosim world --sdf names the world so)"
    size = len(name.encode("utf-8"))  # every character allowed encodes (no lone surrogate)
    if size > NAME_BYTES:
        return f"it has {size} bytes"
    return None


__all__ = ["NAME_BYTES", "NAME_RULE", "name_problem"]
