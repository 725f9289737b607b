"""A study's folder and --resume (cosim.studies.folder): what is trusted, what runs again."""

import errno
import json
import os
import subprocess
from collections.abc import Callable, Iterator
from pathlib import Path

import pandas as pd
import pytest

import cosim.scenario.migrations as migrations
import cosim.studies.folder as folder_module
import cosim.studies.writing as writing_module
from cosim.studies import load_study
from tests.conftest import cosim_main
from tests.cosim.studies.small import (
    finished,
    on_its_way,
    row_times,
    scenario_file,
    small_study,
)

RUNS = ["0000_s1", "0000_s2", "0000_s3"]


def _study(tmp_path: Path, out: Path, *extra: str) -> tuple[Path, object]:
    """A finished study of three tiny runs over a scenario file next to it."""
    scenario_file(tmp_path)
    path = small_study(tmp_path, scenario="scenario.toml")
    done = cosim_main("study", str(path), "--out", str(out), "--workers", "1", "--quiet", *extra)
    assert done.returncode == 0, done.stderr
    assert finished(out) == RUNS
    return path, done


def _resume(path: Path, out: Path) -> object:
    return cosim_main(
        "study", str(path), "--out", str(out), "--workers", "1", "--quiet", "--resume"
    )


def _errors(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if line.startswith("cosim:")]


@pytest.mark.slow
def test_resuming_after_the_scenario_file_changed_is_refused_in_one_line(tmp_path):
    out = tmp_path / "out"
    path, _ = _study(tmp_path, out)
    times = row_times(out)
    scenario = tmp_path / "scenario.toml"
    scenario.write_text(scenario.read_text().replace("[robots]\ncount = 2", "[robots]\ncount = 3"))
    done = _resume(path, out)
    assert done.returncode == 2, done.stdout
    assert done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith(f"cosim: error: {path}: the scenario {scenario} changed (run ")
    assert "`count = 2` then, `count = 3` now" in done.stderr
    assert f"the 3 finished runs in {out} stay there" in done.stderr
    assert row_times(out) == times  # nothing rewritten


@pytest.mark.slow
def test_resuming_with_other_seeds_is_refused_naming_a_run_that_changed(tmp_path):
    out = tmp_path / "out"
    path, _ = _study(tmp_path, out)
    path.write_text(path.read_text().replace("seeds = [1, 2, 3]", "seeds = [1, 2, 4]"))
    done = _resume(path, out)
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert "the study's runs changed (3 runs then, 3 now, e.g. 0000_s3 gone)" in done.stderr


@pytest.mark.slow
def test_resuming_without_the_plan_rebuilds_it_and_runs_only_what_is_missing(tmp_path):
    out = tmp_path / "out"
    path, _ = _study(tmp_path, out)
    plan = (out / "plan.json").read_text()
    (out / "plan.json").unlink()
    subprocess.run(["rm", "-r", str(out / "runs" / "0000_s3")], check=True)
    times = row_times(out)
    done = _resume(path, out)
    assert done.returncode == 0, done.stderr
    assert (
        f"study: {out / 'plan.json'} is missing: rebuilt from the 2 finished runs, which match "
        "this study\n"
    ) in done.stderr
    assert {k: v for k, v in row_times(out).items() if k in times} == times  # not run again
    assert finished(out) == RUNS
    assert (out / "plan.json").read_text() == plan
    results = pd.read_parquet(out / "results.parquet")
    assert list(results["run_id"]) == RUNS and set(results["status"]) == {"ok"}


@pytest.mark.slow
def test_resuming_without_the_plan_over_runs_of_another_scenario_is_refused(tmp_path):
    out = tmp_path / "out"
    path, _ = _study(tmp_path, out)
    (out / "plan.json").unlink()
    scenario = tmp_path / "scenario.toml"
    scenario.write_text(scenario.read_text().replace("shelf_count = 2", "shelf_count = 3"))
    done = _resume(path, out)
    assert done.returncode == 2 and len(_errors(done.stderr)) == 1, done.stderr
    assert "the scenario of finished run 0000_s1 changed (`shelf_count = 2` then" in done.stderr


@pytest.mark.slow
@pytest.mark.parametrize(
    "junk",
    [b"junk", b"", b'{"run_id": "0000_s2", "sta', b"\xff\xfe", b"[" * 100_000, b"[]"],
    ids=["text", "empty", "cut", "not-utf8", "deep", "list"],
)
def test_a_garbled_row_runs_again_and_the_other_runs_are_kept(tmp_path, junk):
    out = tmp_path / "out"
    path, _ = _study(tmp_path, out)
    (out / "runs" / "0000_s2" / "row.json").write_bytes(junk)
    times = row_times(out)
    done = _resume(path, out)
    assert done.returncode == 0, done.stderr
    assert f"study: {out / 'runs' / '0000_s2'} row.json " in done.stderr
    assert ": running 0000_s2 again\n" in done.stderr
    after = row_times(out)
    assert after["0000_s1"] == times["0000_s1"] and after["0000_s3"] == times["0000_s3"]
    assert after["0000_s2"] != times["0000_s2"]
    results = pd.read_parquet(out / "results.parquet")
    assert list(results["run_id"]) == RUNS and set(results["status"]) == {"ok"}


@pytest.mark.slow
def test_a_row_of_other_settings_under_an_intact_plan_runs_again(tmp_path):
    out = tmp_path / "out"
    path, _ = _study(tmp_path, out)
    row_path = out / "runs" / "0000_s2" / "row.json"
    row = json.loads(row_path.read_text())
    row_path.write_text(json.dumps({**row, "seed": 9}))
    done = _resume(path, out)
    assert done.returncode == 0, done.stderr
    assert f"{out / 'runs' / '0000_s2'} row.json has seed = 9, the study 2: running" in done.stderr
    assert pd.read_parquet(out / "results.parquet")["seed"].tolist() == [1, 2, 3]


@pytest.mark.parametrize("where", ["file", "under a file"])
def test_an_out_where_a_file_stands_exits_2_in_one_line(tmp_path, where):
    stand_in = tmp_path / "results.txt"
    stand_in.write_text("not a folder\n")
    out = stand_in if where == "file" else stand_in / "study"
    path = small_study(tmp_path)
    for resume in ((), ("--resume",)):
        done = cosim_main("study", str(path), "--out", str(out), "--workers", "1", *resume)
        assert done.returncode == 2, done.stdout
        assert done.stderr.count("\n") == 1, done.stderr
        expected = (
            f"{out}: is a file; expected a study folder for --out"
            if where == "file"
            else f"{out}: cannot create the study folder: {stand_in} is a file"
        )
        assert done.stderr == f"cosim: error: {expected}\n"
    assert stand_in.read_text() == "not a folder\n"


# --- a full disk ------------------------------------------------------------------------------


@pytest.fixture
def tmpfs(tmp_path: Path) -> Iterator[Callable[[int], Path | None]]:
    """Mounts a tmpfs of a size (KiB) in a new folder, or None where mounting is refused."""
    mounted: list[Path] = []

    def mount(size_kib: int) -> Path | None:
        where = tmp_path / f"disk{len(mounted)}"
        where.mkdir()
        command = ["mount", "-t", "tmpfs", "-o", f"size={size_kib}k", "tmpfs", str(where)]
        if subprocess.run(command, capture_output=True).returncode:
            return None
        mounted.append(where)
        return where

    yield mount
    for where in mounted:
        subprocess.run(["umount", "-l", str(where)], capture_output=True)


def _grow(disk: Path | None, monkeypatch: pytest.MonkeyPatch) -> None:
    """Free space: a bigger tmpfs (its files kept), or the ENOSPC stand-in taken away."""
    if disk is None:
        monkeypatch.undo()
    else:
        command = ["mount", "-o", "remount,size=8m", str(disk)]
        subprocess.run(command, check=True, capture_output=True)


def _full_after(
    monkeypatch: pytest.MonkeyPatch, owner: object, name: str, calls: int, *, path_at: int = 0
) -> None:
    """Where no tmpfs can be mounted: ``owner.name`` fails with ENOSPC after ``calls`` calls.

    Args:
        path_at: which argument is the path written (named in the error).
    """
    real = getattr(owner, name)
    count = [0]

    def full(*args: object, **kwargs: object) -> object:
        count[0] += 1
        if count[0] > calls:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(args[path_at]))
        return real(*args, **kwargs)

    monkeypatch.setattr(owner, name, full)


@pytest.mark.slow
def test_a_full_disk_mid_study_exits_2_in_one_line_and_keeps_the_finished_runs(
    tmp_path, tmpfs, monkeypatch
):
    path = small_study(tmp_path, seeds="[1, 2, 3, 4]")
    # 4 KiB pages: the plan takes one, a run four (row, a summary whose plugins take two,
    # scenario): one run fits
    disk = tmpfs(32)
    if disk is None:
        _full_after(monkeypatch, writing_module, "_write_run_files", 2)
    out = (disk or tmp_path) / "out"
    done = cosim_main("study", str(path), "--out", str(out), "--workers", "1", "--quiet")
    assert done.returncode == 2, done.stdout
    assert done.stderr.count("\n") == 1, done.stderr
    kept = finished(out)
    assert 1 <= len(kept) < 4
    assert done.stderr.startswith(f"cosim: error: small: {out}: cannot write run ")
    assert "(No space left on device" in done.stderr
    assert done.stderr.endswith(
        f"the {len(kept)} finished runs are kept in {out}: free space or fix the folder, then "
        "continue with --resume\n"
    )
    assert not [p for p in (out / "runs").iterdir() if on_its_way(p)]  # its space is freed
    times = row_times(out)
    _grow(disk, monkeypatch)
    resumed = cosim_main("study", str(path), "--out", str(out), "--workers", "1", "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert f"resuming, {len(kept)}/4 runs already done" in resumed.stderr
    assert {k: v for k, v in row_times(out).items() if k in times} == times
    assert len(pd.read_parquet(out / "results.parquet")) == 4


@pytest.mark.slow
def test_a_disk_too_full_for_the_results_keeps_every_run_for_resume(tmp_path, tmpfs, monkeypatch):
    path = small_study(tmp_path)
    # a plan page and three runs of six pages (scenario.toml's sections take two,
    # summary.json's plugins three) fit; results.parquet (some 42 KiB) does not
    disk = tmpfs(80)
    if disk is None:
        _full_after(monkeypatch, pd.DataFrame, "to_parquet", 0, path_at=1)
    out = (disk or tmp_path) / "out"
    done = cosim_main("study", str(path), "--out", str(out), "--workers", "1", "--quiet")
    assert done.returncode == 2, done.stdout
    assert done.stderr.count("\n") == 1, done.stderr
    assert done.stderr.startswith(
        f"cosim: error: small: {out / 'results.parquet'}: cannot write the results ("
    )
    assert done.stderr.endswith(
        f"the 3 finished runs are kept in {out}: free space or fix the folder, then continue "
        "with --resume\n"
    )
    assert finished(out) == RUNS and not (out / "results.parquet").exists()
    times = row_times(out)
    _grow(disk, monkeypatch)
    resumed = cosim_main("study", str(path), "--out", str(out), "--workers", "1", "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert "resuming, 3/3 runs already done" in resumed.stderr
    assert row_times(out) == times
    assert list(pd.read_parquet(out / "results.parquet")["run_id"]) == RUNS


def test_the_plan_names_the_runs_and_the_fingerprint_of_the_scenario(tmp_path):
    scenario_file(tmp_path)
    spec = load_study(small_study(tmp_path, scenario="scenario.toml"))
    plan = folder_module.plan_of(spec)
    assert [r["run_id"] for r in plan["runs"]] == RUNS
    assert plan["scenario"] == str(tmp_path / "scenario.toml")
    assert len(plan["fingerprint"]["scenario"]) == 64


# --- runs of earlier formats --------------------------------------------------------------------


def _as_written_before(out: Path, old: str, new: str) -> None:
    """Make the finished runs' scenario.toml and the plan look as an older cosim wrote them."""
    for run_id in RUNS:
        path = out / "runs" / run_id / "scenario.toml"
        text = path.read_text()
        assert new in text
        path.write_text(text.replace(new, old))
        summary = out / "runs" / run_id / "summary.json"
        found = json.loads(summary.read_text())
        found.pop("format")
        summary.write_text(json.dumps(found))
    plan = json.loads((out / "plan.json").read_text())
    plan["fingerprint"]["scenario"] = "0" * 64  # what an older cosim's dump hashed to
    (out / "plan.json").write_text(json.dumps(plan))


@pytest.mark.slow
def test_resuming_runs_of_before_a_rename_of_the_same_meaning_continues_with_a_note(
    tmp_path, monkeypatch
):
    rename = migrations.Rename("robots.number", "robots.count", "0000000", int, True, "same")
    monkeypatch.setattr(migrations, "RENAMES", (*migrations.RENAMES, rename))
    out = tmp_path / "out"
    path, _ = _study(tmp_path, out)
    times = row_times(out)
    _as_written_before(out, "\n[robots]\nnumber = 2\n", "\n[robots]\ncount = 2\n")
    done = cosim_main("study", str(path), "--out", str(out), "--workers", "1", "--resume")
    assert done.returncode == 0, done.stderr
    assert f"study: {out / 'plan.json'}: the scenario differs from the plan's only by keys " in (
        done.stderr
    )
    assert "[robots] number = 2 read as robots.count = 2 (renamed in 0000000: same)" in (
        done.stderr
    )
    assert "resuming, 3/3 runs already done" in done.stderr
    assert row_times(out) == times  # none run again


@pytest.mark.slow
def test_resuming_runs_of_before_yield_s_was_renamed_is_refused_naming_the_rename(tmp_path):
    out = tmp_path / "out"
    path, _ = _study(tmp_path, out)
    times = row_times(out)
    _as_written_before(out, "\nyield_s = 10.0\n", "\navoid_robots = true\n")
    done = _resume(path, out)
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert (
        "changed (run 0000_s1: humans.yield_s = 10.0 then, renamed humans.avoid_robots in "
        "462a048: people keep clear of robots"
    ) in done.stderr
    assert row_times(out) == times
    (out / "plan.json").unlink()  # the plan lost: the runs are the evidence, read the same way
    done = _resume(path, out)
    assert done.returncode == 2 and len(_errors(done.stderr)) == 1, done.stderr
    assert "finished run 0000_s1 changed (humans.yield_s = 10.0 then, renamed" in done.stderr


def test_a_run_folder_of_a_newer_format_stops_the_resume_in_one_line(tmp_path):
    path = small_study(tmp_path)
    out = tmp_path / "out"
    (out / "runs" / "0000_s1").mkdir(parents=True)
    (out / "runs" / "0000_s1" / "summary.json").write_text(json.dumps({"format": 99}))
    done = cosim_main("study", str(path), "--out", str(out), "--workers", "1", "--resume")
    assert done.returncode == 2 and done.stderr.count("\n") == 1, done.stderr
    assert f"{out / 'runs' / '0000_s1'}: a run folder of format 99, written by a newer cosim" in (
        done.stderr
    )
