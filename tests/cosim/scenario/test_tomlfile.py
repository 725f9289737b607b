"""Reading TOML files with answers that point at the line, and nesting kept shallow."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cosim.core.errors import ConfigError
from cosim.scenario.tomlfile import (
    MAX_DEPTH,
    SHOWN_CHARS,
    deeper_than,
    parse_toml,
    read_toml_file,
    refuse_long_keys,
    too_deep,
)


def _refusal(text: str) -> str:
    with pytest.raises(ConfigError) as refused:
        parse_toml(text, "s.toml")
    return str(refused.value)


def test_a_toml_file_is_read_into_its_tables(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text("[robots]\ncount = 3\n\n[world]\nsize_m = [12.0, 9.5]\n", encoding="utf-8")
    assert read_toml_file(path, "scenario file") == {
        "robots": {"count": 3},
        "world": {"size_m": [12.0, 9.5]},
    }


def test_a_file_that_cannot_be_read_is_named_with_the_reason(tmp_path):
    with pytest.raises(ConfigError) as refused:
        read_toml_file(tmp_path / "nope.toml", "study file")
    assert str(refused.value) == (
        f"{tmp_path / 'nope.toml'}: cannot read study file (No such file or directory)"
    )


def test_a_byte_that_is_not_utf8_is_named_with_its_line(tmp_path):
    path = tmp_path / "s.toml"
    path.write_bytes(b'[robots]\ncount = 3\nname = "\xe9t\xe9"\n')
    with pytest.raises(ConfigError) as refused:
        read_toml_file(path, "scenario file")
    assert str(refused.value) == (
        f"{path}: line 3: byte 0xe9 is not UTF-8; expected a UTF-8 text scenario file"
    )


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("a = 1\n\tb = = 2\n", "s.toml: line 2: b = = 2  <- invalid value (malformed TOML)"),
        ("[a]\n[a]\n", "s.toml: line 2: [a]  <- cannot declare ('a',) twice (malformed TOML)"),
        ("a = [1,\n", "s.toml: malformed TOML: Invalid value (at end of document)"),
    ],
)
def test_malformed_toml_names_the_line_shows_it_and_says_the_complaint(text, message):
    assert _refusal(text) == message


def test_a_long_bad_line_is_shortened_and_its_tabs_shown_as_spaces():
    message = _refusal("[robots]\ncount =\t" + "9 " * 200 + "\n")
    shown = message.split("line 2: ", 1)[1].split("  <- ", 1)[0]
    assert len(shown) == SHOWN_CHARS and shown.endswith("...")
    assert shown.startswith("count = 9 9") and "\t" not in shown


@pytest.mark.parametrize(
    "value",
    [
        "[" * 1500 + "]" * 1500,
        "{b = " * 1500 + "1" + "}" * 1500,
        "[" * 100_000 + "]" * 100_000,
    ],
    ids=["arrays", "inline tables", "a hundred thousand arrays"],
)
def test_a_file_nested_thousands_deep_is_one_line_naming_the_file(tmp_path, value):
    path = tmp_path / "deep.toml"
    path.write_text(f"a = {value}\n", encoding="utf-8")
    with pytest.raises(ConfigError) as refused:
        read_toml_file(path, "scenario file")
    assert str(refused.value) == (
        f"{path}: tables or arrays nested deeper than {MAX_DEPTH} levels; expected at most "
        f"{MAX_DEPTH} (a scenario needs 4)"
    )


def test_a_dotted_key_of_many_parts_is_refused_before_the_reader_takes_its_time():
    text = "[scenario]\n" + ".".join(["a"] * 100_000) + " = 1\n"
    with pytest.raises(ConfigError, match=r"^s\.toml: line 2: a dotted key of more than 100 parts"):
        parse_toml(text, "s.toml")


def test_tables_a_hundred_and_one_deep_are_refused_once_read():
    key = ".".join(["a"] * (MAX_DEPTH - 1)) + " = 1\n"  # 98 tables in each other
    assert parse_toml("[x]\n" + key, "s.toml")  # the file, x and 98 tables: 100 levels
    with pytest.raises(ConfigError, match="nested deeper than 100 levels"):
        parse_toml("[x.y]\n" + key, "s.toml")


def test_long_lists_of_numbers_are_not_taken_for_dotted_keys():
    text = "[world]\nobstacles = [" + ", ".join(["[1.0, 2.0, 3.5, 4.5]"] * 2000) + "]\n"
    assert len(parse_toml(text, "s.toml")["world"]["obstacles"]) == 2000


def test_a_dotted_key_of_a_hundred_parts_is_taken_and_one_on_one_line_is_named_without_line():
    refuse_long_keys(".".join(["a"] * MAX_DEPTH) + " = 1", "s.toml")  # 99 dots: allowed
    with pytest.raises(ConfigError) as refused:
        refuse_long_keys(".".join(['"a b"'] * (MAX_DEPTH + 1)) + " = 1", "--set x")
    assert str(refused.value) == (
        f"--set x: a dotted key of more than {MAX_DEPTH} parts; expected tables nested at most "
        f"{MAX_DEPTH} levels deep"
    )


def test_depth_counts_tables_and_arrays_from_one_at_the_top_without_recursing():
    assert not deeper_than({}, 1)
    assert deeper_than({"a": {}}, 1) and not deeper_than({"a": {}}, 2)
    assert not deeper_than({"a": [[1, 2]]}, 3) and deeper_than({"a": [[1, 2]]}, 2)
    nested: list[object] = []
    for _ in range(50_000):  # deeper than Python's stack
        nested = [nested]
    assert deeper_than(nested, MAX_DEPTH) and not deeper_than(nested, 50_001)
    assert too_deep("s.toml").startswith("s.toml: tables or arrays nested deeper than 100")


@settings(max_examples=200, deadline=None)
@given(text=st.text(alphabet=st.sampled_from(list("[]{}=.\"'#ab1 ,\n\t\\")), max_size=80))
def test_any_text_is_read_or_refused_in_one_line_naming_the_origin(text):
    try:
        data = parse_toml(text, "s.toml")
    except ConfigError as refused:
        message = str(refused)
        assert message.startswith("s.toml: ") and "\n" not in message
    else:
        assert isinstance(data, dict)
