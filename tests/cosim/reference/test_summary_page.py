"""The summary.json reference: every declared key, its unit, meaning and writer, as written."""

from __future__ import annotations

import re
from collections.abc import Mapping
from pathlib import Path

import pytest

from adapters.mapping.bagmap import SUMMARY_KEYS as MAP_SUMMARY_KEYS
from cosim.cli.bagmap import map_bag
from cosim.core.summary import SummaryKey
from cosim.reference import summary_page
from cosim.reference.summary_page import keys_table, summary_markdown, writer_markdown
from cosim.runner.summary_keys import DeclaredSummary, declared_summaries
from tests.adapters.mapping.recordings import drive, write
from tests.cosim.reference.rendered import as_shown, rows, shown


@pytest.fixture(scope="module")
def page() -> str:
    return summary_markdown()


def _section(page: str, heading: str) -> str:
    return page.split(f"\n## {heading}\n", 1)[1].split("\n## ", 1)[0]


def _expected_row(key: str, declared: SummaryKey) -> list[str]:
    marks = [f"only: {declared.when}"] if declared.when else []
    marks += ["volatile"] if declared.volatile else []
    note = f" ({'; '.join(marks)})" if marks else ""
    return [key, declared.unit, as_shown(declared.doc) + note]


def test_every_writer_has_a_section_with_a_row_per_key_in_order(page):
    summaries = declared_summaries()
    headings = re.findall(r"^## (.+)$", page, flags=re.M)
    assert len(headings) == len(summaries) + 1 and headings[-1] == "`cosim map`"
    for summary in summaries:
        heading = summary.writer[0].upper() + summary.writer[1:]
        block = _section(page, heading)
        assert block.startswith(f"\n*Package `{summary.package}`.*\n"), heading
        assert rows(block) == [_expected_row(k, v) for k, v in summary.keys.items()], heading


def test_the_keys_the_issue_found_undocumented_are_there_with_their_units(page):
    found = {row[0]: row[1:] for row in rows(page)}
    assert found["claims_released"] == ["count", "times a robot gave its task up"]
    assert found["latency_ms_p95"][0] == "ms"
    assert found["latency_ms_p95"][1].startswith("95th percentile one-way latency")
    assert found["sim_time_s"][0] == "s" and found["network_bytes"][0] == "bytes"
    assert found["wall_time_s"][1].endswith("(volatile)")
    assert found["max_lateness_ms"][1].endswith("(only: real-time runs; volatile)")


def test_the_page_says_where_the_keys_are_declared_and_how_a_plugin_declares_its_own(page):
    assert page.startswith("# summary.json\n")
    said = shown(page)
    for words in (
        "`summary_keys` class attribute",
        "cosim.core.summary.SummaryKey(unit, doc)",
        "cosim/runner/summary_keys.py",
        "A plugin declares its keys the same way",
        "cosim check-plugin",
    ):
        assert as_shown(words) in said, words


def test_a_plugin_s_keys_show_as_written_whatever_they_quote(monkeypatch):
    keys = {
        "gadget_fixes": SummaryKey("count", "fixes on /<robot>/gadget | '*' any {robot}"),
        "gadget_gain": SummaryKey("1/m", "slope", when="gadget.mode = 'a'", volatile=True),
    }
    plugin = DeclaredSummary("adapter `gadget`", "testkit", keys)
    monkeypatch.setattr(summary_page, "declared_summaries", lambda: [plugin])
    page = summary_markdown()
    assert "\n## Adapter `gadget`\n\n*Package `testkit`.*\n" in page
    assert rows(_section(page, "Adapter `gadget`")) == [
        ["gadget_fixes", "count", "fixes on /<robot>/gadget | '*' any {robot}"],
        ["gadget_gain", "1/m", "slope (only: gadget.mode = 'a'; volatile)"],
    ]


def test_a_writer_section_and_a_keys_table_are_markdown_tables():
    summary = DeclaredSummary("the runner (every run)", "cosim", {"x_s": SummaryKey("s", "x")})
    assert writer_markdown(summary) == [
        "## The runner (every run)",
        "",
        "*Package `cosim`.*",
        "",
        "| key | unit | meaning |",
        "|---|---|---|",
        "| `x_s` | s | x |",
        "",
    ]
    assert keys_table({}) == ["| key | unit | meaning |", "|---|---|---|"]


def _map_keys(tmp_path: Path) -> Mapping[str, object]:
    bag = write(tmp_path / "bag", drive())
    return map_bag(bag, tmp_path / "map", reference_topic="/ground_truth").summary


def test_the_keys_cosim_map_writes_are_declared_and_on_the_page(tmp_path, page):
    written = _map_keys(tmp_path)
    assert list(written) == list(MAP_SUMMARY_KEYS)  # a reference given: every key
    block = _section(page, "`cosim map`")
    assert [row[0] for row in rows(block)] == list(MAP_SUMMARY_KEYS)
