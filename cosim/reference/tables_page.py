"""The table reference: every table a run can write, with what each column means."""

from __future__ import annotations

from dataclasses import dataclass

from cosim.core.recorder import EVENTS, MESSAGES
from cosim.core.registry import installed_groups
from cosim.core.table import TableSpec
from cosim.reference.escaping import cell, code, text
from cosim.runner.lateness import REALTIME
from cosim.scenario.fields import unit_of


@dataclass(frozen=True)
class DocumentedTable:
    """A table and who writes it.

    Attributes:
        spec: the table's declaration.
        writer: what writes it (``the recorder``, ``adapter navigation``, ...).
        package: the package that registers the writer.
    """

    spec: TableSpec
    writer: str
    package: str


def documented_tables() -> list[DocumentedTable]:
    """The recorder's tables, the real-time table, and every loadable entry's ``tables``.

    Entries of every registry may write tables (an adapter, a network backend, ...); each
    declares them in a ``tables`` class attribute.
    """
    found = [
        DocumentedTable(
            MESSAGES, "the recorder (every run, unless record.messages = false)", "cosim"
        ),
        DocumentedTable(EVENTS, "the recorder (every run)", "cosim"),
        DocumentedTable(REALTIME, "the runner (real-time runs)", "cosim"),
    ]
    for group in installed_groups():
        registry = group.installed()
        for name, entry in registry.load_all().items():
            specs = getattr(entry, "tables", ())
            if not isinstance(specs, tuple):  # a settings section's key named "tables"
                continue
            for spec in (s for s in specs if isinstance(s, TableSpec)):
                writer = f"{group.words} `{name}`"
                found.append(DocumentedTable(spec, writer, registry.package(name)))
    return found


def column_unit(spec: TableSpec, column: str) -> str:
    """A column's unit: declared in its spec's ``units``, else the one its name carries."""
    return spec.units.get(column) or unit_of(column)


def tables_markdown() -> str:
    """The whole table reference page."""
    lines = [
        "# Tables",
        "",
        "A run writes its tables into `tables/NAME.parquet` of its folder (unless "
        "`record.tables = false`); `cosim.run` returns them as pandas DataFrames in "
        "`result.tables`. Units are in the column names (`t_s`, `x_m`, `yaw_rad`, "
        "`bytes`), and in a column of their own below (a count, a fraction or an id where "
        "a number has none); positions are in the `map` frame. Columns marked *category* "
        "hold repeated strings (pandas `category`); *volatile* ones are wall-clock "
        "figures, the only values that differ between two runs of the same scenario and "
        "seed.",
        "",
        "This page is generated from the tables' declarations (`TableSpec`, "
        "`cosim/reference/tables_page.py`).",
        "",
    ]
    for table in documented_tables():
        spec = table.spec
        lines += [
            f"## {code(spec.name)}",
            "",
            text(spec.doc),
            "",
            f"*Written by {text(table.writer)}, package {code(table.package)}.*",
            "",
            "| column | unit | meaning |",
            "|---|---|---|",
        ]
        for column, meaning in spec.columns.items():
            marks = [m for m, on in (("category", column in spec.categorical),
                                     ("volatile", column in spec.volatile)) if on]  # fmt: skip
            note = f" *({', '.join(marks)})*" if marks else ""
            unit = cell(column_unit(spec, column))
            lines.append(f"| {code(column)} | {unit} | {cell(meaning)}{note} |")
        lines.append("")
    return "\n".join(lines) + "\n"
