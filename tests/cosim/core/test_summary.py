"""Summary keys declared beside the code that writes them: what a declaration must hold."""

from __future__ import annotations

from collections.abc import Mapping
from typing import ClassVar

import pytest

from cosim.core.summary import SummaryKey, declaration_problems, key_problems, summary_keys_of


class Declares:
    summary_keys: ClassVar[Mapping[str, SummaryKey]] = {
        "battery_lowest": SummaryKey("fraction", "lowest charge of any robot at the end"),
        "battery_swaps": SummaryKey("count", "batteries swapped", when="battery.swap = true"),
    }


def test_an_entry_s_declared_keys_are_read_in_order():
    keys = summary_keys_of(Declares)
    assert list(keys) == ["battery_lowest", "battery_swaps"]
    assert keys["battery_swaps"] == SummaryKey("count", "batteries swapped", "battery.swap = true")
    assert not keys["battery_lowest"].volatile and keys["battery_lowest"].when == ""


def test_an_entry_without_a_declaration_declares_nothing_and_has_no_problem():
    assert summary_keys_of(object()) == {}
    assert declaration_problems(object()) == []
    assert declaration_problems(Declares) == []


def test_a_declaration_that_is_no_mapping_of_summary_keys_is_named():
    class Listed:
        summary_keys = ("battery_lowest",)

    class Loose:
        summary_keys: ClassVar[Mapping[object, object]] = {
            "battery_lowest": ("fraction", "lowest charge"),
            "": SummaryKey("count", "nothing"),
            "battery_ok": SummaryKey("count", "fine"),
        }

    assert summary_keys_of(Listed) == {}
    assert declaration_problems(Listed) == [
        "summary_keys is a tuple; expected a mapping of key names to cosim.core.summary.SummaryKey"
    ]
    assert list(summary_keys_of(Loose)) == ["", "battery_ok"]
    assert declaration_problems(Loose) == [
        "summary_keys['battery_lowest'] is a tuple; expected a SummaryKey",
        "summary_keys has the key ''; expected a non-empty string",
    ]


@pytest.mark.parametrize(
    ("key", "problem"),
    [
        (SummaryKey("", "what it is"), "has no unit"),
        (SummaryKey("  ", "what it is"), "has no unit"),
        (SummaryKey("count", ""), "has no doc"),
        (SummaryKey("count", "two\nlines"), "has a doc of several lines"),
    ],
)
def test_a_key_without_a_unit_or_a_one_line_meaning_is_named(key, problem):
    found = key_problems(key)
    assert len(found) == 1 and found[0].startswith(problem)


def test_an_empty_declaration_is_named_with_its_key():
    class Empty:
        summary_keys: ClassVar[Mapping[str, SummaryKey]] = {"x_total": SummaryKey("", "")}

    problems = declaration_problems(Empty)
    assert [p.split(":")[0] for p in problems] == [
        "summary_keys['x_total'] has no unit",
        "summary_keys['x_total'] has no doc",
    ]
