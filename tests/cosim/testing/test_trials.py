"""The short real runs of ``cosim check-plugin``: plugins broken on purpose fail, by name."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from adapters.assignment.contract import PROTOCOLS, EpochView, ProtocolBase
from adapters.mocap.contract import MOCAP_SOURCES
from adapters.navigation.contract import CONTROLLERS
from cosim.core.registry import ADAPTERS, Group, registered
from cosim.core.summary import SummaryKey
from cosim.scenario.fields import param
from cosim.scenario.model import SECTIONS
from cosim.testing.trials import choosing_key, raised, trial_checks


def lines(group: Group, name: str, entry: Any, **overrides: Any) -> list[str]:
    with registered(group.entry_points, name, entry):
        return [o.line() for o in trial_checks(group, name, entry, overrides, None)]


def test_the_key_that_chooses_an_entry_is_found_from_the_settings():
    assert choosing_key(PROTOCOLS) == ("assignment.protocol", False)
    assert choosing_key(ADAPTERS) == ("scenario.adapters", True)
    assert choosing_key(MOCAP_SOURCES) == ("mocap.source", False)


class Nobody(ProtocolBase):
    """Its robots never take a task."""

    name: ClassVar[str] = "nobody"
    central: ClassVar[bool] = True  # the base station decides: and gives no orders

    def agent(self, epoch: EpochView) -> None:
        return None


def test_a_protocol_that_assigns_nobody_fails_assigns_naming_every_task():
    said = lines(PROTOCOLS, "nobody", Nobody)
    assert [line.split(":")[0] for line in said] == [
        "ok   scenario", "ok   runs", "ok   summary", "ok   declared", "ok   repeats",
        "FAIL assigns", "ok   conflicts",
    ]  # fmt: skip
    assert said[5] == (
        "FAIL assigns: 3 of 3 tasks not claimed within 5 s of appearing: task 0 (appeared at "
        "0 s, never claimed by the end at 15 s); task 1 (appeared at 0 s, never claimed by "
        "the end at 15 s); task 2 (appeared at 0 s, never claimed by the end at 15 s) (on a "
        "network that loses nothing)"
    )


class Idle(ProtocolBase):
    """Robots decide alone, and never on anything."""

    name: ClassVar[str] = "idle"

    def agent(self, epoch: EpochView) -> None:
        return None


def test_robots_deciding_alone_on_nothing_fail_even_the_lesser_rule():
    said = lines(PROTOCOLS, "idle", Idle)
    assert "FAIL assigns: no task of 3 claimed within 5 s of appearing" in said[5]
    assert said[6].startswith("skip conflicts: 0 allowed: it exchanges no messages")


class NanControl:
    """A controller that commands not-a-number speeds."""

    name: ClassVar[str] = "nan_control"

    def __init__(self, context: Any) -> None:
        self.robots = len(context.radii_m)

    def commands(self, inputs: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        n = len(inputs.pose)
        return np.full(n, math.nan), np.zeros(n), np.zeros(n, dtype=bool)


def test_a_controller_returning_nan_fails_its_run_or_its_finite_poses():
    said = lines(CONTROLLERS, "nan_control", NanControl)
    failed = [line for line in said if line.startswith("FAIL")]
    assert failed and failed[0].split(":")[0] in ("FAIL runs", "FAIL finite"), said
    assert said[0].startswith("ok   scenario: warehouse-random (16 m x 16 m, 3 robots) with "
                              "robots.driver = 'navigation', navigation.controller = "
                              "'nan_control'")  # fmt: skip


class BadFinish:
    """An adapter whose finish() hands back a list."""

    name: ClassVar[str] = "bad_finish"
    requires: ClassVar[tuple[str, ...]] = ("fleet",)

    def __init__(self, run: Any) -> None: ...

    def start(self, run: Any) -> None: ...

    def finish(self, run: Any) -> list[int]:
        return [1, 2]


def test_an_adapter_whose_finish_returns_no_mapping_fails_its_run():
    said = lines(ADAPTERS, "bad_finish", BadFinish)
    assert said[0] == (
        "ok   scenario: warehouse-random (16 m x 16 m, 3 robots) with robots.driver = "
        "'waypoints', scenario.adapters = ['bad_finish']"
    )
    assert said[1].startswith("FAIL runs: ") and len(said) == 2


class Live:
    """A live pose source: needs its system."""

    name: ClassVar[str] = "live_probe"
    live: ClassVar[bool] = True


def test_a_live_source_is_not_run_and_says_why():
    assert lines(MOCAP_SOURCES, "live_probe", Live) == [
        "skip runs: a live source needs its outside system: try it with `cosim run` against "
        "that system (its contract and settings are checked above)"
    ]


def test_a_group_no_key_chooses_from_is_not_run():
    gadgets = Group("cosim.test_gadgets", "gadget", "gadgets", "x", "nothing")
    (said,) = [o.line() for o in trial_checks(gadgets, "g", object, {}, None)]
    assert said.startswith("skip runs: no scenario key chooses a gadget")


def test_a_scenario_the_users_keys_break_fails_scenario_saying_how_to_give_keys():
    said = lines(PROTOCOLS, "nobody", Nobody, **{"assignment.protocl": "nobody"})
    assert said == [
        "FAIL scenario: --set assignment.protocl: [assignment] unknown key 'protocl'; did you "
        "mean 'protocol'?; give what it needs with --set SECTION.KEY=VALUE"
    ]


@dataclass(frozen=True)
class Odd:
    """``[odd]``: a key whose default TOML cannot give back."""

    gain: float = param(math.nan, "a gain")


@dataclass(frozen=True)
class Fine:
    """``[fine]``: a plain section."""

    gain: float = param(1.5, "a gain")


def test_a_section_must_read_back_the_same_from_a_resolved_scenario_toml():
    assert lines(SECTIONS, "fine", Fine) == [
        "ok   scenario: [fine] is in warehouse-random and reads back the same from scenario.toml"
    ]
    (said,) = lines(SECTIONS, "odd", Odd)
    assert re.fullmatch(
        r"FAIL scenario: \[odd\] does not go through scenario.toml: ValueError: cannot write "
        r"non-finite nan to TOML \(raised in cosim.scenario.loader, line \d+, toml_value\)",
        said,
    )


def test_an_error_of_a_plugins_code_says_where_it_was_raised():
    def plugin_code() -> None:
        raise ValueError("bad\nvalue")

    with registered("cosim.adapters", "raiser", plugin_code):
        try:
            plugin_code()
        except ValueError as error:
            said = raised(error)
    assert said.startswith("ValueError: bad value (raised in tests.cosim.testing.test_trials, line")
    assert said.endswith(", plugin_code)")


def test_a_summary_entry_that_is_not_flat_fails_summary():
    class Nested:
        name: ClassVar[str] = "nested"
        requires: ClassVar[tuple[str, ...]] = ()

        def __init__(self, run: Any) -> None: ...

        def start(self, run: Any) -> None: ...

        def finish(self, run: Any) -> Mapping[str, Any]:
            return {"nested_counts": {"a": 1}}

    said = lines(ADAPTERS, "nested", Nested)
    assert "FAIL summary: summary entries that are no number, string, true/false or null: " \
           "nested_counts = {'a': 1}" in said  # fmt: skip


def _gadget(keys: object) -> type:
    """An adapter writing ``gadget_fixes`` that declares ``keys`` (none: declares nothing)."""

    class Gadget:
        name: ClassVar[str] = "gadget"
        requires: ClassVar[tuple[str, ...]] = ()

        def __init__(self, run: Any) -> None: ...

        def start(self, run: Any) -> None: ...

        def finish(self, run: Any) -> Mapping[str, Any]:
            return {"gadget_fixes": 3, "gadget_closest_m": 0.5}

    if keys is not None:
        Gadget.summary_keys = keys  # type: ignore[attr-defined]
    return Gadget


def _declared(said: list[str]) -> str:
    return next(line for line in said if line.split(":")[0].split()[-1] == "declared")


def test_summary_keys_a_plugin_declares_nowhere_are_a_warning_naming_them_and_how():
    said = lines(ADAPTERS, "gadget", _gadget(None))
    assert _declared(said) == (
        "warn declared: summary keys gadget_fixes, gadget_closest_m declared nowhere: declare "
        "each in the summary_keys of the class that writes it (key -> "
        "cosim.core.summary.SummaryKey(unit, doc)), so the summary reference documents it"
    )
    assert not any(line.startswith("FAIL") for line in said)
    one = {"gadget_fixes": SummaryKey("count", "fixes taken")}
    assert _declared(lines(ADAPTERS, "gadget", _gadget(one))).startswith(
        "warn declared: summary key gadget_closest_m declared nowhere: "
    )


def test_a_plugin_declaring_its_summary_keys_passes_the_check():
    keys = {
        "gadget_fixes": SummaryKey("count", "fixes taken"),
        "gadget_closest_m": SummaryKey("m", "closest thing seen"),
    }
    found = _declared(lines(ADAPTERS, "gadget", _gadget(keys)))
    assert re.fullmatch(
        r"ok   declared: the \d+ summary keys are declared with unit and meaning, 2 of them by "
        r"gadget",
        found,
    )


def test_a_declaration_without_a_unit_or_no_summary_key_fails():
    keys = {"gadget_fixes": SummaryKey("", "fixes taken"), "gadget_closest_m": ("m", "closest")}
    assert _declared(lines(ADAPTERS, "gadget", _gadget(keys))) == (
        "FAIL declared: gadget: summary_keys['gadget_fixes'] has no unit: give one (s, m, "
        "bytes, ...), or say what a unitless value is (count, fraction, ratio, true/false, "
        "text); summary_keys['gadget_closest_m'] is a tuple; expected a SummaryKey"
    )


def test_a_run_that_ended_early_keeping_what_ran_fails_runs(monkeypatch):
    from cosim.testing import trials
    from tests.cosim.testing.conftest import made_run

    ended = made_run({}, sim_time_s=3.5, failed="robot_2 went silent")
    monkeypatch.setattr(trials, "run", lambda scenario, duration_s: ended)
    said = lines(PROTOCOLS, "nobody", Nobody)
    assert said[1:] == ["FAIL runs: the run ended at t = 3.5 s: robot_2 went silent"]
