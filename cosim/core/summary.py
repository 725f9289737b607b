"""What a run's ``summary.json`` holds, declared beside the code that writes it.

Every summary entry is declared once, with its unit and what it means, in a
``summary_keys`` class attribute of whatever writes it: an adapter (the keys its
``finish()`` returns), or any registered entry whose own summary an adapter merges (an
assignment protocol's ``summary()``, a pose source's, a network backend's ``finish()``).
cosim's built-ins declare theirs exactly so, and so does a plugin::

    class BatteryAdapter:
        summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
            "battery_lowest": SummaryKey("fraction", "lowest charge of any robot at the end"),
        }

From these declarations come the documentation's ``summary.json`` reference (with the
unit in a column of its own) and the note ``cosim check-plugin`` gives on a key a run
writes that nothing declares. A run itself never refuses an undeclared key.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

ATTRIBUTE = "summary_keys"
"""The class attribute an entry declares its summary keys in."""


@dataclass(frozen=True)
class SummaryKey:
    """One entry of ``summary.json``: its unit and what it means.

    Attributes:
        unit: the value's unit (``s``, ``ms``, ``m``, ``m/s``, ``bytes``, ``Hz``); for a
            value without one, what it is instead: ``count``, ``fraction`` (0..1),
            ``ratio``, ``true/false``, ``text``, ``record`` (a JSON object). Never empty:
            a unitless value is declared so on purpose.
        doc: one line: what the value is (and ``null`` when it can be null).
        when: when the key is written, if not in every run of its writer (``real-time
            runs only``); empty otherwise.
        volatile: a wall-clock or machine figure, not a function of the scenario and
            seed (comparisons of runs leave it out).
    """

    unit: str
    doc: str
    when: str = ""
    volatile: bool = False


SummaryKeys = Mapping[str, SummaryKey]
"""A writer's declaration: summary key -> what it is, in the order it is written."""


def summary_keys_of(entry: object) -> dict[str, SummaryKey]:
    """The summary keys ``entry`` declares (its ``summary_keys`` attribute), or none.

    Only well-formed entries are returned (a name mapped to a :class:`SummaryKey`);
    :func:`declaration_problems` says what is wrong with the others.
    """
    declared = getattr(entry, ATTRIBUTE, None)
    if not isinstance(declared, Mapping):
        return {}
    return {
        key: value
        for key, value in declared.items()
        if isinstance(key, str) and isinstance(value, SummaryKey)
    }


def declaration_problems(entry: object) -> list[str]:
    """What is wrong with ``entry``'s ``summary_keys``, one phrase each (none: nothing).

    An entry without the attribute declares nothing, which is no problem here (a run's
    undeclared keys are).
    """
    if not hasattr(entry, ATTRIBUTE):
        return []
    declared = getattr(entry, ATTRIBUTE)
    if not isinstance(declared, Mapping):
        return [
            f"{ATTRIBUTE} is a {type(declared).__name__}; expected a mapping of key names "
            "to cosim.core.summary.SummaryKey"
        ]
    found = []
    for key, value in declared.items():
        if not isinstance(key, str) or not key:
            found.append(f"{ATTRIBUTE} has the key {key!r}; expected a non-empty string")
        elif not isinstance(value, SummaryKey):
            found.append(f"{ATTRIBUTE}[{key!r}] is a {type(value).__name__}; expected a SummaryKey")
        else:
            found += [f"{ATTRIBUTE}[{key!r}] {said}" for said in key_problems(value)]
    return found


def key_problems(key: SummaryKey) -> list[str]:
    """What a declaration lacks: a unit, a one-line doc (none: it is complete)."""
    found = []
    if not isinstance(key.unit, str) or not key.unit.strip():
        found.append(
            "has no unit: give one (s, m, bytes, ...), or say what a unitless value is "
            "(count, fraction, ratio, true/false, text)"
        )
    if not isinstance(key.doc, str) or not key.doc.strip():
        found.append("has no doc: one line saying what the value is")
    elif "\n" in key.doc:
        found.append("has a doc of several lines: one line saying what the value is")
    return found
