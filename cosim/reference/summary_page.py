"""The ``summary.json`` reference: every key a run can write, its unit, meaning and writer."""

from __future__ import annotations

from collections.abc import Mapping

from adapters.mapping.bagmap import SUMMARY_KEYS as MAP_SUMMARY_KEYS
from cosim.core.summary import SummaryKey
from cosim.reference.escaping import cell, code, text
from cosim.runner.summary_keys import DeclaredSummary, declared_summaries


def keys_table(keys: Mapping[str, SummaryKey]) -> list[str]:
    """A table of summary keys: key, unit, meaning (with when it is written, if not always)."""
    lines = ["| key | unit | meaning |", "|---|---|---|"]
    for key, declared in keys.items():
        marks = [f"only: {declared.when}"] if declared.when else []
        marks += ["volatile"] if declared.volatile else []
        note = f" *({cell('; '.join(marks))})*" if marks else ""
        lines.append(f"| {code(key)} | {cell(declared.unit)} | {cell(declared.doc)}{note} |")
    return lines


def writer_markdown(summary: DeclaredSummary) -> list[str]:
    """One writer's heading and table of keys."""
    heading = summary.writer[0].upper() + summary.writer[1:]
    return [
        f"## {text(heading)}",
        "",
        f"*Package {code(summary.package)}.*",
        "",
        *keys_table(summary.keys),
        "",
    ]


def summary_markdown() -> str:
    """The whole ``summary.json`` reference page."""
    lines = [
        "# summary.json",
        "",
        "A run writes `summary.json` into its folder; `cosim.run` returns the same entries "
        "as `result.summary`, and a study's `results.parquet` has a column for each. Its "
        "values are flat (a number, a string, true/false or null) but for the records "
        "`failure` and `plugins`. Every key is listed below with its unit in a column of "
        "its own (a value without one says what it is instead: a `count`, a `fraction` of "
        "0..1, a `ratio`, `text`, ...), what it means, and what writes it: the runner "
        "itself, or an adapter, assignment protocol, pose source or network backend, "
        "each in the section of its own name. Keys marked *only* are written in those runs "
        "alone; *volatile* ones are machine or wall-clock figures, the only values that "
        "differ between two runs of the same scenario and seed.",
        "",
        "Each key is declared beside the code that writes it: in a `summary_keys` class "
        "attribute of its writer, a mapping of key to `cosim.core.summary.SummaryKey(unit, "
        "doc)`, and the runner's own in `cosim/runner/summary_keys.py`. A plugin declares "
        "its keys the same way, and they appear here once its package is installed; "
        "`cosim check-plugin` warns about a key a plugin's run writes that nothing "
        "declares. This page is generated from the declarations "
        "(`cosim/reference/summary_page.py`).",
        "",
    ]
    for summary in declared_summaries():
        lines += writer_markdown(summary)
    lines += [
        f"## {code('cosim map')}",
        "",
        "`cosim map BAG --out DIR` writes a `summary.json` of its own, about the recording "
        "it mapped (`adapters/mapping/bagmap.py`):",
        "",
        *keys_table(MAP_SUMMARY_KEYS),
        "",
    ]
    return "\n".join(lines) + "\n"
