"""The scenario key reference: every key of every registered section, with what it accepts."""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterator
from dataclasses import dataclass
from typing import ClassVar, Literal, get_args, get_type_hints

import pytest

from cosim.reference.keys_page import UNITS, keys_markdown, section_markdown, unit_of
from cosim.scenario.fields import key_unit, param
from cosim.scenario.loader import toml_value
from cosim.scenario.model import section_classes, section_registry
from tests.conftest import cosim_main
from tests.cosim.reference.rendered import as_shown
from tests.cosim.reference.rendered import rows as shown_rows


def _resolved_keys(text: str) -> list[tuple[str, str]]:
    section, keys = "", []
    for line in text.splitlines():
        if match := re.fullmatch(r"\[(\w+)\]", line):
            section = match.group(1)
        elif match := re.match(r"(\w+) = ", line):
            keys.append((section, match.group(1)))
    return keys


def _rows(page: str) -> dict[str, dict[str, list[str]]]:
    """Section (``robots``, ``network.partitions``) -> key -> its cells after the key, as shown."""
    found: dict[str, dict[str, list[str]]] = {}
    blocks = re.split(r"^(#{2,3} .+)$", page, flags=re.M)
    for heading, block in zip(blocks[1::2], blocks[2::2], strict=True):
        if match := re.fullmatch(r"#{2,3} `\[{1,2}([\w.]+)\]{1,2}`", heading):
            found[match.group(1)] = {row[0]: row[1:] for row in shown_rows(block)}
    return found


def _fields(cls: type, prefix: str) -> Iterator[tuple[str, dataclasses.Field[object]]]:
    """Every key of a section, and of its arrays of tables, as (section, field)."""
    hints = get_type_hints(cls)
    for field in dataclasses.fields(cls):
        args = get_args(hints[field.name])
        if len(args) == 2 and args[1] is Ellipsis and dataclasses.is_dataclass(args[0]):
            yield from _fields(args[0], f"{prefix}.{field.name}")
        else:
            yield prefix, field


def _every_key() -> list[tuple[str, dataclasses.Field[object], object]]:
    """Every key of every section cosim registers: (section, field, type)."""
    found = []
    registry = section_registry()
    for name, cls in section_classes().items():
        if registry.package(name) != "cosim":  # a plugin installed here has its own tests
            continue
        for section, field in _fields(cls, name):
            found.append((section, field, get_type_hints(section_class(section))[field.name]))
    return found


def section_class(dotted: str) -> type:
    """The dataclass of ``robots`` or of ``network.partitions``."""
    name, *inner = dotted.split(".")
    cls = section_classes()[name]
    for key in inner:
        cls = get_args(get_type_hints(cls)[key])[0]
    return cls


def _is_number(hint: object) -> bool:
    """Whether a key takes a number (or numbers): an int or float anywhere in its type."""
    if hint is bool:
        return False
    if hint in (int, float):
        return True
    return any(_is_number(arg) for arg in get_args(hint) if arg is not Ellipsis)


def numbers_without_unit(keys: list[tuple[str, dataclasses.Field[object], object]]) -> list[str]:
    """Keys that take a number but neither carry a unit in their name nor declare one."""
    return [f"[{s}] {f.name}" for s, f, hint in keys if _is_number(hint) and not key_unit(f)]


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


def test_every_key_shows_its_declared_unit_or_the_one_its_name_carries(page):
    shown = _rows(page)
    checked = 0
    for section, field, _hint in _every_key():
        unit = shown[section][field.name][2]
        assert unit == key_unit(field), f"[{section}] {field.name}"
        checked += bool(unit)
    assert checked > 80


def test_every_key_that_takes_a_number_has_a_unit_or_says_what_it_counts():
    keys = _every_key()
    assert sum(_is_number(hint) for _, _, hint in keys) > 100
    assert numbers_without_unit(keys) == []


def test_a_number_without_a_unit_is_found():
    @dataclass(frozen=True)
    class Counted:
        things: int = param(3, "how many things")
        named: str = param("a", "a name")
        declared: int = param(3, "how many", unit="count")
        scale: tuple[float, float] = param((1.0, 2.0), "a pair")

    keys = [("counted", f, get_type_hints(Counted)[f.name]) for f in dataclasses.fields(Counted)]
    assert numbers_without_unit(keys) == ["[counted] things", "[counted] scale"]


@pytest.mark.parametrize(
    ("section", "key", "unit"),
    [
        ("network", "tx_power_dbm", "dBm"),
        ("network", "sensitivity_dbm", "dBm"),
        ("network", "ref_loss_db", "dB"),
        ("network", "shadowing_db", "dB"),
        ("navigation", "cost_scaling", "1/m"),
        ("network", "loss_prob", "probability"),
        ("network", "ge_p", "probability"),
        ("network", "ge_loss_bad", "probability"),
        ("mocap", "dropout", "probability"),
        ("robots", "count", "count"),
        ("robots", "positions", "m, m, rad"),
        ("scenario", "seed", "id"),
    ],
)
def test_decibels_inverse_metres_probabilities_and_counts_have_their_unit_shown(
    page, section, key, unit
):
    assert _rows(page)[section][key][2] == unit


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
        ("tx_power_dbm", "dBm"),
        ("shadowing_db", "dB"),
        ("t_sent_ns", "ns"),
        ("capacity_wh", "Wh"),
        ("idle_w", "W"),
        ("drive_wh_per_m", "Wh/m"),  # not m: what comes before _per_ counts
        ("cost_per_m", "1/m"),
        ("rad_per_m", "rad/m"),
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
        "1.0", "a number > 0 and <= 2", "m/s", "forward speed limit (m/s)",
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
    assert {"navigation", "tasks", "waypoints", "wander"} <= set(driver.split(": ")[1].split(", "))
    listed = r"^\| `driver` \| .*\| a registered robot driver: `agents`, `navigation`, "
    assert re.search(listed, page, re.M)
    source = rows["mocap"]["source"][1]
    assert "simulated" in source and source.endswith(", or none (none at all)")
    assert rows["mocap"]["source"][0] == '"none"'


def test_every_key_s_default_and_doc_show_on_the_rendered_page_as_written(page):
    shown = _rows(page)
    for section, field, _hint in _every_key():
        default, _expected, _unit, meaning = shown[section][field.name]
        assert meaning == as_shown(field.metadata["doc"]), f"[{section}] {field.name}"
        written = toml_value(field.default) if field.default is not None else ""
        assert default == " ".join(written.split()), f"[{section}] {field.name}"


def test_names_in_angle_brackets_show_on_the_rendered_page(page):
    shown = _rows(page)
    assert "Twist on /<robot>/cmd_vel" in shown["physical"]["drive"][3]
    assert "/<robot>/goal_pose" in shown["physical"]["drive"][3]
    assert "publishes /vicon/<subject>/<segment>)" in shown["mocap"]["topic_pattern"][3]


def test_a_section_with_profiles_lists_what_each_fills_in(page):
    network = page.split("## `[network]`", 1)[1].split("\n## ", 1)[0]
    assert "Profiles (`network.profile` fills these keys; keys given win):" in network
    assert re.search(r"^- `wifi_nominal`: `latency_model = \"normal\"`, ", network, flags=re.M)


def test_an_array_of_tables_gets_its_own_table_of_keys(page):
    rows = _rows(page)
    assert rows["network"]["partitions"][1] == "a list of tables ([[network.partitions]], below)"
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
    topic: str = param("/{robot}/gadget", "published on /<robot>/gadget; '*' any text {robot}")
    gain: float = param(2.0, "inflation slope", unit="1/m")


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
        "5.0", "a number >= 0.001 and <= 100", "Hz", "ticks per second | or none at all",
    ]  # fmt: skip
    assert rows["gadget"]["topic"] == [
        '"/{robot}/gadget"', "a string", "", "published on /<robot>/gadget; '*' any text {robot}",
    ]  # fmt: skip
    assert rows["gadget"]["gain"] == ["2.0", "a number", "1/m", "inflation slope"]
    assert "ticks per second \\| or none at all" in text  # the pipe escaped, no line break
    assert rows["gadget"]["mode"] == ['"a"', "one of 'a', 'b'", "", "which mode"]
    assert rows["gadget"]["label"][:2] == ['""', "a string"]
    assert "- `fast`: `rate_hz = 50.0`" in lines
    assert "### `[[gadget.items]]`" in lines
    assert rows["gadget.items"]["size_m"] == ["1.0", "a number > 0", "m", "edge of the item (m)"]
