"""What a study's runs depend on besides their overrides, and how ``--resume`` checks it.

``plan.json`` keeps a fingerprint (:func:`fingerprint`): a digest of every combination's
resolved scenario, a digest of each file a combination reads (an empirical latency CSV, a
replayed bag), and the sections of the resolved scenario with the package that registers
each. Resuming over a folder whose fingerprint differs is refused in one line saying what
changed (a file, the first line of a finished run's ``scenario.toml`` that differs), unless
the only change is a section a newly installed package added that changes no run
(:mod:`cosim.studies.gained`), or keys renamed since with their meaning kept
(:data:`cosim.scenario.migrations.RENAMES`): then the study resumes, and says so.
"""

from __future__ import annotations

import hashlib
import tomllib
from collections.abc import Collection, Iterator
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from cosim.core.errors import ConfigError, ExportError
from cosim.runner.runfolder import read_run_scenario
from cosim.scenario import Scenario, load_scenario
from cosim.scenario.fields import show_value
from cosim.scenario.loader import dump_scenario
from cosim.scenario.migrations import migrate
from cosim.studies.gained import (
    dump_of,
    gained,
    gained_line,
    refuse_gained,
    refuse_lost,
    section_owners,
    toml_sections,
)
from cosim.studies.spec import RunSpec, StudySpec
from cosim.studies.worker import Job, job_scenario, run_overrides

PLAN_FILE = "plan.json"
RUNS_DIR = "runs"
SCENARIO_FILE = "scenario.toml"
CHUNK = 1 << 20


@dataclass(frozen=True)
class Compared:
    """A finished run's ``scenario.toml`` against what the study would run now.

    Attributes:
        change: ``""`` the same (its keys read under today's names), the first difference,
            or None when the file cannot be read.
        notes: one line per key of the file read under its new name.
    """

    change: str | None
    notes: tuple[str, ...] = ()


def job_of(spec: StudySpec, run: RunSpec) -> Job:
    """The job of a study's run."""
    return Job(run.run_id, spec.scenario, run.seed, spec.duration_s, run.overrides, spec.tables)


def combinations(spec: StudySpec) -> Iterator[tuple[str, Scenario]]:
    """Each combination's resolved scenario (seed aside), labelled by its runs."""
    for k, combination in enumerate(spec.combinations()):
        overrides = run_overrides(combination, seed=None, duration_s=spec.duration_s)
        scenario = load_scenario(spec.scenario, overrides, override_origin="study")
        yield f"runs {k:04d}_s*", scenario


def fingerprint(spec: StudySpec, keep: Collection[str] | None = None) -> dict[str, Any]:
    """What the runs depend on besides their overrides: the scenario, and files it reads.

    Args:
        spec: the study.
        keep: digest only these sections of each resolved scenario (those a folder was
            started with), or all when None.

    Returns:
        ``scenario``: sha256 of every combination's resolved scenario (so a changed scenario
        file, or changed defaults, show); ``files``: sha256 of each file (or folder) a
        combination names by a path key (an empirical latency CSV, a replayed bag);
        ``sections``: each section of the resolved scenario, with its package and version.
    """
    digest = hashlib.sha256()
    files: dict[str, str] = {}
    sections: dict[str, str] = {}
    for _, scenario in combinations(spec):
        sections = sections or section_owners(scenario)
        text = dump_scenario(scenario) if keep is None else dump_of(scenario, keep)
        digest.update(text.encode())
        for name in _read_files(scenario):
            if name not in files:
                files[name] = _digest_path(Path(name))
    return {"scenario": digest.hexdigest(), "files": files, "sections": sections}


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


def changed(spec: StudySpec, out: Path, what: str, finished: dict[str, Any]) -> str:
    """The message for a folder started by another study: what changed, what to do."""
    return (
        f"{spec.path}: {what} since {out} was started; resuming would mix two studies' runs "
        f"in one table: restore it to resume, or run this study with another --out (the "
        f"{len(finished)} finished runs in {out} stay there); deleting {out} to start over "
        "there loses them"
    )


def check_fingerprint(
    spec: StudySpec,
    out: Path,
    old: dict[str, Any],
    new: dict[str, Any],
    finished: dict[str, Any],
) -> list[str]:
    """Refuse a folder whose runs depended on other files or another scenario; notes.

    Returns:
        Notes when the scenario differs only by sections a newly installed package added
        that change no run, or only by keys renamed since with their meaning kept (every
        finished run's ``scenario.toml`` is today's once its keys are read under their new
        names): the study resumes. Empty when nothing differs.

    Raises:
        ConfigError: naming the file, the first line of the scenario that changed, or the
            section and package that came or went.
    """
    files = old.get("files", {})
    for name, digest in new["files"].items():
        if isinstance(files, dict) and files.get(name, digest) != digest:
            what = f"{name} (a file the scenario reads) changed"
            raise ConfigError(changed(spec, out, what, finished))
    if old.get("scenario") == new["scenario"]:
        return []
    note = _sections_only(spec, out, old, new, finished)
    if note is not None:
        return [note]
    planned = {r.run_id: r for r in spec.runs()}
    compared = {r: scenario_change(spec, out, planned[r]) for r in finished if r in planned}
    renamed = [note for c in compared.values() for note in c.notes]
    if compared and renamed and all(c.change == "" for c in compared.values()):
        return [
            f"{out / PLAN_FILE}: the scenario differs from the plan's only by keys renamed "
            "since; resuming",
            *dict.fromkeys(renamed),
        ]
    where = next((f" (run {run_id}: {c.change})" for run_id, c in compared.items() if c.change), "")
    raise ConfigError(changed(spec, out, f"the scenario {spec.scenario} changed{where}", finished))


def _sections_then(old: dict[str, Any], out: Path, finished: dict[str, Any]) -> dict[str, str]:
    """The sections the folder was started with: from its plan, or a finished run's file."""
    kept = old.get("sections")
    if isinstance(kept, dict) and all(isinstance(v, str) for v in kept.values()):
        return dict(kept)
    for run_id in finished:
        try:
            text = (out / RUNS_DIR / run_id / SCENARIO_FILE).read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            continue
        names = toml_sections(text)
        if names:
            return dict.fromkeys(names, "")
    return {}


def _sections_only(
    spec: StudySpec,
    out: Path,
    old: dict[str, Any],
    new: dict[str, Any],
    finished: dict[str, Any],
) -> str | None:
    """The note when only sections of a newly installed package differ; None if more does.

    Raises:
        ConfigError: a section is gone, or a new one changes the runs.
    """
    then = _sections_then(old, out, finished)
    now: dict[str, str] = new["sections"]
    if not then or set(then) == set(now):
        return None
    if lost := [name for name in then if name not in now]:
        owners = {name: then[name] or "unknown" for name in lost}
        raise refuse_lost(lost, owners, str(spec.path), str(out), len(finished))
    if fingerprint(spec, keep=then)["scenario"] != old.get("scenario"):
        return None  # more changed than the sections: the first change is said
    found = gained(combinations(spec), then, now)
    if found.why:
        raise refuse_gained(found, str(spec.path), str(out), len(finished))
    return gained_line(found, str(out), len(finished))


def scenario_change(spec: StudySpec, out: Path, run: RunSpec) -> Compared:
    """How a finished run's ``scenario.toml`` differs from what the study runs now.

    Sections the run's file does not have (a package installed since) are left out of the
    comparison: :func:`check_fingerprint` and :func:`gained_since` judge them. Keys renamed
    since are read under their new names first: a rename that kept the meaning is no
    difference (it is noted), one whose model changed is the difference.
    """
    folder = out / RUNS_DIR / run.run_id
    try:
        then = (folder / SCENARIO_FILE).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return Compared(None)
    scenario = job_scenario(job_of(spec, run))
    sections = toml_sections(then)
    now = dump_scenario(scenario) if sections is None else dump_of(scenario, sections)
    if then == now:
        return Compared("")
    try:
        raw = tomllib.loads(then)
        applied = migrate(raw, str(folder / SCENARIO_FILE)).applied
        old = read_run_scenario(folder)
    except (tomllib.TOMLDecodeError, ConfigError, ExportError):
        return Compared(_first_difference(then, now))
    for rename in applied:
        if not rename.same_meaning:
            section, _, key = rename.old.partition(".")
            value = show_value(raw[section][key])
            return Compared(
                f"{rename.old} = {value} then, renamed {rename.new} in {rename.commit}: "
                f"{rename.change}"
            )
    migrated = dump_scenario(old) if sections is None else dump_of(old, sections)
    if migrated.split("\n", 1)[1:] == now.split("\n", 1)[1:]:  # but the source line
        return Compared("", old.notes)
    return Compared(_first_difference(migrated, now))


def _first_difference(then: str, now: str) -> str:
    """```line` then, `line` now`` for the first line that differs, or the line counts."""
    old_lines, new_lines = then.splitlines(), now.splitlines()
    for a, b in zip(old_lines[1:], new_lines[1:], strict=False):
        if a != b:
            return f"`{a}` then, `{b}` now"
    return f"{len(old_lines)} lines then, {len(new_lines)} now"


def gained_since(spec: StudySpec, out: Path, run: RunSpec, finished: dict[str, Any]) -> str:
    """The note for sections a finished run's ``scenario.toml`` lacks and change nothing.

    Returns:
        "" when the run's file has every section the study's scenario has now.

    Raises:
        ConfigError: a new section changes the runs.
    """
    then = (out / RUNS_DIR / run.run_id / SCENARIO_FILE).read_text(encoding="utf-8")
    sections = toml_sections(then) or []
    scenario = job_scenario(job_of(spec, run))
    if set(scenario.sections) <= set(sections):
        return ""
    found = gained([(f"run {run.run_id}", scenario)], sections, section_owners(scenario))
    if found.why:
        raise refuse_gained(found, str(spec.path), str(out), len(finished))
    return gained_line(found, str(out), len(finished))


__all__ = [
    "PLAN_FILE",
    "RUNS_DIR",
    "SCENARIO_FILE",
    "Compared",
    "changed",
    "check_fingerprint",
    "combinations",
    "fingerprint",
    "gained_since",
    "job_of",
    "scenario_change",
]
