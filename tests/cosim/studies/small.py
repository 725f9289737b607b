"""Tiny studies for the tests of ``cosim.studies``: two robots in a small hall, a second each."""

from __future__ import annotations

import json
from pathlib import Path

from cosim.runner.staging import STAGING_PREFIX

SCENARIO = """\
[scenario]
name = "small"
duration_s = 1.0

[world]
size_m = [12.0, 12.0]
shelf_count = 2

[robots]
count = 2

[record]
messages = false
"""
"""A scenario file a study can name: runs of 1 simulated second take a few milliseconds."""

STUDY = """\
[study]
name = "{name}"
scenario = "{scenario}"
seeds = {seeds}
{duration}"""
OVERRIDES = """
[overrides]
"world.size_m" = [12.0, 12.0]
"world.shelf_count" = 2
"robots.count" = 2
"record.messages" = false
"""
"""What makes the preset small (a scenario file is small already)."""


def small_study(
    folder: Path,
    *,
    name: str = "small",
    seeds: str = "[1, 2, 3]",
    duration_s: float | None = 1.0,
    scenario: str = "warehouse-random",
    extra: str = "",
    file: str = "study.toml",
) -> Path:
    """Write a study file of a few tiny runs into ``folder``; its path.

    Args:
        folder: where the study file goes.
        name: ``[study] name`` (written as is, between double quotes).
        seeds: ``[study] seeds`` as TOML text.
        duration_s: ``[study] duration_s`` (s), or None to leave it out.
        scenario: ``[study] scenario``: a preset (made small by ``[overrides]``), or a file
            name next to the study (taken as it is).
        extra: TOML text appended (more sections).
        file: the study file's name.
    """
    duration = "" if duration_s is None else f"duration_s = {duration_s}\n"
    text = STUDY.format(name=name, scenario=scenario, seeds=seeds, duration=duration)
    # a scenario file of ours is small already, and a test may edit what it sets
    text += "\n" if scenario.endswith(".toml") else OVERRIDES
    path = folder / file
    path.write_text(text + extra, encoding="utf-8")
    return path


def scenario_file(folder: Path, name: str = "scenario.toml") -> Path:
    """Write :data:`SCENARIO` into ``folder``; its path."""
    path = folder / name
    path.write_text(SCENARIO, encoding="utf-8")
    return path


def finished(out: Path) -> list[str]:
    """The run folders of a study folder that are complete (not a run's on its way), sorted."""
    runs = out / "runs"
    if not runs.is_dir():
        return []
    return sorted(p.name for p in runs.iterdir() if p.is_dir() and not on_its_way(p))


def on_its_way(path: Path) -> bool:
    """Whether ``path`` is a run folder being written (``runs/.cosim-partial-*``)."""
    return path.name.startswith(STAGING_PREFIX)


def row_times(out: Path) -> dict[str, int]:
    """Each finished run's ``row.json`` modification time (ns), by run id."""
    return {
        run_id: (out / "runs" / run_id / "row.json").stat().st_mtime_ns for run_id in finished(out)
    }


def ok_row(path: Path) -> bool:
    """Whether ``path`` is a readable ``row.json`` of a run that finished."""
    try:
        row = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(row, dict) and row.get("status") == "ok"
