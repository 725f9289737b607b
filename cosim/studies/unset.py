"""Runs that leave a key the report groups by unset: grouped under the value they used.

A study whose ``[[cases]]`` set a key in some cases only (``"navigation.controller"`` in the
cases that change it) has no value of it in the other runs' rows. Grouped by that key (the
report's ``x``, ``hue`` or ``facet``), those runs would vanish from every figure, its
``.csv`` and the report's tables. Each such run ran with the value of its resolved scenario
(``runs/<run_id>/scenario.toml``), so that is the value it is grouped under, and the value
``results.parquet`` then holds for it: a default and the same value set explicitly are the
same setting and share a panel. A run still without a value (its ``scenario.toml`` lost, or
the key is a metric it does not report) is left out, and a note names it.
"""

from __future__ import annotations

import json
import tomllib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from cosim.core.errors import ConfigError
from cosim.scenario.migrations import migrate
from cosim.studies.analysis import RESULTS_FILE, load_results
from cosim.studies.fingerprint import RUNS_DIR, SCENARIO_FILE
from cosim.studies.writing import write_results

NAMED = 10
"""Runs a note names; the others are counted."""


def fill_unset(study_dir: Path, keys: Sequence[str | None]) -> list[str]:
    """Give the ok runs without a value of a dotted key in ``keys`` the value they used.

    ``results.parquet`` is rewritten when a value was filled in.

    Args:
        study_dir: the study's folder.
        keys: the columns the report groups by (x, hue, facet; None for those it lacks).

    Returns:
        One note per key some ok runs still have no value of (they are left out of the
        figures grouped by it), naming them.

    Raises:
        ExportError: the results cannot be read or written.
    """
    results = load_results(study_dir)
    ok = results["status"] == "ok"
    scenarios: dict[str, dict[str, Any] | None] = {}
    notes, changed = [], False
    for key in dict.fromkeys(k for k in keys if k is not None and k in results.columns):
        unset = ok & results[key].isna()
        if "." in key and unset.any():
            section, _, name = key.partition(".")
            values = results[key].astype(object)
            for index in results.index[unset]:
                run_id = str(results.at[index, "run_id"])
                if run_id not in scenarios:
                    scenarios[run_id] = _scenario(Path(study_dir), run_id)
                found = _value(scenarios[run_id], section, name)
                if found is not None:
                    values.at[index] = _cell(found)
                    changed = True
            results[key] = values.infer_objects()
            unset = ok & results[key].isna()
        if unset.any():
            notes.append(_note(key, results.loc[unset, "run_id"].astype(str).tolist()))
    if changed:
        write_results(results, Path(study_dir) / RESULTS_FILE)
    return notes


def _scenario(study_dir: Path, run_id: str) -> dict[str, Any] | None:
    """A run's resolved scenario as TOML tables, or None if it cannot be read.

    Keys renamed since the run are under their new names (a run of any earlier format
    is grouped under the value it ran with: :func:`cosim.scenario.migrations.migrate`).
    """
    path = study_dir / RUNS_DIR / run_id / SCENARIO_FILE
    try:
        return migrate(tomllib.loads(path.read_text(encoding="utf-8")), str(path)).tables
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError, ConfigError):
        return None


def _value(scenario: dict[str, Any] | None, section: str, key: str) -> Any:
    table = (scenario or {}).get(section)
    return table.get(key) if isinstance(table, dict) else None


def _cell(value: Any) -> Any:
    """A list as its JSON text, as a run's row holds an override (``"[12.0, 12.0]"``)."""
    return json.dumps(value) if isinstance(value, list) else value


def _note(key: str, run_ids: list[str]) -> str:
    named = ", ".join(f"`{r}`" for r in run_ids[:NAMED])
    more = f" and {len(run_ids) - NAMED} more" if len(run_ids) > NAMED else ""
    runs = "run" if len(run_ids) == 1 else "runs"
    why = (
        "neither its row nor its scenario.toml has a value of it"
        if "." in key
        else "it reports no value of it"
    )
    return (
        f"{len(run_ids)} ok {runs} left out of the figures grouped by `{key}` ({why}; the "
        f"tables show them under nan): {named}{more}."
    )
