"""A study's folder, and what ``--resume`` trusts in it.

The folder::

    plan.json           the runs, and a fingerprint of what they depend on
    runs/<run_id>/      row.json, summary.json, scenario.toml[, tables/*.parquet]
    results.parquet     one row per run

A run's folder appears at once, complete (:mod:`cosim.studies.writing`). ``--resume``
continues only the study that started the folder: the same runs (seeds, overrides,
duration, tables) of the same resolved scenario and the same files it reads
(:func:`fingerprint`). If ``plan.json`` is lost or garbled, the finished runs are the
evidence: each one's row and ``scenario.toml`` must be what this study would run, and then
the plan is written again. A run whose ``row.json`` cannot be read, or is not the planned
run's (its seed or an override differs), is run again.

Run folders of every earlier format are read (:mod:`cosim.runner.runfolder`): a key
renamed since with its meaning kept (:data:`cosim.scenario.migrations.RENAMES`) is the
same setting, so a finished run whose ``scenario.toml`` differs from today's only by such
names is resumed, with a note; a rename whose model changed too is a changed scenario,
named as such.
"""

from __future__ import annotations

import hashlib
import json
import os
import tomllib
from collections.abc import Iterator
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from cosim.core.errors import ConfigError, ExportError
from cosim.runner.runfolder import folder_format, read_run_scenario
from cosim.scenario import Scenario, load_scenario
from cosim.scenario.fields import show_value
from cosim.scenario.loader import dump_scenario
from cosim.scenario.migrations import migrate, migrate_dotted
from cosim.studies.spec import RunSpec, StudySpec
from cosim.studies.worker import Job, job_scenario, row_cells, run_overrides

PLAN_FILE = "plan.json"
RUNS_DIR = "runs"
ROW_FILE = "row.json"
SCENARIO_FILE = "scenario.toml"
RESULTS_FILE = "results.parquet"
PARTIAL = ".partial"
"""What the folders of runs on their way ended with before format 1 (never read)."""
CHUNK = 1 << 20


@dataclass(frozen=True)
class FolderState:
    """What a study's folder holds, read before anything is written to it.

    Attributes:
        done: the runs finished earlier (skipped on resume).
        notes: one line each for the user: a plan rebuilt, a run to run again and why.
        plan: the ``plan.json`` text to write.
    """

    done: frozenset[str]
    notes: tuple[str, ...]
    plan: str


@dataclass(frozen=True)
class _Compared:
    """A finished run's ``scenario.toml`` against what the study would run now.

    Attributes:
        change: ``""`` the same (its keys read under today's names), the first difference,
            or None when the file cannot be read.
        notes: one line per key of the file read under its new name.
    """

    change: str | None
    notes: tuple[str, ...] = ()


@dataclass(frozen=True)
class _Found:
    """A run folder: its row, or why it cannot be trusted (and the run is run again)."""

    row: dict[str, Any] | None
    problem: str = ""


def job_of(spec: StudySpec, run: RunSpec) -> Job:
    """The job of a study's run."""
    return Job(run.run_id, spec.scenario, run.seed, spec.duration_s, run.overrides, spec.tables)


def _canonical(value: Any) -> str:
    return json.dumps(value, sort_keys=True, default=str)


def _reason(error: OSError) -> str:
    text = error.strerror or str(error)
    return f"{text}: {error.filename}" if error.filename else text


def fingerprint(spec: StudySpec) -> dict[str, Any]:
    """What the runs depend on besides their overrides: the scenario, and files it reads.

    Returns:
        ``scenario``: sha256 of every combination's resolved scenario (so a changed scenario
        file, or changed defaults, show); ``files``: sha256 of each file (or folder) a
        combination names by a path key (an empirical latency CSV, a replayed bag).
    """
    digest = hashlib.sha256()
    files: dict[str, str] = {}
    for combination in spec.combinations():
        overrides = run_overrides(combination, seed=None, duration_s=spec.duration_s)
        scenario = load_scenario(spec.scenario, overrides, override_origin="study")
        digest.update(dump_scenario(scenario).encode())
        for name in _read_files(scenario):
            if name not in files:
                files[name] = _digest_path(Path(name))
    return {"scenario": digest.hexdigest(), "files": files}


def _read_files(scenario: Scenario) -> Iterator[str]:
    for _, section in scenario:
        for f in fields(section):
            value = getattr(section, f.name)
            if f.metadata.get("path") and value:
                yield str(value)


def _digest_path(path: Path) -> str:
    """sha256 of a file's bytes, or of a folder's file names and bytes; "missing" if none."""
    digest = hashlib.sha256()
    try:
        files = sorted(p for p in path.rglob("*") if p.is_file()) if path.is_dir() else [path]
        for file in files:
            digest.update(str(file.relative_to(path) if file != path else "").encode())
            with file.open("rb") as stream:
                while chunk := stream.read(CHUNK):
                    digest.update(chunk)
    except OSError:
        return "missing"
    return digest.hexdigest()


def plan_of(spec: StudySpec) -> dict[str, Any]:
    """The plan written to ``plan.json``: the runs and the fingerprint (JSON values)."""
    plan = {
        "study": spec.name,
        "scenario": spec.scenario,
        "duration_s": spec.duration_s,
        "tables": list(spec.tables),
        "runs": [
            {"run_id": r.run_id, "seed": r.seed, "overrides": r.overrides} for r in spec.runs()
        ],
        "fingerprint": fingerprint(spec),
    }
    loaded: dict[str, Any] = json.loads(_canonical(plan))
    return loaded


def _entries(out: Path) -> list[str]:
    """The names in ``out`` (none if it does not exist yet).

    Raises:
        ExportError: ``out``, or a folder it would be created in, is not a folder.
    """
    if out.exists() and not out.is_dir():
        raise ExportError(f"{out}: is a file; expected a study folder for --out")
    if not out.exists():
        for parent in out.parents:
            if parent.exists():
                if not parent.is_dir():
                    raise ExportError(f"{out}: cannot create the study folder: {parent} is a file")
                break
        return []
    try:
        return os.listdir(out)
    except OSError as error:
        raise ExportError(f"{out}: cannot read the study folder ({_reason(error)})") from None


def read_row(path: Path) -> _Found:
    """A run's ``row.json``, or why it cannot be used."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        return _Found(None, f"has no {ROW_FILE}")
    except (OSError, UnicodeDecodeError) as error:
        return _Found(None, f"{ROW_FILE} cannot be read ({error})")
    try:
        row = json.loads(text)
    except (ValueError, RecursionError):  # RecursionError: nested deeper than Python's stack
        return _Found(None, f"{ROW_FILE} is not valid JSON")
    if (
        not isinstance(row, dict)
        or row.get("run_id") != path.parent.name
        or not isinstance(row.get("status"), str)
    ):
        return _Found(None, f"{ROW_FILE} is not this run's row (run_id, status)")
    return _Found(row)


def _run_folders(out: Path) -> dict[str, _Found]:
    runs = out / RUNS_DIR
    if not runs.is_dir():
        return {}
    try:
        folders = [
            p
            for p in runs.iterdir()
            if p.is_dir() and not p.name.startswith(".") and not p.name.endswith(PARTIAL)
        ]
    except OSError as error:
        raise ExportError(f"{runs}: cannot read the study's runs ({_reason(error)})") from None
    for folder in folders:  # a run of a newer format than this cosim reads stops the resume
        folder_format(folder)
    return {p.name: read_row(p / ROW_FILE) for p in sorted(folders)}


def _read_plan(path: Path) -> tuple[dict[str, Any] | None, str]:
    """The plan, or None and what is wrong with it."""
    try:
        plan = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None, "is missing"
    except (OSError, UnicodeDecodeError, ValueError, RecursionError):
        return None, "is garbled"
    if not isinstance(plan, dict) or not isinstance(plan.get("runs"), list):
        return None, "is garbled"
    return plan, ""


def inspect(spec: StudySpec, out: Path, *, resume: bool) -> FolderState:
    """Read a study's folder and decide what to run; nothing is written.

    Raises:
        ExportError: a non-empty folder without ``resume``; a folder that is not a study's.
        ConfigError: resuming another study, or the same one over a changed scenario.
    """
    plan = plan_of(spec)
    text = json.dumps(plan, indent=1, sort_keys=True)
    if not _entries(out):
        return FolderState(frozenset(), (), text)
    if not resume:
        raise ExportError(
            f"{out}: folder is not empty; use --resume to continue the study "
            "there, or another --out"
        )
    found = _run_folders(out)
    old, problem = _read_plan(out / PLAN_FILE)
    if old is None and not (out / RUNS_DIR).is_dir():
        raise ExportError(
            f"{out}: not a study folder (no {PLAN_FILE}, no {RUNS_DIR}/); use another --out"
        )
    planned = {r.run_id: r for r in spec.runs()}
    notes = [
        f"{out / RUNS_DIR / run_id} {f.problem}: running {run_id} again"
        for run_id, f in found.items()
        if f.problem and run_id in planned
    ]
    finished = {run_id: f.row for run_id, f in found.items() if f.row and f.row["status"] == "ok"}
    if old is not None and (difference := _plan_difference(old, plan)):
        what = f"the study's runs changed ({difference})"
        raise ConfigError(_changed(spec, out, what, finished))
    if old is not None and isinstance(old.get("fingerprint"), dict):
        notes += _check_fingerprint(spec, out, old["fingerprint"], plan["fingerprint"], finished)
        done = set()
        for run_id in (r for r in finished if r in planned):
            if bad := _unlike(finished[run_id], row_cells(job_of(spec, planned[run_id]))):
                notes.append(
                    f"{out / RUNS_DIR / run_id} {ROW_FILE} has {bad}: running {run_id} again"
                )
            else:
                done.add(run_id)
    else:
        done, unverified = _verify(spec, out, finished)
        notes += unverified
        if old is None:
            notes.insert(
                0,
                f"{out / PLAN_FILE} {problem}: rebuilt from the {len(done)} finished runs, "
                "which match this study",
            )
    return FolderState(frozenset(done), tuple(notes), text)


def _changed(spec: StudySpec, out: Path, what: str, finished: dict[str, Any]) -> str:
    """The message for a folder started by another study: what changed, what to do."""
    return (
        f"{spec.path}: {what} since {out} was started; resuming would mix two studies' runs "
        f"in one table: restore it to resume, or run this study with another --out (the "
        f"{len(finished)} finished runs in {out} stay there); deleting {out} to start over "
        "there loses them"
    )


def _plan_difference(old: dict[str, Any], new: dict[str, Any]) -> str:
    """What differs between the plan that started the folder and this study's, or ""."""
    for key in ("scenario", "duration_s", "tables"):
        if key in old and _canonical(old[key]) != _canonical(new[key]):
            return f"{key} {_canonical(old[key])} then, {_canonical(new[key])} now"
    then = {str(r.get("run_id")): _renamed_run(r) for r in old["runs"] if isinstance(r, dict)}
    now = {r["run_id"]: r for r in new["runs"]}
    if set(then) != set(now):
        gone, added = sorted(set(then) - set(now)), sorted(set(now) - set(then))
        example = f"{gone[0]} gone" if gone else f"{added[0]} new"
        return f"{len(then)} runs then, {len(now)} now, e.g. {example}"
    for run_id, run in now.items():
        before = then[run_id]
        if _canonical(before) != _canonical(run):
            return _run_difference(run_id, before, run)
    return ""


def _renamed_run(run: dict[str, Any]) -> dict[str, Any]:
    """A planned run of ``plan.json`` with its overrides' keys under today's names."""
    overrides = run.get("overrides")
    return {**run, "overrides": migrate_dotted(overrides)} if isinstance(overrides, dict) else run


def _run_difference(run_id: str, before: dict[str, Any], now: dict[str, Any]) -> str:
    old, new = before.get("overrides", {}), now["overrides"]
    if not isinstance(old, dict):
        return f"run {run_id}: other overrides"
    for key in sorted({*old, *new}):
        if _canonical(old.get(key)) != _canonical(new.get(key)):
            then, now_ = _canonical(old.get(key)), _canonical(new.get(key))
            return f"run {run_id}: {key} = {then} then, {now_} now"
    return f"run {run_id}: seed {before.get('seed')} then, {now['seed']} now"


def _check_fingerprint(
    spec: StudySpec,
    out: Path,
    old: dict[str, Any],
    new: dict[str, Any],
    finished: dict[str, Any],
) -> list[str]:
    """Refuse a folder whose runs depend on other files or another scenario; notes.

    A fingerprint that differs only because keys were renamed since (every finished run's
    ``scenario.toml`` is today's once its keys are read under their new names) is no
    change: the notes say which keys.

    Raises:
        ConfigError: a file the scenario reads, or the scenario itself, changed.
    """
    files = old.get("files", {})
    for name, digest in new["files"].items():
        if isinstance(files, dict) and files.get(name, digest) != digest:
            what = f"{name} (a file the scenario reads) changed"
            raise ConfigError(_changed(spec, out, what, finished))
    if old.get("scenario") == new["scenario"]:
        return []
    planned = {r.run_id: r for r in spec.runs()}
    compared = {r: _scenario_change(spec, out, planned[r]) for r in finished if r in planned}
    renamed = [note for c in compared.values() for note in c.notes]
    if compared and renamed and all(c.change == "" for c in compared.values()):
        return [
            f"{out / PLAN_FILE}: the scenario differs from the plan's only by keys renamed "
            "since; resuming",
            *dict.fromkeys(renamed),
        ]
    where = next((f" (run {run_id}: {c.change})" for run_id, c in compared.items() if c.change), "")
    raise ConfigError(_changed(spec, out, f"the scenario {spec.scenario} changed{where}", finished))


def _scenario_change(spec: StudySpec, out: Path, run: RunSpec) -> _Compared:
    """How a finished run's ``scenario.toml`` differs from what the study runs now.

    Keys renamed since are read under their new names first: a rename that kept the
    meaning is no difference (it is noted), one whose model changed is the difference.
    """
    folder = out / RUNS_DIR / run.run_id
    try:
        then = (folder / SCENARIO_FILE).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return _Compared(None)
    now = dump_scenario(job_scenario(job_of(spec, run)))
    if then == now:
        return _Compared("")
    try:
        raw = tomllib.loads(then)
        applied = migrate(raw, str(folder / SCENARIO_FILE)).applied
        old = read_run_scenario(folder)
    except (tomllib.TOMLDecodeError, ConfigError, ExportError):
        return _Compared(_first_difference(then, now))
    for rename in applied:
        if not rename.same_meaning:
            section, _, key = rename.old.partition(".")
            value = show_value(raw[section][key])
            return _Compared(
                f"{rename.old} = {value} then, renamed {rename.new} in {rename.commit}: "
                f"{rename.change}"
            )
    migrated = dump_scenario(old)
    if migrated.split("\n", 1)[1:] == now.split("\n", 1)[1:]:  # but the source line
        return _Compared("", old.notes)
    return _Compared(_first_difference(migrated, now))


def _first_difference(then: str, now: str) -> str:
    """```line` then, `line` now`` for the first line that differs, or the line counts."""
    old_lines, new_lines = then.splitlines(), now.splitlines()
    for a, b in zip(old_lines[1:], new_lines[1:], strict=False):
        if a != b:
            return f"`{a}` then, `{b}` now"
    return f"{len(old_lines)} lines then, {len(new_lines)} now"


def _verify(
    spec: StudySpec, out: Path, finished: dict[str, dict[str, Any]]
) -> tuple[set[str], list[str]]:
    """Finished runs that are this study's runs (row and resolved scenario), with notes.

    Raises:
        ConfigError: a finished run is not one of this study's, or ran other settings.
    """
    planned = {r.run_id: r for r in spec.runs()}
    done, notes = set(), []
    for run_id, row in finished.items():
        run = planned.get(run_id)
        if run is None:
            what = f"finished run {run_id} is not one of this study's runs"
            raise ConfigError(_changed(spec, out, what, finished))
        if bad := _unlike(row, row_cells(job_of(spec, run))):
            raise ConfigError(_changed(spec, out, f"finished run {run_id} has {bad}", finished))
        compared = _scenario_change(spec, out, run)
        change = compared.change
        if change is None:
            notes.append(
                f"{out / RUNS_DIR / run_id} has no readable {SCENARIO_FILE} to tell which "
                f"scenario it ran: running {run_id} again"
            )
            continue
        if change:
            what = f"the scenario of finished run {run_id} changed ({change})"
            raise ConfigError(_changed(spec, out, what, finished))
        notes += [note for note in compared.notes if note not in notes]
        done.add(run_id)
    return done, notes


def _unlike(row: dict[str, Any], expected: dict[str, Any]) -> str:
    """``key = value, the study other`` for the first cell of a row unlike the run's, or "".

    The row's keys are read under today's names (renamed keys of the same meaning).
    """
    row = migrate_dotted(row)
    for key, value in expected.items():
        if _canonical(row.get(key)) != _canonical(value):
            return f"{key} = {_canonical(row.get(key))}, the study {_canonical(value)}"
    return ""
