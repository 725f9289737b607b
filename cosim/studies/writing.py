"""Writing a study's folder: the plan, each run's folder, ``results.parquet``.

Each run's folder appears at once, complete: it is written whole into a staging folder
beside it in ``runs/`` (``runs/.cosim-partial-XXXXXXXX``, :mod:`cosim.runner.staging`), then
renamed. A file is written beside itself under a name of its own, then renamed, so a reader
sees the old file or the new one and no file of the user's is overwritten on the way. Only
what cosim made is ever removed: its staging folders, and a run's earlier folder (one with a
``row.json``, which only a study writes) when the run is run again.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import pandas as pd

from cosim.core.errors import ExportError
from cosim.runner.faults import FAILURE_FILE
from cosim.runner.runfolder import FORMAT_KEY, RUN_FORMAT
from cosim.runner.staging import discard, is_staging, reason, replace_file, stage_in
from cosim.studies.fingerprint import PLAN_FILE, RUNS_DIR, SCENARIO_FILE
from cosim.studies.folder import RESULTS_FILE, ROW_FILE, FolderState, read_row
from cosim.studies.spec import StudySpec
from cosim.studies.worker import Outcome


def _reason(error: OSError) -> str:
    text = reason(error)
    return f"{text}: {error.filename}" if error.filename else text


def _write_text(path: Path, text: str) -> None:
    """Write ``text`` beside ``path``, then rename: a reader sees the old or the new file."""
    replace_file(path, lambda beside: beside.write_text(text, encoding="utf-8"))


def prepare(out: Path, state: FolderState) -> None:
    """Create the folder, write the plan, and clear what runs cut short left on their way.

    Raises:
        ExportError: the folder cannot be written (read-only, full, not a folder).
    """
    try:
        (out / RUNS_DIR).mkdir(parents=True, exist_ok=True)
        _write_text(out / PLAN_FILE, state.plan)
        for stale in (out / RUNS_DIR).iterdir():
            if is_staging(stale) and stale.is_dir():
                discard(stale)
    except OSError as error:
        raise ExportError(f"{out}: cannot write the study folder ({_reason(error)})") from None


def write_run(out: Path, outcome: Outcome) -> None:
    """Write a run's folder: complete, or not at all.

    An earlier folder of the run (an attempt that failed, a garbled row) is replaced only
    when a study wrote it (it has a ``row.json``); any other folder in its place is named
    and left alone.

    Raises:
        ExportError: the folder cannot be written (read-only, full), or a folder the study
            did not write is in the way.
    """
    run_id = outcome.row["run_id"]
    final = out / RUNS_DIR / run_id
    stage = None
    try:
        (out / RUNS_DIR).mkdir(parents=True, exist_ok=True)
        stage = stage_in(out / RUNS_DIR)
        _write_run_files(stage, outcome)
        if final.exists() or final.is_symlink():
            _replace_earlier(final, stage)
        else:
            os.replace(stage, final)
    except OSError as error:
        discard(stage)  # free what it took
        raise ExportError(f"{out}: cannot write run {run_id} ({_reason(error)})") from None
    except ExportError:
        discard(stage)
        raise


def _replace_earlier(final: Path, stage: Path) -> None:
    """Put ``stage`` in the place of a run's earlier folder, which goes only once it is out."""
    if final.is_symlink() or not final.is_dir() or not (final / ROW_FILE).is_file():
        raise ExportError(
            f"{final}: holds no {ROW_FILE}, so no study wrote it, where this run's folder "
            "goes; move it away, then continue with --resume"
        )
    earlier = stage.with_name(stage.name + ".earlier")
    os.replace(final, earlier)
    os.replace(stage, final)
    discard(earlier)


def _write_run_files(folder: Path, outcome: Outcome) -> None:
    if outcome.scenario_toml:
        (folder / SCENARIO_FILE).write_text(outcome.scenario_toml)
    if outcome.summary:
        summary = {FORMAT_KEY: RUN_FORMAT, **outcome.summary}
        (folder / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    if outcome.tables:
        (folder / "tables").mkdir()
        for name, data in outcome.tables.items():
            (folder / "tables" / f"{name}.parquet").write_bytes(data)
    if outcome.failure:
        (folder / FAILURE_FILE).write_text(outcome.failure)
    (folder / ROW_FILE).write_text(json.dumps(outcome.row, indent=1, default=str) + "\n")


def finished_rows(spec: StudySpec, out: Path) -> list[dict[str, Any]]:
    """The readable rows of the study's runs, in plan order."""
    rows = []
    for run in spec.runs():
        found = read_row(out / RUNS_DIR / run.run_id / ROW_FILE)
        if found.row is not None:
            rows.append(found.row)
    return rows


def collect(spec: StudySpec, out: Path) -> pd.DataFrame:
    """Assemble ``results.parquet`` from the run folders, in plan order.

    Raises:
        ExportError: the results cannot be written (read-only, full).
    """
    frame = pd.DataFrame(finished_rows(spec, out))
    if len(frame):
        write_results(frame, out / RESULTS_FILE)
    return frame


def write_results(frame: pd.DataFrame, path: Path) -> None:
    """Write a study's results beside ``path``, then rename: a full disk keeps the old file.

    A column whose runs hold values of different kinds (a grid over ``"auto"`` and
    ``false``) is written as text, each value as TOML spells it (``auto``, ``false``): a
    Parquet column has one type.

    Raises:
        ExportError: the results cannot be written (read-only, full).
    """
    frame = uniform_columns(frame)
    try:
        replace_file(path, lambda beside: frame.to_parquet(beside, index=False))
    except OSError as error:
        raise ExportError(f"{path}: cannot write the results ({_reason(error)})") from None


def uniform_columns(frame: pd.DataFrame) -> pd.DataFrame:
    """``frame`` with each column of values of several kinds turned into their TOML text.

    Missing values stay missing; a column of one kind is left as it is.
    """
    mixed = {}
    for name in frame.columns:
        column = frame[name]
        if column.dtype != object:
            continue
        kinds = {type(v) for v in column.dropna()}
        if len(kinds) > 1:
            mixed[name] = column.map(_toml_text, na_action="ignore")
    return frame.assign(**mixed) if mixed else frame


def _toml_text(value: Any) -> str:
    """A value as a scenario file spells it: ``true``, ``0.5``, a string as it is."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return value if isinstance(value, str) else json.dumps(value, default=str)
