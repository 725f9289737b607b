"""Names that become folder names (cosim.scenario.names): any script, nothing that escapes."""

import os
import unicodedata

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import cosim
from cosim.core.errors import ConfigError
from cosim.scenario.names import NAME_BYTES, NAME_RULE, name_problem

WORLD = ["仓库-1", "склад", "Zürich hall", "गोदाम", "คลังสินค้า", "مستودع", "창고", "انبار\u200cها"]
"""Warehouse in Chinese, Russian, German, Hindi, Thai, Arabic, Korean and Persian (with ZWNJ)."""


@pytest.mark.parametrize("name", [*WORLD, unicodedata.normalize("NFD", "Zürich")])
def test_a_name_in_any_script_is_accepted_and_names_a_folder(tmp_path, name):
    assert name_problem(name) is None
    scenario = cosim.load_scenario("warehouse-random", {"scenario.name": name})
    folder = tmp_path / f"{scenario.name}-seed{scenario.seed}"
    folder.mkdir()
    assert os.listdir(tmp_path) == [folder.name]


@pytest.mark.parametrize(
    ("name", "why"),
    [
        ("", "it is empty"),
        ("a/b", "'/' (U+002F) is not one"),
        ("a\\b", "'\\\\' (U+005C) is not one"),
        ("x\ny", "'\\n' (U+000A) is not one"),
        ("evil\u202etxt.exe", "'\\u202e' (U+202E) is not one"),
        ("a:b", "':' (U+003A) is not one"),
        ("..", "it starts with '.' (a hidden folder)"),
        (".hidden", "it starts with '.' (a hidden folder)"),
        (" hall", "it starts or ends with a space"),
        ("hall ", "it starts or ends with a space"),
        (
            "__model__",
            "SDFormat reserves names between '__' (cosim world --sdf names the world so)",
        ),
        ("仓" * 34, "it has 102 bytes"),
        ("\ud800", "'\\ud800' (U+D800) is not one"),
    ],
)
def test_a_name_that_cannot_name_a_folder_says_why(name, why):
    assert name_problem(name) == why


def test_a_refused_scenario_name_is_one_line_naming_the_key_the_value_and_the_rule():
    with pytest.raises(ConfigError) as caught:
        cosim.load_scenario("warehouse-random", {"scenario.name": "halle/2"})
    assert str(caught.value) == (
        f"--set scenario.name: [scenario] name = 'halle/2': expected {NAME_RULE}; "
        "'/' (U+002F) is not one"
    )


@settings(max_examples=200, deadline=None)
@given(name=st.text(max_size=40))
def test_an_accepted_name_is_one_folder_name_that_stays_where_it_is_put(tmp_path_factory, name):
    if name_problem(name) is not None:
        return
    assert 0 < len(name.encode("utf-8")) <= NAME_BYTES
    invisible = [c for c in name if unicodedata.category(c).startswith("C")]
    assert set(invisible) <= {"\u200c", "\u200d"}
    base = tmp_path_factory.mktemp("names")
    folder = base / f"{name}-seed1"
    folder.mkdir()
    assert folder.resolve().parent == base.resolve() and not folder.name.startswith(".")
