"""The scenario key reference: every key of every registered section, with what it accepts."""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass
from typing import ClassVar, Literal

import pytest

from cosim.reference.keys_page import UNITS, keys_markdown, section_markdown, unit_of
from cosim.scenario.fields import param
from cosim.scenario.model import section_classes
from tests.conftest import cosim_main


def _resolved_keys(text: str) -> list[tuple[str, str]]:
    section, keys = "", []
    for line in text.splitlines():
        if match := re.fullmatch(r"\[(\w+)\]", line):
            section = match.group(1)
        elif match := re.match(r"(\w+) = ", line):
            keys.append((section, match.group(1)))
    return keys


def _cells(row: str) -> list[str]:
    """The cells of a Markdown table row (``\\|`` is a pipe inside a cell)."""
    return [c.strip().replace("\\|", "|") for c in re.split(r"(?<!\\)\|", row)[1:-1]]


def _rows(page: str) -> dict[str, dict[str, list[str]]]:
    """Section (``robots``, ``network.partitions``) -> key -> its cells after the key."""
    found: dict[str, dict[str, list[str]]] = {}
    section = ""
    for line in page.splitlines():
        if match := re.fullmatch(r"#{2,3} `\[{1,2}([\w.]+)\]{1,2}`", line):
            section = match.group(1)
            found[section] = {}
        elif match := re.match(r"\| `(\w+)` \|", line):
            found[section][match.group(1)] = _cells(line)[1:]
    return found


@pytest.fixture(scope="module")
def page() -> str:
    return keys_markdown()


def test_every_key_of_the_humans_scenario_is_in_the_key_reference():
    done = cosim_main("check", "warehouse-humans", "--print")
    assert done.returncode == 0, done.stderr
    keys = _resolved_keys(done.stdout)
    assert len(keys) > 100
    page = keys_markdown()
    sections = re.split(r"^## `\[", page, flags=re.M)
    documented = {}
    for block in sections[1:]:
        name = block.split("]", 1)[0]
        documented[name] = set(re.findall(r"^\| `(\w+)` \|", block, flags=re.M))
    for section, key in keys:
        assert key in documented.get(section, set()), f"[{section}] {key} is not documented"


def test_every_registered_section_has_its_heading_and_a_row_per_key_in_registry_order(page):
    rows = _rows(page)
    classes = section_classes()
    headings = re.findall(r"^## `\[(\w+)\]`$", page, flags=re.M)
    assert headings == list(classes)
    for name, cls in classes.items():
        assert list(rows[name]) == [f.name for f in dataclasses.fields(cls)], name


def test_every_key_shows_the_unit_its_name_carries(page):
    rows = _rows(page)
    checked = 0
    for section, keys in rows.items():
        for key, (_default, _expected, unit, _meaning) in keys.items():
            assert unit == unit_of(key), f"[{section}] {key}"
            checked += bool(unit)
    assert checked > 50


@pytest.mark.parametrize(
    ("key", "unit"),
    [
        ("max_speed_mps", "m/s"),
        ("max_accel_mps2", "m/s²"),  # not m/s: the longer suffix wins
        ("max_yaw_accel_radps2", "rad/s²"),
        ("max_yaw_rate_radps", "rad/s"),
        ("bandwidth_mbps", "Mbit/s"),
        ("control_hz", "Hz"),
        ("latency_ms", "ms"),
        ("duration_s", "s"),
        ("radius_m", "m"),
        ("fov_deg", "deg"),
        ("yaw_rad", "rad"),
        ("dropout_prob", "probability"),
        ("count", ""),
        ("ge_p", ""),
    ],
)
def test_a_key_s_unit_comes_from_its_name_s_suffix(key, unit):
    assert unit_of(key) == unit


def test_every_unit_suffix_is_reached_by_some_key_ending_in_it():
    for suffix, unit in UNITS.items():
        assert unit_of("x" + suffix) == unit, suffix


def test_a_key_s_row_gives_its_default_bounds_unit_and_meaning(page):
    rows = _rows(page)
    assert rows["robots"]["max_speed_mps"] == [
        "`1.0`", "a number > 0 and <= 2", "m/s", "forward speed limit (m/s)",
    ]  # fmt: skip
    # a rate declared > 0 keeps the implicit limit of every rate: at least 0.001 Hz
    assert rows["robots"]["control_hz"][1] == "a number >= 0.001 and <= 1000"
    # a time without a declared upper bound gets the implicit one
    assert rows["network"]["latency_ms"][1] == "a number >= 0 and <= 1e+12"
    assert rows["world"]["layout"][1] == "one of 'random', 'all_rows', 'two_corridors'"


def test_a_key_naming_an_implementation_lists_the_registered_names_and_its_off_value(page):
    rows = _rows(page)
    driver = rows["robots"]["driver"][1]
    assert driver.startswith("a registered robot driver: ")
    for name in ("navigation", "tasks", "waypoints", "wander"):
        assert f"`{name}`" in driver
    source = rows["mocap"]["source"][1]
    assert "`simulated`" in source and source.endswith("or `none` (none at all)")
    assert rows["mocap"]["source"][0] == '`"none"`'


def test_a_section_with_profiles_lists_what_each_fills_in(page):
    network = page.split("## `[network]`", 1)[1].split("\n## ", 1)[0]
    assert "Profiles (`network.profile` fills these keys; keys given win):" in network
    assert re.search(r"^- `wifi_nominal`: `latency_model = \"normal\"`, ", network, flags=re.M)


def test_an_array_of_tables_gets_its_own_table_of_keys(page):
    rows = _rows(page)
    assert rows["network"]["partitions"][1] == "a list of tables (`[[network.partitions]]`, below)"
    assert {"from_s", "to_s", "hosts", "links"} <= set(rows["network.partitions"])


@dataclass(frozen=True)
class ItemConfig:
    """One item."""

    size_m: float = param(1.0, "edge of the item (m)", gt=0)


@dataclass(frozen=True)
class GadgetConfig:
    """``[gadget]``: a plugin's section, its doc in ``double backticks``."""

    PROFILES: ClassVar[dict[str, dict[str, object]]] = {"fast": {"rate_hz": 50.0}}

    rate_hz: float = param(5.0, "ticks per second | or none\nat all", gt=0, le=100)
    mode: Literal["a", "b"] = param("a", "which mode")
    label: str = param("", "a name")
    items: tuple[ItemConfig, ...] = param((), "the items")


def test_a_plugin_s_section_is_documented_with_its_package_and_cells_kept_on_one_line():
    lines = section_markdown("gadget", GadgetConfig, "testkit")
    text = "\n".join(lines)
    assert lines[:6] == [
        "## `[gadget]`",
        "",
        f"*Registered by package `testkit` ({__name__}).*",
        "",
        "`[gadget]`: a plugin's section, its doc in `double backticks`.",
        "",
    ]
    rows = _rows(text)
    assert rows["gadget"]["rate_hz"] == [
        "`5.0`", "a number >= 0.001 and <= 100", "Hz", "ticks per second | or none at all",
    ]  # fmt: skip
    assert "ticks per second \\| or none at all" in text  # the pipe escaped, no line break
    assert rows["gadget"]["mode"] == ['`"a"`', "one of 'a', 'b'", "", "which mode"]
    assert rows["gadget"]["label"][:2] == ['`""`', "a string"]
    assert "- `fast`: `rate_hz = 50.0`" in lines
    assert "### `[[gadget.items]]`" in lines
    assert rows["gadget.items"]["size_m"] == ["`1.0`", "a number > 0", "m", "edge of the item (m)"]
