"""The arguments of cosim's Python API, checked where they come in.

``cosim.run``, ``cosim.load_scenario``, ``cosim.study`` and :class:`~cosim.scenario.Scenario`'s
``with_*`` methods check each argument with these functions before using it, so that a value
of the wrong kind is refused in one line naming the call, the argument, the value and what
was expected (``cosim.run(seed='3'): expected an int >= 0, or None (the scenario's own)``),
never by an ``AttributeError`` or a comparison error from deep inside.

A value of the wrong type raises :class:`ArgumentError`, which is both a
:class:`~cosim.core.errors.ConfigError` (the one-line errors of bad input) and a
``TypeError`` (what Python code expects of a wrong type); a value of the right type out of
its bounds raises :class:`~cosim.core.errors.ConfigError`, as the same value in a scenario
file would.
"""

from __future__ import annotations

import inspect
import math
import numbers
import os
import reprlib
from collections.abc import Mapping
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from cosim.core.errors import ConfigError
from cosim.scenario.fields import key_bounds
from cosim.scenario.sections import ScenarioSection

T = TypeVar("T")

SHOWN = reprlib.Repr()
"""How a message shows a value: Python's repr, cut short (a long list, a long string)."""
SHOWN.maxstring = 60
SHOWN.maxother = 60
SHOWN.maxlist = SHOWN.maxtuple = SHOWN.maxdict = SHOWN.maxset = 4
SHOWN.maxlevel = 3


class ArgumentError(ConfigError, TypeError):
    """An argument of the Python API of a type the call does not take."""


def shown(value: Any) -> str:
    """``value`` as a message shows it: its repr, at most about 60 characters."""
    try:
        return SHOWN.repr(value)
    except Exception:  # a repr that raises must not hide the refusal
        return f"<{type(value).__name__} object>"


def refusal(call: str, name: str, value: Any, expected: str) -> str:
    """The one line: ``call(name=value): expected ...``."""
    return f"{call}({name}={shown(value)}): expected {expected}"


def wrong_type(call: str, name: str, value: Any, expected: str) -> ArgumentError:
    """The error for an argument of the wrong type."""
    return ArgumentError(refusal(call, name, value, expected))


def _integer(value: Any) -> bool:
    """An int, a numpy integer; not a bool (``True`` is no seed)."""
    return isinstance(value, numbers.Integral) and not isinstance(value, bool | np.bool_)


def _real(value: Any) -> bool:
    """An int or float, numpy's too; not a bool."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_)


SEED_EXPECTED = "an int >= 0"


def seed_argument(call: str, seed: Any, *, expected: str = SEED_EXPECTED) -> int:
    """A seed: an int within the bounds of ``scenario.seed`` (numpy's ints too, not bools).

    Raises:
        ArgumentError: a seed that is no int (a bool, a string, a float).
        ConfigError: a negative one.
    """
    if not _integer(seed):
        raise wrong_type(call, "seed", seed, expected)
    value = int(seed)
    if key_bounds(ScenarioSection, "seed").violation(value) is not None:
        raise ConfigError(refusal(call, "seed", seed, expected))
    return value


def optional_seed_argument(call: str, seed: Any) -> int | None:
    """A seed as :func:`seed_argument` takes it, or None (the scenario's own seed)."""
    if seed is None:
        return None
    return seed_argument(call, seed, expected=f"{SEED_EXPECTED}, or None (the scenario's own)")


def duration_argument(call: str, duration_s: Any) -> float | None:
    """A duration (s) within the bounds of ``scenario.duration_s``, or None.

    Raises:
        ArgumentError: a duration that is no number.
        ConfigError: one out of those bounds, or not finite.
    """
    if duration_s is None:
        return None
    bounds = key_bounds(ScenarioSection, "duration_s")
    expected = f"a number of seconds {bounds.describe()}, or None (the scenario's own)"
    if not _real(duration_s):
        raise wrong_type(call, "duration_s", duration_s, expected)
    value = float(duration_s)
    if not math.isfinite(value) or bounds.violation(value) is not None:
        raise ConfigError(refusal(call, "duration_s", duration_s, expected))
    return value


def path_argument(call: str, name: str, value: Any, *, what: str = "a path") -> Path:
    """A file or folder name given as ``str`` or ``os.PathLike`` (``pathlib.Path``).

    Raises:
        ArgumentError: another type (bytes included), an empty name, or one holding NUL.
    """
    expected = f"{what} (a str or pathlib.Path)"
    if not isinstance(value, str | os.PathLike):
        raise wrong_type(call, name, value, expected)
    try:
        text = os.fspath(value)
    except Exception:  # a PathLike whose __fspath__ fails
        raise wrong_type(call, name, value, expected) from None
    if not isinstance(text, str):
        raise wrong_type(call, name, value, expected)
    if not text or "\0" in text:
        raise wrong_type(call, name, value, f"{expected}, not empty and without NUL")
    return Path(text)


def flag_argument(call: str, name: str, value: Any) -> bool:
    """True or False (a bool).

    Raises:
        ArgumentError: anything else (``1``, ``"yes"``, None).
    """
    if isinstance(value, bool | np.bool_):
        return bool(value)
    raise wrong_type(call, name, value, "True or False")


def callable_argument(call: str, name: str, value: Any, what: str, *, arity: int = 1) -> Any:
    """A function that takes ``arity`` positional arguments, or None.

    A function whose signature cannot take them (``lambda: ...`` for a progress callback)
    would fail only when the run calls it; it is refused here. A callable whose signature
    Python cannot read (some builtins) is taken.

    Raises:
        ArgumentError: no callable, or one that cannot take ``arity`` arguments.
    """
    if value is None:
        return value
    if not callable(value):
        raise wrong_type(call, name, value, f"{what}, or None")
    try:
        signature = inspect.signature(value)
    except (TypeError, ValueError):  # no signature to read: taken as it is
        return value
    try:
        signature.bind(*range(arity))
    except TypeError:
        raise wrong_type(call, name, value, f"{what}, or None") from None
    return value


def instance_argument(call: str, name: str, value: Any, kind: type[T], what: str) -> T | None:
    """An instance of ``kind``, or None.

    Raises:
        ArgumentError: anything else.
    """
    if value is None or isinstance(value, kind):
        return value
    raise wrong_type(call, name, value, f"{what}, or None")


def _plain(value: Any) -> Any:
    """A numpy scalar or array as the Python value or list a TOML file would give."""
    to_list = getattr(value, "tolist", None)
    if type(value).__module__ == "numpy" and callable(to_list):
        return to_list()
    return value


OVERRIDES_EXPECTED = "a mapping {'section.key': value} (a dict), or None"


def overrides_argument(call: str, overrides: Any) -> dict[str, Any]:
    """Overrides ``{"section.key": value}``; numpy values become Python ones.

    The values are checked later against the scenario's keys, as a file's values are.

    Raises:
        ArgumentError: no mapping (a list of pairs, a string), or a key that is no string.
    """
    if overrides is None:
        return {}
    if not isinstance(overrides, Mapping):
        raise wrong_type(call, "overrides", overrides, OVERRIDES_EXPECTED)
    plain: dict[str, Any] = {}
    for key, value in overrides.items():
        if not isinstance(key, str):
            raise wrong_type(call, "overrides", {key: value}, "keys that are strings 'section.key'")
        plain[key] = _plain(value)
    return plain


def text_argument(call: str, name: str, value: Any) -> str:
    """A string.

    Raises:
        ArgumentError: anything else.
    """
    if isinstance(value, str):
        return value
    raise wrong_type(call, name, value, "a str")


def origins_argument(call: str, value: Any) -> dict[str, str] | None:
    """``override_origins``: ``{"section.key": "how messages name its origin"}``, or None.

    Raises:
        ArgumentError: no mapping of strings to strings.
    """
    if value is None:
        return None
    if isinstance(value, Mapping) and all(
        isinstance(k, str) and isinstance(v, str) for k, v in value.items()
    ):
        return dict(value)
    raise wrong_type(call, "override_origins", value, "a mapping of str to str, or None")


def count_argument(call: str, name: str, value: Any, *, at_least: int = 1) -> int | None:
    """A whole number >= ``at_least``, or None.

    Raises:
        ArgumentError: no int (a bool, a float).
        ConfigError: one below ``at_least``.
    """
    expected = f"an int >= {at_least}, or None"
    if value is None:
        return None
    if not _integer(value):
        raise wrong_type(call, name, value, expected)
    if int(value) < at_least:
        raise ConfigError(refusal(call, name, value, expected))
    return int(value)


def positive_argument(call: str, name: str, value: Any, what: str) -> float:
    """A finite number > 0.

    Raises:
        ArgumentError: no number.
        ConfigError: zero, negative, infinite or NaN.
    """
    expected = f"a finite number > 0 ({what})"
    if not _real(value):
        raise wrong_type(call, name, value, expected)
    number = float(value)
    if not (math.isfinite(number) and number > 0):
        raise ConfigError(refusal(call, name, value, expected))
    return number


def keywords_argument(call: str, options: Mapping[str, Any], known: Mapping[str, str]) -> None:
    """Refuse a keyword argument the call does not take, listing those it does.

    Raises:
        ArgumentError: for the first unknown keyword.
    """
    for name in options:
        if name not in known:
            raise ArgumentError(
                f"{call}(): unexpected keyword argument {name!r}; expected one of "
                + ", ".join(f"{k} ({v})" for k, v in known.items())
            )


__all__ = [
    "ArgumentError",
    "callable_argument",
    "count_argument",
    "duration_argument",
    "flag_argument",
    "instance_argument",
    "keywords_argument",
    "optional_seed_argument",
    "origins_argument",
    "overrides_argument",
    "path_argument",
    "positive_argument",
    "refusal",
    "seed_argument",
    "shown",
    "text_argument",
    "wrong_type",
]
