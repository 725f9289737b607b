"""What --resume checks of a study folder (cosim.studies.fingerprint): new packages too."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pandas as pd
import pytest

from cosim.core.errors import ConfigError
from cosim.scenario.loader import dump_scenario
from cosim.studies import load_study
from cosim.studies.fingerprint import PLAN_FILE, RUNS_DIR, fingerprint, job_of
from cosim.studies.folder import inspect
from cosim.studies.worker import Outcome, job_scenario, row_cells
from cosim.studies.writing import prepare, write_run
from tests.conftest import cosim_main
from tests.cosim.studies.small import finished, row_times, scenario_file, small_study
from tests.cosim.studies.test_gained import install
from tests.packages import on_path


def started(tmp_path: Path, *, scenario: str = "warehouse-random"):
    """A study folder whose runs all finished (written as a study writes them, not run)."""
    path = small_study(tmp_path, seeds="[1, 2]", scenario=scenario)
    spec = load_study(path)
    out = tmp_path / "out"
    prepare(out, inspect(spec, out, resume=False))
    for run in spec.runs():
        job = job_of(spec, run)
        row = {**row_cells(job), "status": "ok"}
        write_run(out, Outcome(row, dump_scenario(job_scenario(job)), {}, {}))
    return path, out


def resume(path: Path, out: Path):
    return inspect(load_study(path), out, resume=True)


def test_the_plan_keeps_each_section_with_its_package(tmp_path):
    _, out = started(tmp_path)
    plan = json.loads((out / PLAN_FILE).read_text())
    sections = plan["fingerprint"]["sections"]
    assert {"scenario", "world", "robots", "navigation", "mapping"} <= set(sections)
    assert all(owner.startswith("cosim ") for owner in sections.values())


def test_a_package_installed_since_whose_section_changes_nothing_lets_the_study_resume(tmp_path):
    path, out = started(tmp_path)
    with on_path(install(tmp_path / "site", "quietkit")):
        state = resume(path, out)
        assert state.done == {"0000_s1", "0000_s2"}
        assert state.notes == (
            f"{out}: the resolved scenario gained [quietkit] (package quietkit 0.1.0) since the "
            "folder was started (a package installed since); no run of this study sets its "
            "keys and its defaults start nothing, so the 2 finished runs stand: resuming",
        )
        prepare(out, state)  # the plan now has the section: said once, not at every resume
        assert resume(path, out).notes == ()
        assert "quietkit" in json.loads((out / PLAN_FILE).read_text())["fingerprint"]["sections"]


def test_a_package_installed_since_whose_defaults_start_an_adapter_is_refused_naming_it(
    tmp_path,
):
    path, out = started(tmp_path)
    site = install(tmp_path / "site", "loudkit", enabled=True)
    with on_path(site), pytest.raises(ConfigError) as caught:
        resume(path, out)
    assert str(caught.value) == (
        f"{path}: the resolved scenario gained [loudkit] (package loudkit 0.1.0) since {out} "
        "was started, and it changes the runs (its defaults start adapter 'loudkit' in every "
        "run); resuming would mix runs with and without it in one table: uninstall loudkit to "
        f"resume, or run this study with another --out (the 2 finished runs in {out} stay there)"
    )


def test_a_scenario_file_that_sets_the_new_section_is_refused_naming_the_key(tmp_path):
    scenario = scenario_file(tmp_path)
    path, out = started(tmp_path, scenario="scenario.toml")
    with on_path(install(tmp_path / "site", "quietkit")):
        scenario.write_text(scenario.read_text() + "\n[quietkit]\ngain = 2.5\n")
        with pytest.raises(ConfigError, match=r"\(\[quietkit\] gain = 2.5, not its default in "):
            resume(path, out)


def test_a_section_whose_package_was_uninstalled_is_refused_naming_the_package(tmp_path):
    site = install(tmp_path / "site", "quietkit")
    with on_path(site):
        path, out = started(tmp_path)
    with pytest.raises(ConfigError) as caught:
        resume(path, out)
    assert str(caught.value).startswith(
        f"{path}: [quietkit] (package quietkit 0.1.0) is gone from the resolved scenario since "
        f"{out} was started (its package uninstalled, or failing to load: `cosim plugins` "
        "says); the finished runs had it: install quietkit again to resume"
    )


def test_more_changes_than_a_new_section_name_the_first_real_change(tmp_path):
    scenario = scenario_file(tmp_path)
    path, out = started(tmp_path, scenario="scenario.toml")
    scenario.write_text(scenario.read_text().replace("shelf_count = 2", "shelf_count = 3"))
    with on_path(install(tmp_path / "site", "quietkit")), pytest.raises(ConfigError) as caught:
        resume(path, out)
    assert "(run 0000_s1: `shelf_count = 2` then, `shelf_count = 3` now)" in str(caught.value)
    assert "quietkit" not in str(caught.value)


def test_without_the_plan_the_finished_runs_files_show_the_new_section_alone(tmp_path):
    path, out = started(tmp_path)
    (out / PLAN_FILE).unlink()
    with on_path(install(tmp_path / "site", "quietkit")):
        state = resume(path, out)
    assert state.done == {"0000_s1", "0000_s2"}
    assert state.notes[0].startswith(f"{out / PLAN_FILE} is missing: rebuilt from the 2 finished")
    assert state.notes[1].startswith(f"{out}: the resolved scenario gained [quietkit] (package ")
    assert len(state.notes) == 2


def test_a_plan_of_an_older_cosim_without_sections_reads_them_from_a_finished_run(tmp_path):
    path, out = started(tmp_path)
    plan = json.loads((out / PLAN_FILE).read_text())
    del plan["fingerprint"]["sections"]
    (out / PLAN_FILE).write_text(json.dumps(plan))
    with on_path(install(tmp_path / "site", "quietkit")):
        state = resume(path, out)
    assert state.done == {"0000_s1", "0000_s2"}
    assert "gained [quietkit] (package quietkit 0.1.0)" in state.notes[0]


def test_the_fingerprint_of_the_sections_then_is_the_one_the_folder_was_started_with(tmp_path):
    path, out = started(tmp_path)
    spec = load_study(path)
    then = json.loads((out / PLAN_FILE).read_text())["fingerprint"]
    with on_path(install(tmp_path / "site", "quietkit")):
        now = fingerprint(spec)
        assert now["scenario"] != then["scenario"]
        assert fingerprint(spec, keep=then["sections"])["scenario"] == then["scenario"]


@pytest.mark.slow
def test_a_study_resumed_after_installing_a_quiet_package_runs_only_what_is_missing(tmp_path):
    path = small_study(tmp_path)
    out = tmp_path / "out"
    args = ("study", str(path), "--out", str(out), "--workers", "1", "--quiet")
    assert cosim_main(*args).returncode == 0
    shutil.rmtree(out / RUNS_DIR / "0000_s3")  # as if the study had been stopped there
    times = row_times(out)
    with on_path(install(tmp_path / "site", "quietkit")):
        done = cosim_main(*args, "--resume")
    assert done.returncode == 0, done.stderr
    assert (
        f"study: {out}: the resolved scenario gained [quietkit] (package quietkit 0.1.0) since "
        "the folder was started"
    ) in done.stderr
    assert {k: v for k, v in row_times(out).items() if k in times} == times  # not run again
    assert finished(out) == ["0000_s1", "0000_s2", "0000_s3"]
    assert "[quietkit]" in (out / RUNS_DIR / "0000_s3" / "scenario.toml").read_text()
    assert "[quietkit]" not in (out / RUNS_DIR / "0000_s1" / "scenario.toml").read_text()
    results = pd.read_parquet(out / "results.parquet")
    assert list(results["run_id"]) == ["0000_s1", "0000_s2", "0000_s3"]
