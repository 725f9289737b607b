"""The table reference: every table a run can write, who writes it, what each column means."""

from __future__ import annotations

import re

import pytest

import cosim
from cosim.core.recorder import EVENTS, MESSAGES
from cosim.core.table import TableSpec
from cosim.reference import tables_page
from cosim.reference.tables_page import (
    DocumentedTable,
    column_unit,
    documented_tables,
    tables_markdown,
)
from cosim.runner.lateness import REALTIME
from cosim.scenario.fields import unit_of
from tests.cosim.reference.rendered import as_shown, rows, shown


def _block(page: str, name: str) -> str:
    return page.split(f"## `{name}`\n", 1)[1].split("\n## ", 1)[0]


def test_every_table_a_full_run_writes_is_declared_with_its_columns_and_documented():
    scenario = cosim.load_scenario(
        "warehouse-humans",
        {
            "scenario.duration_s": 4.0,
            "robots.driver": "tasks",
            "mapping.enabled": True,
            "mocap.source": "simulated",
            "mocap.robots": ["robot_1"],
            "mocap.dropout": 0.3,
            "humans.workers": 3,
        },
    )
    result = cosim.run(scenario)
    documented = {t.spec.name: t.spec for t in documented_tables()}
    for name, frame in result.tables.items():
        assert name in documented, f"table {name} has no TableSpec listed by its adapter"
        assert list(frame.columns) == list(documented[name].columns), name
    page = tables_markdown()
    for spec in documented.values():
        assert f"## `{spec.name}`" in page
        for column in spec.columns:
            assert f"| `{column}` |" in page


def test_the_recorder_s_and_the_runner_s_tables_come_first_written_by_cosim():
    tables = documented_tables()
    assert [t.spec for t in tables[:3]] == [MESSAGES, EVENTS, REALTIME]
    assert all(t.package == "cosim" for t in tables[:3])
    assert tables[0].writer.startswith("the recorder")


def test_each_table_is_documented_once_and_names_the_adapter_that_writes_it():
    tables = documented_tables()
    names = [t.spec.name for t in tables]
    assert len(names) == len(set(names))
    writers = {t.spec.name: t.writer for t in tables}
    assert writers["poses"] == "adapter `poses`"
    assert writers["assignments"] == "adapter `dta`"
    assert writers["links"] == "network backend `links`"


def test_each_table_s_section_has_its_doc_writer_and_a_row_per_column_in_order():
    page = tables_markdown()
    assert re.findall(r"^## `(\w+)`$", page, flags=re.M) == [
        t.spec.name for t in documented_tables()
    ]
    for table in documented_tables():
        block = _block(page, table.spec.name)
        assert block.startswith(f"\n{table.spec.doc}\n")
        assert f"*Written by {table.writer}, package `{table.package}`.*" in block
        rows = re.findall(r"^\| `(\w+)` \|", block, flags=re.M)
        assert rows == list(table.spec.columns), table.spec.name


def test_categorical_and_volatile_columns_are_marked():
    page = tables_markdown()
    messages = _block(page, "messages")
    assert "| `topic` |  | the topic *(category)* |" in messages
    assert "| `t_sent_s` | s | when the message was published (s) |" in messages
    realtime = _block(page, "realtime")
    assert re.search(r"^\| `lateness_ms` \| ms \| .* \*\(volatile\)\* \|$", realtime, flags=re.M)
    navigation = _block(page, "navigation")
    assert re.search(r"^\| `plan_ms` \| ms \| .*\*\(volatile\)\* \|$", navigation, flags=re.M)


def test_every_column_shows_its_declared_unit_or_the_one_its_name_carries():
    page = tables_markdown()
    for table in documented_tables():
        shown = {row[0]: row[1:] for row in rows(_block(page, table.spec.name))}
        for column, meaning in table.spec.columns.items():
            unit = table.spec.units.get(column) or unit_of(column)
            assert shown[column][0] == unit, f"{table.spec.name}.{column}"
            assert shown[column][1].startswith(as_shown(meaning)), f"{table.spec.name}.{column}"


@pytest.mark.parametrize(
    ("table", "column", "unit"),
    [
        ("messages", "bytes", "bytes"),
        ("messages", "t_sent_ns", "ns"),
        ("poses", "v_mps", "m/s"),
        ("assignments", "cost", "m"),
        ("map_quality", "iou", "fraction"),
        ("realtime", "events", "count"),
        ("tasks", "task", "id"),
    ],
)
def test_units_have_a_column_of_their_own(table, column, unit):
    spec = next(t.spec for t in documented_tables() if t.spec.name == table)
    assert column_unit(spec, column) == unit
    assert f"| `{column}` | {unit} | " in _block(tables_markdown(), table)


def test_a_plugin_s_table_doc_and_columns_show_as_written():
    spec = TableSpec(
        "gadget",
        "One row per /<robot>/gadget reading; '*' any",
        {"t_s": "when (s)", "topic": "the /<robot>/gadget topic | its {robot}", "gain": "slope"},
        units={"gain": "1/m"},
    )
    found = [DocumentedTable(spec, "adapter `gadget`", "testkit")]
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(tables_page, "documented_tables", lambda: found)
        page = tables_markdown()
    assert "One row per /<robot>/gadget reading; '*' any" in shown(page)
    assert rows(page) == [
        ["t_s", "s", "when (s)"],
        ["topic", "", "the /<robot>/gadget topic | its {robot}"],
        ["gain", "1/m", "slope"],
    ]


def test_the_page_says_where_tables_are_written_and_that_units_are_in_column_names():
    page = tables_markdown()
    assert page.startswith("# Tables\n")
    assert "`tables/NAME.parquet`" in page and "`result.tables`" in page
    assert "Units are in the column names" in page and "`map` frame" in page
    assert "in a column of their own" in page
