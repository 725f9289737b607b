"""Which topics a recording keeps: ``record.topics`` glob patterns over the advertised topics."""

from __future__ import annotations

import fnmatch
import re
from collections.abc import Iterable, Mapping, Sequence

from cosim.core.bus import Advertisement
from cosim.core.errors import ConfigError

SHOWN = 12
"""Topic families quoted in an error message; the others are counted."""
_ROBOT = re.compile(r"^/robot_\d+/")


def select_topics(
    patterns: Sequence[str], advertised: Mapping[str, Advertisement], *, origin: str
) -> dict[str, Advertisement]:
    """The advertised topics the patterns keep, in advertisement order.

    Patterns apply in order: a plain pattern adds the topics it matches, one starting with
    ``!`` removes them (``["*", "!/robot_*/cmd_vel"]``: all but the velocity commands).
    ``*`` matches any text, ``/`` included.

    Args:
        patterns: ``record.topics``.
        advertised: every topic the run publishes.
        origin: the scenario's file or preset, for messages.

    Raises:
        ConfigError: naming the pattern, when a plain pattern matches no advertised topic
            (a typo would otherwise record nothing without a word).
    """
    keep: set[str] = set()
    names = list(advertised)
    for pattern in patterns:
        exclude = pattern.startswith("!")
        glob = pattern[1:] if exclude else pattern
        matched = {name for name in names if fnmatch.fnmatchcase(name, glob)}
        if exclude:
            keep -= matched
            continue
        if not matched:
            raise ConfigError(
                f"{origin}: [record] topics: pattern {pattern!r} matches no topic of this run; "
                f"expected a glob over its topics ({_listing(names)})"
            )
        keep |= matched
    return {name: ad for name, ad in advertised.items() if name in keep}


def _listing(names: Iterable[str]) -> str:
    """The topics with robot namespaces folded: ``/robot_*/scan`` for every robot's scan."""
    ordered = sorted({_ROBOT.sub("/robot_*/", name) for name in names})
    shown = ", ".join(ordered[:SHOWN])
    more = len(ordered) - SHOWN
    return shown + (f", ... {more} more" if more > 0 else "")
