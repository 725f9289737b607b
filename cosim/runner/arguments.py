"""The arguments of :func:`cosim.run`, checked before anything is built.

Each argument is checked with the rules of :mod:`cosim.scenario.arguments`: a value of the
wrong type is refused in one line naming it (:class:`~cosim.scenario.arguments.ArgumentError`,
a ``ConfigError`` and a ``TypeError``), a value out of bounds likewise
(:class:`~cosim.core.errors.ConfigError`). Two conveniences are taken rather than refused:
``scenario`` may be a preset name or a scenario file (loaded as :func:`cosim.load_scenario`
would), and ``adapters`` may be one name or one class instead of a list of them.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from adapters.unity.server import UnityOptions
from cosim.core.adapter import AdapterType
from cosim.core.errors import ConfigError
from cosim.core.workers import MAX_THREADS, available_cores
from cosim.recording.foxglove import LiveOptions
from cosim.runner.stopping import StopRequest
from cosim.scenario.arguments import (
    ArgumentError,
    callable_argument,
    duration_argument,
    flag_argument,
    instance_argument,
    optional_seed_argument,
    path_argument,
    refusal,
    shown,
    wrong_type,
)
from cosim.scenario.loader import load_scenario
from cosim.scenario.model import Scenario

CALL = "cosim.run"
SCENARIO_EXPECTED = (
    "a Scenario (from cosim.load_scenario), a preset name (`cosim scenarios`) or a scenario "
    "file (a str or pathlib.Path)"
)
ADAPTERS_EXPECTED = (
    "registered adapter names (str, `cosim plugins`) or adapter classes: one, or a list of them"
)
PORT_MAX = 65535
HOST_EXPECTED = "an address or host name of this machine (a str: 127.0.0.1, 0.0.0.0, ::1)"


def _address_like(host: str) -> bool:
    """Not empty, one word of printable characters: the server says if it cannot listen."""
    return bool(host) and host.isprintable() and not any(c.isspace() for c in host)


@dataclass(frozen=True)
class RunArguments:
    """``cosim.run``'s arguments once checked.

    Attributes:
        scenario: the scenario, with the seed and duration asked for.
        out: the run folder, or None.
        adapters: the extra adapters, each a registered name or an adapter class.
        threads: the run's worker threads (None asked: the cores available).
    """

    scenario: Scenario
    out: Path | None
    adapters: tuple[str | AdapterType, ...]
    threads: int = 1


def run_arguments(
    scenario: Any,
    *,
    seed: Any,
    duration_s: Any,
    out: Any,
    force: Any,
    progress: Any,
    live: Any,
    on_ready: Any,
    adapters: Any,
    stop: Any,
    figures: Any,
    unity: Any,
    threads: Any = None,
) -> RunArguments:
    """Check every argument of :func:`cosim.run`; load a scenario given by name or file.

    Raises:
        ArgumentError: an argument of the wrong type, naming it, its value and what was
            expected.
        ConfigError: a value out of bounds (a negative seed, a TCP port past 65535), or a
            scenario file or preset that does not load.
    """
    checked_seed = optional_seed_argument(CALL, seed)
    checked_duration = duration_argument(CALL, duration_s)
    folder = None if out is None else path_argument(CALL, "out", out, what="a folder")
    flag_argument(CALL, "force", force)
    flag_argument(CALL, "figures", figures)
    callable_argument(
        CALL, "progress", progress, "a function of (sim s, duration s, wall s)", arity=3
    )
    callable_argument(CALL, "on_ready", on_ready, "a function of the recording session")
    instance_argument(CALL, "stop", stop, StopRequest, "a StopRequest (stop_on_signals())")
    if instance_argument(CALL, "live", live, LiveOptions, "LiveOptions(...)") is not None:
        _check_address(live, "live")
        _check_field(
            live,
            "live",
            "rate",
            "a finite number > 0 (simulated s per wall-clock s)",
            _number(live.rate),
            lambda rate: math.isfinite(rate) and rate > 0,
        )
        _check_field(live, "live", "wait", "True or False", isinstance(live.wait, bool))
    if instance_argument(CALL, "unity", unity, UnityOptions, "UnityOptions(...)") is not None:
        _check_address(unity, "unity")
    names = adapters_argument(adapters)
    checked_threads = threads_argument(CALL, threads)
    loaded = scenario_argument(scenario)
    if checked_seed is not None:
        loaded = loaded.with_seed(checked_seed)
    if checked_duration is not None:
        loaded = loaded.with_duration(checked_duration)
    return RunArguments(loaded, folder, names, checked_threads)


def threads_argument(call: str, threads: Any) -> int:
    """Worker threads for a run: an int in ``[1, MAX_THREADS]``, or None (the cores available).

    Raises:
        ArgumentError: no int (a bool, a float).
        ConfigError: one out of bounds.
    """
    expected = f"an int from 1 to {MAX_THREADS}, or None (the cores available)"
    if threads is None:
        return min(available_cores(), MAX_THREADS)
    if isinstance(threads, bool) or not isinstance(threads, int):
        raise wrong_type(call, "threads", threads, expected)
    if not 1 <= threads <= MAX_THREADS:
        raise ConfigError(refusal(call, "threads", threads, expected))
    return threads


def scenario_argument(scenario: Any) -> Scenario:
    """A :class:`Scenario`, or the one a preset name or a scenario file gives.

    Raises:
        ArgumentError: anything else.
        ConfigError: a preset or file that does not load.
    """
    if isinstance(scenario, Scenario):
        return scenario
    if isinstance(scenario, str | os.PathLike):
        spec = path_argument(CALL, "scenario", scenario, what=SCENARIO_EXPECTED)
        return load_scenario(scenario if isinstance(scenario, str) else spec)
    raise wrong_type(CALL, "scenario", scenario, SCENARIO_EXPECTED)


def adapters_argument(adapters: Any) -> tuple[str | AdapterType, ...]:
    """The extra adapters: one name or class, or an iterable of names and classes.

    A bare string is one adapter's name (``adapters="lidar"``), never a list of letters.

    Raises:
        ArgumentError: anything else, naming the first element that is neither.
    """
    if isinstance(adapters, str | type):
        adapters = (adapters,)
    if isinstance(adapters, bytes | bytearray | dict) or not isinstance(adapters, Iterable):
        raise wrong_type(CALL, "adapters", adapters, ADAPTERS_EXPECTED)
    names = tuple(adapters)
    for adapter in names:
        if not isinstance(adapter, str | type) or adapter == "":
            raise ArgumentError(
                f"{CALL}(adapters=[..., {shown(adapter)}, ...]): expected {ADAPTERS_EXPECTED}"
            )
    return names


def _number(value: Any) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _check_address(options: LiveOptions | UnityOptions, argument: str) -> None:
    """The host and port of the live view's or Unity's options."""
    host, port = options.host, options.port
    _check_field(options, argument, "host", HOST_EXPECTED, isinstance(host, str), _address_like)
    _check_field(
        options,
        argument,
        "port",
        f"a TCP port, an int from 0 to {PORT_MAX}",
        isinstance(port, int) and not isinstance(port, bool),
        lambda p: 0 <= p <= PORT_MAX,
    )


def _check_field(
    options: Any,
    argument: str,
    name: str,
    expected: str,
    right_type: bool,
    right_value: Callable[[Any], bool] = lambda _: True,
) -> None:
    """Refuse ``options.name`` of the wrong type (ArgumentError) or value (ConfigError)."""
    value = getattr(options, name)
    if right_type and right_value(value):
        return
    kind = ConfigError if right_type else ArgumentError
    raise kind(f"{CALL}({argument}=...): {argument}.{name} = {shown(value)}: expected {expected}")


__all__ = ["RunArguments", "adapters_argument", "run_arguments", "scenario_argument"]
