"""What a run folder is: its format, the mark that proves cosim wrote it, reading any format.

A run folder (``cosim run --out``, a study's ``runs/<run_id>/``) says which format it has in
``summary.json``: ``"format": 1`` (:data:`RUN_FORMAT`). The formats:

- 0 (no ``"format"``; every folder written before formats were numbered): keys of
  ``scenario.toml`` may have older names (:data:`cosim.scenario.migrations.RENAMES`), and no
  file marks the folder.
- 1: ``summary.json`` begins with ``"format": 1``; the file :data:`MARKER` marks the folder
  as cosim's (written before anything else), and the results are written inside the folder
  (``.cosim-partial-*``, :mod:`cosim.runner.staging`) before they take their places.

Whatever reads a run (figures, ``cosim bag``, ``cosim map``, studies) reads every format up
to :data:`RUN_FORMAT` (:func:`read_run_scenario`); a newer one is refused in one line. What
replaces files in a folder (``--force``) does so only in a folder :func:`is_cosim_folder`
proves is cosim's.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from cosim.core.errors import ExportError
from cosim.recording.bag import BAG_DIR
from cosim.scenario import Scenario, load_scenario

RUN_FORMAT = 1
"""The format of the run folders this cosim writes (``summary.json`` ``"format"``)."""
FORMAT_KEY = "format"
"""The key of ``summary.json`` that holds it (0 where it is missing)."""
MARKER = ".cosim-run"
"""The file that marks a folder as written by cosim (its first line: ``cosim KIND folder``)."""
SUMMARY_FILE = "summary.json"
SCENARIO_FILE = "scenario.toml"
LEGACY_KEYS: dict[str, tuple[str, ...]] = {
    "run": ("scenario", "seed", "version", "sim_time_s"),
    "map": ("scans", "map_updates", "recording_s"),
}
"""Keys the ``summary.json`` of a folder of format 0 has, by kind: the proof an unmarked
folder was written by cosim before folders were marked."""


def mark(folder: Path, kind: str = "run") -> Path:
    """Write :data:`MARKER` into ``folder`` (a ``kind`` folder: ``run``, ``map``); the file.

    Raises:
        OSError: the folder cannot be written.
    """
    path = folder / MARKER
    path.write_text(
        f"cosim {kind} folder, format {RUN_FORMAT}\n"
        "cosim wrote this folder: `--force` may replace the files cosim writes here, never "
        "another; without this file cosim replaces nothing here.\n",
        encoding="utf-8",
    )
    return path


def _read_summary(folder: Path) -> dict[str, Any] | None:
    try:
        loaded = json.loads((folder / SUMMARY_FILE).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError, RecursionError):
        return None
    return loaded if isinstance(loaded, dict) else None


def _marked(folder: Path, kind: str) -> bool:
    try:
        with (folder / MARKER).open(encoding="utf-8") as marker:
            first = marker.readline()
    except (OSError, UnicodeDecodeError):
        return False
    return first.startswith(f"cosim {kind} folder")


def is_cosim_folder(folder: Path, kind: str = "run") -> bool:
    """Whether cosim wrote ``folder`` as a ``kind`` folder: it is marked, or of format 0.

    A folder of format 0 (written before folders were marked) is recognised by its
    ``summary.json`` (:data:`LEGACY_KEYS`, no ``"format"``) and, for a run, its
    ``scenario.toml``. A folder of a later format without its mark is not cosim's any more:
    the mark was removed to keep cosim from replacing anything there.
    """
    if _marked(folder, kind):
        return True
    summary = _read_summary(folder)
    if summary is None or FORMAT_KEY in summary:
        return False
    if not all(key in summary for key in LEGACY_KEYS[kind]):
        return False
    return kind != "run" or (folder / SCENARIO_FILE).is_file()


def folder_format(folder: Path) -> int:
    """The format of a run folder: its ``summary.json``'s ``"format"``, 0 when it has none.

    A folder without a readable ``summary.json`` (a run killed outright) counts as 0: what
    reads it needs its tables and ``scenario.toml`` only.

    Raises:
        ExportError: the format is not a whole number, or is newer than this cosim reads.
    """
    summary = _read_summary(folder)
    if summary is None or FORMAT_KEY not in summary:
        return 0
    found = summary[FORMAT_KEY]
    if isinstance(found, bool) or not isinstance(found, int) or found < 0:
        raise ExportError(
            f"{folder / SUMMARY_FILE}: {FORMAT_KEY} = {found!r}: expected the format of a run "
            f"folder, a whole number from 0 to {RUN_FORMAT}"
        )
    if found > RUN_FORMAT:
        raise ExportError(
            f"{folder}: a run folder of format {found}, written by a newer cosim; this one "
            f"reads formats 0 to {RUN_FORMAT} (upgrade cosim to read it)"
        )
    return found


def read_run_scenario(folder: Path) -> Scenario:
    """A finished run's scenario, of any format, to read its results (figures, reports).

    Renamed keys are read under their new names, and sections and names of plugins not
    installed any more are carried (``load_scenario(..., reading=True)``); each is said in
    the scenario's ``notes``. The result is for reading: it cannot be run.

    Raises:
        ExportError: ``folder`` has no ``scenario.toml``, or is of a newer format.
        ConfigError: ``scenario.toml`` is invalid (naming the file, the key, the value).
    """
    source = folder / SCENARIO_FILE
    if not source.is_file():
        raise ExportError(f"{folder}: no {SCENARIO_FILE}; expected a run folder (cosim run --out)")
    folder_format(folder)
    return load_scenario(source, reading=True)


def bag_of(path: Path) -> Path:
    """The bag ``path`` names: itself, or a run folder's ``bag/`` (a run of any format).

    Raises:
        ExportError: a run folder of a newer format than this cosim reads.
    """
    if path.is_dir() and (path / SCENARIO_FILE).is_file() and (path / BAG_DIR).is_dir():
        folder_format(path)
        return path / BAG_DIR
    return path


__all__ = [
    "FORMAT_KEY",
    "MARKER",
    "RUN_FORMAT",
    "bag_of",
    "folder_format",
    "is_cosim_folder",
    "mark",
    "read_run_scenario",
]
