"""The short real runs of ``cosim check-plugin``: a small scenario per group, and its rules.

An entry is chosen by the scenario key whose field names its group
(``param(..., registry="cosim.protocols")``: ``assignment.protocol``; ``scenario.adapters``
for an adapter), in ``warehouse-random`` made small (:data:`SMALL_WAREHOUSE`) and set up
for what the group does: a protocol with tasks on a network that loses nothing, a
controller with navigation, a latency model with a latency to draw. The run must finish,
leave a flat summary (each key declared with its unit, or a warning), repeat exactly with
the same seed, and keep its group's rules
(:mod:`cosim.testing.rules`). A settings section is not run: it must survive the round
trip through a resolved ``scenario.toml``.
"""

from __future__ import annotations

import dataclasses
import json
import traceback
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any

from cosim.core.errors import ConfigError, CosimError
from cosim.core.plugins import plugin_of_module
from cosim.core.registry import Group
from cosim.core.summary import declaration_problems, summary_keys_of
from cosim.runner.assembly import check_scenario
from cosim.runner.execute import run
from cosim.runner.result import RECORD_KEYS, RunResult
from cosim.runner.summary_keys import declared_keys
from cosim.scenario import Scenario, dump_scenario, load_scenario, scenario_from_text
from cosim.scenario.model import SECTIONS, section_classes
from cosim.testing.outcomes import assert_same_run
from cosim.testing.rules import Rule, assigns, conflicts, delivers, finite, moves, tracks
from cosim.testing.running import SMALL_WAREHOUSE
from cosim.testing.verdicts import Outcome, fail, ok, skip, warn

PRESET = "warehouse-random"
"""The preset every trial starts from (with :data:`SMALL_WAREHOUSE`)."""


@dataclass(frozen=True)
class Trial:
    """How the entries of one group are tried.

    Attributes:
        overrides: scenario keys that give the group something to do.
        duration_s: simulated time (s).
        rules: what must hold after the run.
    """

    overrides: Mapping[str, Any]
    duration_s: float
    rules: tuple[Rule, ...] = ()


TASKS = {"robots.driver": "tasks"}
NAVIGATION = {"robots.driver": "navigation"}
AGENTS = {"robots.driver": "agents", "agents.policy": "random"}
"""Learning agents deciding by themselves (a random policy), so their parts are used."""
TRIALS: Mapping[str, Trial] = {
    "cosim.adapters": Trial({"robots.driver": "waypoints"}, 5.0),
    "cosim.drivers": Trial({}, 10.0, (finite,)),
    "cosim.protocols": Trial({**TASKS, "network.profile": "ideal"}, 15.0, (assigns, conflicts)),
    "cosim.controllers": Trial(NAVIGATION, 20.0, (finite, moves)),
    "cosim.planners": Trial(NAVIGATION, 20.0, (finite, moves)),
    "cosim.traffic": Trial(NAVIGATION, 20.0, (finite, moves)),
    "cosim.network_backends": Trial({**TASKS, "network.profile": "ideal"}, 10.0, (delivers,)),
    "cosim.latency_models": Trial({**TASKS, "network.latency_ms": 5.0}, 10.0, (delivers,)),
    "cosim.loss_models": Trial(TASKS, 10.0),
    "cosim.topologies": Trial(TASKS, 10.0),
    "cosim.mocap_sources": Trial(NAVIGATION, 10.0, (tracks,)),
    "cosim.map_sharing": Trial({**NAVIGATION, "mapping.enabled": True}, 10.0),
    "cosim.agent_observations": Trial(AGENTS, 10.0, (finite,)),
    "cosim.agent_actions": Trial(AGENTS, 10.0, (finite,)),
    "cosim.agent_rewards": Trial(AGENTS, 10.0, (finite,)),
    "cosim.agent_policies": Trial({"robots.driver": "agents"}, 10.0, (finite, moves)),
}
"""The trial of each of cosim's groups; a plugin's own group gets :data:`ANY_GROUP`."""
ANY_GROUP = Trial({}, 10.0)


def choosing_key(group: Group) -> tuple[str, bool] | None:
    """The scenario key that chooses an entry of ``group``, and whether it takes a list."""
    for section, cls in section_classes().items():
        for field in dataclasses.fields(cls):
            if field.metadata.get("registry") == group.entry_points:
                return f"{section}.{field.name}", isinstance(field.default, tuple)
    return None


def trial_checks(
    group: Group,
    name: str,
    entry: Any,
    overrides: Mapping[str, Any],
    duration_s: float | None,
) -> Iterator[Outcome]:
    """The scenario, run, summary, repeat and rule checks of one entry, in order.

    Args:
        group: the entry's group.
        name: its registered name.
        entry: the loaded entry (its class).
        overrides: the user's scenario keys, applied last.
        duration_s: simulated time (s; default: the group's).
    """
    if group == SECTIONS:
        yield round_trip(name, overrides)
        return
    key = choosing_key(group)
    if key is None:
        yield skip(
            "runs",
            f"no scenario key chooses a {group.words} (none is declared with "
            f"param(..., registry={group.entry_points!r})): nothing to run it in",
        )
        return
    if getattr(entry, "live", False) is True:
        yield skip(
            "runs",
            "a live source needs its outside system: try it with `cosim run` against that "
            "system (its contract and settings are checked above)",
        )
        return
    trial = TRIALS.get(group.entry_points, ANY_GROUP)
    chosen, as_list = key
    asked = {**trial.overrides, chosen: [name] if as_list else name, **overrides}
    try:
        scenario = load_scenario(PRESET, {**SMALL_WAREHOUSE, **asked})
        check_scenario(scenario)  # what the run's adapters refuse before anything is built
    except ConfigError as error:
        yield fail("scenario", f"{error}; give what it needs with --set SECTION.KEY=VALUE")
        return
    except Exception as error:  # an adapter's own check_scenario is a plugin's code
        yield fail("scenario", raised(error))
        return
    said = ", ".join(f"{k} = {v!r}" for k, v in asked.items())
    yield ok("scenario", f"{PRESET} (16 m x 16 m, 3 robots) with {said}")
    seconds = duration_s if duration_s is not None else trial.duration_s
    first = try_run(scenario, seconds)
    if isinstance(first, Outcome):
        yield first
        return
    yield ok(
        "runs",
        f"{seconds:g} s simulated in {first.summary['wall_time_s']:.3g} s of wall-clock time",
    )
    yield flat_summary(first)
    yield declared_summary(first, name, entry)
    second = try_run(scenario, seconds)
    if isinstance(second, Outcome):
        yield fail("repeats", f"the second run with the same seed failed: {second.detail}")
        return
    try:
        assert_same_run(first, second)
    except AssertionError as error:
        yield fail("repeats", f"two runs with seed {scenario.seed}: {error}")
    else:
        yield ok(
            "repeats", f"a second run with seed {scenario.seed} gave the same tables and summary"
        )
    for rule in trial.rules:
        yield rule(first, entry)


def try_run(scenario: Scenario, duration_s: float) -> RunResult | Outcome:
    """The run's result, or the failed ``runs`` check naming what went wrong and where."""
    try:
        result = run(scenario, duration_s=duration_s)
    except Exception as error:  # the plugin's fault, whatever it raised, is this check's
        return fail("runs", raised(error))
    ended = result.summary.get("failed") or result.summary.get("stopped")
    if ended:  # a run that ended early and kept what ran is no run to the end
        return fail("runs", f"the run ended at t = {result.summary['sim_time_s']:g} s: {ended}")
    return result


def raised(error: BaseException) -> str:
    """An error in one line; one that is not cosim's own says where it was raised."""
    if isinstance(error, CosimError):
        return " ".join(str(error).split("\n"))
    said = f"{type(error).__name__}: {' '.join(str(error).split())}"
    ours: list[tuple[str, int, str]] = []  # frames in cosim's code
    theirs: list[tuple[str, int, str]] = []  # frames in a plugin's
    for frame, line in traceback.walk_tb(error.__traceback__):
        module = str(frame.f_globals.get("__name__", ""))
        owner = plugin_of_module(module)
        if owner is not None:
            (ours if owner.builtin else theirs).append((module, line, frame.f_code.co_name))
    if theirs or ours:
        module, line, function = (theirs or ours)[-1]  # the plugin's own line, if on the way
        said += f" (raised in {module}, line {line}, {function})"
    return said


def flat_summary(result: RunResult) -> Outcome:
    """``summary.json`` is flat: numbers, strings, true/false or null, by key.

    Besides cosim's own records (:data:`~cosim.runner.result.RECORD_KEYS`).
    """
    nested = [
        f"{key} = {value!r}"
        for key, value in result.summary.items()
        if key not in RECORD_KEYS
        and not (value is None or isinstance(value, bool | int | float | str))
    ]
    if nested:
        return fail(
            "summary",
            f"summary entries that are no number, string, true/false or null: {', '.join(nested)}",
        )
    try:
        json.dumps(result.summary)
    except (TypeError, ValueError) as error:
        return fail("summary", f"summary.json cannot be written: {error}")
    return ok("summary", f"{len(result.summary)} flat entries")


def declared_summary(result: RunResult, name: str, entry: Any) -> Outcome:
    """Every key of ``summary.json`` is declared with its unit and meaning.

    Each writer declares its keys in a ``summary_keys`` class attribute (key ->
    :class:`~cosim.core.summary.SummaryKey`), from which the summary reference is
    generated. A key the run wrote that nothing installed (nor the entry) declares is a
    warning: the reference cannot document it, but nothing breaks. A declaration that is
    no mapping of keys to a ``SummaryKey`` with a unit and a one-line doc fails.
    """
    problems = declaration_problems(entry)
    if problems:
        return fail("declared", f"{name}: " + "; ".join(problems))
    declared = declared_keys(entry)
    missing = [key for key in result.summary if key not in declared]
    if missing:
        listed = ", ".join(missing)
        return warn(
            "declared",
            f"summary key{'s' * (len(missing) > 1)} {listed} declared nowhere: declare each "
            "in the summary_keys of the class that writes it (key -> "
            "cosim.core.summary.SummaryKey(unit, doc)), so the summary reference documents it",
        )
    own = len(summary_keys_of(entry))
    mine = f", {own} of them by {name}" if own else ""
    return ok(
        "declared",
        f"the {len(result.summary)} summary keys are declared with unit and meaning{mine}",
    )


def round_trip(name: str, overrides: Mapping[str, Any]) -> Outcome:
    """The section is in every scenario and survives a resolved ``scenario.toml``."""
    try:
        scenario = load_scenario(PRESET, dict(overrides))
        again = scenario_from_text(dump_scenario(scenario), "scenario.toml")
    except Exception as error:  # the section's own code (problems(), its values) included
        return fail("scenario", f"[{name}] does not go through scenario.toml: {raised(error)}")
    if name not in scenario.sections:
        return fail("scenario", f"{PRESET} has no [{name}] section")
    if again.sections.get(name) != scenario.sections[name]:
        return fail(
            "scenario",
            f"[{name}] changes through scenario.toml: {scenario.sections[name]!r} is read back "
            f"as {again.sections.get(name)!r}",
        )
    return ok("scenario", f"[{name}] is in {PRESET} and reads back the same from scenario.toml")
