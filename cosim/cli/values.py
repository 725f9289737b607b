"""The types of the command line's values: each turns one argument's text into its value.

Each raises :class:`argparse.ArgumentTypeError` with one line naming the value and what
was expected; the parser (:mod:`cosim.cli.args`) prints it and exits 2.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from cosim.scenario.fields import key_bounds
from cosim.scenario.sections import ScenarioSection


def non_negative_int(text: str) -> int:
    """An integer >= 0 (``--seed``)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"{value} is negative; expected an integer >= 0")
    return value


def non_negative_float(text: str) -> float:
    """A finite number >= 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not value >= 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"{value:g} is not a finite number >= 0")
    return value


def registry_kind(text: str) -> str:
    """A registry's entry-point group from its name, its short name or its singular.

    ``cosim.planners``, ``planners`` and ``planner`` all name the global planners; only
    the installed packages' metadata is read (no contract is imported).
    """
    from cosim.core.registry import registry_names

    names = registry_names()
    for group in names:
        short = group.removeprefix("cosim.")
        singular = short[:-3] + "y" if short.endswith("ies") else short.removesuffix("s")
        if text in (group, short, singular):
            return group
    shorts = [group.removeprefix("cosim.") for group in names]
    raise argparse.ArgumentTypeError(
        f"{text!r} is not a registry; expected one of {', '.join(shorts)}"
    )


def positive_int(text: str) -> int:
    """An integer >= 1."""
    value = non_negative_int(text)
    if value == 0:
        raise argparse.ArgumentTypeError("0 is not an integer >= 1")
    return value


def threads(text: str) -> int:
    """``--threads``: an integer from 1 to :data:`cosim.core.workers.MAX_THREADS`."""
    from cosim.core.workers import MAX_THREADS

    value = positive_int(text)
    if value > MAX_THREADS:
        raise argparse.ArgumentTypeError(f"{value} is more than {MAX_THREADS} threads")
    return value


def positive_float(text: str) -> float:
    """A finite number > 0 (``--live-rate``)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"{value:g} is not a finite number > 0")
    return value


def duration_s(text: str) -> float:
    """``--duration-s``: within the bounds of ``scenario.duration_s`` (checked alike)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of seconds") from None
    bounds = key_bounds(ScenarioSection, "duration_s")
    if not math.isfinite(value) or bounds.violation(value) is not None:
        raise argparse.ArgumentTypeError(
            f"{value:g} is not a duration {bounds.describe()} s (the bounds of scenario.duration_s)"
        )
    return value


def folder(text: str) -> Path:
    """An output folder's name: not empty, and no NUL byte (no file system takes one)."""
    if not text or "\0" in text:
        raise argparse.ArgumentTypeError(f"{text!r} is not a folder name")
    return Path(text)


def between(text: str, low: float, high: float, what: str, unit: str = "") -> float:
    """A number from ``low`` to ``high``, said as ``what`` (with ``unit``) when not."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not low <= value <= high:  # NaN too
        raise argparse.ArgumentTypeError(f"{value:g} is not {what} from {low:g} to {high:g}{unit}")
    return value


def cell_size_m(text: str) -> float:
    """A map cell size (m): 0.01 to 1."""
    # the bounds of adapters.mapping.bagmap.RESOLUTION_M (not imported: numpy at start-up)
    return between(text, 0.01, 1.0, "a map cell size", " m")


def score(text: str) -> float:
    """A score from 0 to 1."""
    return between(text, 0.0, 1.0, "a score")


def port(text: str) -> int:
    """A TCP port: 0 to 65535."""
    value = non_negative_int(text)
    if value > 65535:
        raise argparse.ArgumentTypeError(f"{value} is not a TCP port (expected 0 to 65535)")
    return value


def times(text: str) -> list[float]:
    """Times (s) separated by commas, each finite and >= 0 (``--at 10,20,30``)."""
    values = []
    for part in text.split(","):
        try:
            value = float(part)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{part.strip()!r} in {text!r} is not a number; expected times in s, "
                "comma-separated (e.g. 10,20,30)"
            ) from None
        if not value >= 0 or value == float("inf"):
            raise argparse.ArgumentTypeError(f"{part.strip()} is not a finite time >= 0 (s)")
        values.append(value)
    return values
