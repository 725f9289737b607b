"""Quoted text on the generated pages shows as written, once rendered as the site renders it."""

from __future__ import annotations

import pytest

from cosim.reference.commands_page import commands_markdown
from cosim.reference.escaping import cell, code, fenced, text
from cosim.reference.keys_page import keys_markdown
from cosim.reference.registries_page import registries_markdown
from cosim.reference.summary_page import summary_markdown
from cosim.reference.tables_page import tables_markdown
from tests.cosim.reference.rendered import cells, render, shown, tags

QUOTED = [
    "/<robot>/cmd_vel",
    "/vicon/<subject>/<segment>",
    "ros2-vicon-receiver publishes /vicon/<subject>/<segment>",
    "glob patterns ('*' any text, '*' again)",
    "_private_ names and x_ and __init__",
    "snake_case_names stay as they are",
    "the {robot} token",
    "ends with {robot}",
    "x {: .class}",
    "[x](not-a-link) and [a][b]",
    "[x, y] (m)",
    "a | b",
    "P(good -> bad) and 1 < 2 > 0",
    "<!-- not a comment --> <b>not bold</b>",
    "&lt; stays as typed, R&D too",
    "a \\ backslash and a\\*b",
    "a stray ` backtick",
    "- not a list",
    "> not a quote",
    "# not a heading",
    "2. not a list",
]


def _table(value: str) -> str:
    return f"| a | b |\n|---|---|\n| {value} | x |\n"


@pytest.mark.parametrize("written", QUOTED)
def test_quoted_text_shows_as_written_in_a_table_cell(written):
    assert cells(_table(cell(written))) == [" ".join(written.split()), "x"]


@pytest.mark.parametrize("written", QUOTED)
def test_quoted_text_shows_as_written_in_prose(written):
    assert shown(text(written)) == " ".join(written.split())


def test_an_angle_bracket_name_is_no_html_tag():
    page = _table(cell("/<robot>/cmd_vel")) + "\n" + text("on /<robot>/goal_pose") + "\n"
    assert "robot" not in tags(page)
    assert "/<robot>/goal_pose" in shown(page)


def test_unescaped_the_angle_brackets_would_be_swallowed():
    # what the references did before: the check above would catch it
    assert cells(_table("/<robot>/cmd_vel")) == ["//cmd_vel", "x"]
    assert "robot" in tags(_table("/<robot>/cmd_vel"))


def test_code_spans_in_quoted_text_stay_code():
    written = "sets `drift` m, `a|b` and `<robot>` as code"
    assert "<code>drift</code>" in render(text(written))
    assert "<code>&lt;robot&gt;</code>" in render(cell(written))
    assert cells(_table(cell(written))) == ["sets drift m, a|b and <robot> as code", "x"]


def test_a_cell_is_one_line_with_its_pipes_escaped_outside_code():
    assert cell("one\ntwo | three `x|y`") == "one two \\| three `x|y`"


@pytest.mark.parametrize("value", ["plain", "a`b", "`starts", "ends`", "x``y`", "a|b", "<robot>"])
def test_code_shows_a_value_whole_whatever_backticks_and_pipes_it_holds(value):
    assert cells(_table(code(value))) == [value, "x"]
    assert f"<code>{value.replace('<', '&lt;').replace('>', '&gt;')}</code>" in render(code(value))


def test_a_fenced_block_is_closed_by_a_longer_fence_than_any_inside():
    inner = "usage:\n```\nnot the end\n```\n<robot>"
    lines = fenced(inner)
    assert lines[0] == "````text" and lines[-1] == "````"
    html = render("\n".join(lines))
    assert html.count("<pre") == 1 and "not the end" in html and "&lt;robot&gt;" in html


def test_text_leaves_plain_prose_alone():
    said = "every key (m/s), one of 'a', 'b'; >= 0 and <= 1: map_quality rows"
    assert text(said) == said
    assert cell(said) == said


MARKUP = {"h1", "h2", "h3", "p", "em", "code", "a", "ul", "li", "pre", "div", "span"}
TABLES = {"table", "thead", "tbody", "tr", "th", "td"}


@pytest.mark.parametrize(
    "page",
    [keys_markdown, tables_markdown, summary_markdown, commands_markdown, registries_markdown],
)
def test_no_generated_page_holds_a_tag_of_what_it_quotes(page):
    # a quoted <robot>, <subject> or <b> would be a tag of its own; *x* would be em only
    # where the generator marks something (category, volatile, registered by)
    assert tags(page()) <= MARKUP | TABLES
