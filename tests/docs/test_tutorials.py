"""The tutorials run as their readers run them, and do what they say.

Each tutorial's blocks run as ``test_pages.py`` runs the guides' (``tests/docs/pages.py``):
the plugin tutorials' packages are written from the pages' titled blocks, installed with the
page's own ``pip install -e``, run, checked with ``cosim check-plugin`` and tested with their
kit-written tests, all in a clone of the repository; a command that fails fails here. Then,
in the same clone, what each page promises of its outcome (a subtest each): the settings
taken, the summary metrics and tables, the bag's types, the study's rows.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from collections.abc import Callable

import pandas as pd
import pytest

from tests.conftest import REPO
from tests.docs.blocks import Kind
from tests.docs.pages import PAGES, PageRun, PageRuns, Part, parts, run_part

TUTORIALS = tuple(page for page in PAGES if page.startswith("tutorials/"))


def _summary(page: PageRun, out: str) -> dict[str, object]:
    summary: dict[str, object] = json.loads((page.clone.root / out / "summary.json").read_text())
    return summary


def _plugin_passed(page: PageRun, name: str, tests: int) -> None:
    """The page's ``cosim check-plugin NAME`` passed and its ``pytest`` ran ``tests`` tests."""
    checked = page.output_of(f".venv/bin/cosim check-plugin {name}")
    assert checked.stdout.splitlines()[-1].startswith(f"{name}: "), checked.told()
    ran = page.output_of(".venv/bin/python -m pytest")
    assert f"{tests} passed" in ran.stdout, ran.told()


def battery_takes_its_settings_and_records_its_table(page: PageRun) -> None:
    listed = page.output_of(".venv/bin/cosim plugins adapter section")
    assert re.search(r"^  battery\s+fleet-battery\s", listed.stdout, re.M), listed.stdout
    summary = _summary(page, "runs/battery")
    assert 0.9 < float(str(summary["battery_lowest"])) < 1.0
    battery = pd.read_parquet(page.clone.root / "runs" / "battery" / "tables" / "battery.parquet")
    assert list(battery.columns) == ["t_s", "robot", "charge_wh", "percentage"]
    resolved = (page.clone.root / "runs" / "battery" / "scenario.toml").read_text()
    assert "[battery]\ncapacity_wh = 270.0" in resolved and "idle_w = 35.0" in resolved
    info = page.clone.shell(".venv/bin/cosim bag info runs/battery/bag")
    assert "sensor_msgs/msg/BatteryState" in info.stdout, info.told()
    _plugin_passed(page, "battery", tests=3)


def battery_given_in_code_without_its_package_reads_its_defaults(page: PageRun) -> None:
    (snippet,) = [b.code for b in page.blocks if b.kind is Kind.PYTHON]
    code = snippet + "\nprint(result.summary['battery_lowest'])\n"
    # this test environment has no fleet-battery installed: only its source on the path
    source = page.clone.root / "fleet-battery"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(source), str(REPO)])}
    ran = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300
    )
    assert ran.returncode == 0, ran.stderr
    assert 0.0 < float(ran.stdout.split()[-1]) < 1.0


def cheapest_pairs_serves_tasks_alone_and_in_its_study(page: PageRun) -> None:
    summary = _summary(page, "runs/pairs")
    assert int(str(summary["tasks_completed"])) >= 3
    gap = summary["optimality_gap"]
    assert gap is not None and float(str(gap)) >= 0.0
    rows = pd.read_parquet(page.clone.root / "runs" / "pairs_study" / "results.parquet")
    assert len(rows) == 8 and set(rows["status"]) == {"ok"}
    _plugin_passed(page, "cheapest_pairs", tests=3)


def turn_then_go_drives_robots_to_their_goals_within_limits(page: PageRun) -> None:
    summary = _summary(page, "runs/ttg")
    assert int(str(summary["arrivals"])) >= 4
    assert summary["controller_commands_clipped"] == 0  # it keeps to the limits, as the page says
    _plugin_passed(page, "turn_then_go", tests=3)


def the_study_writes_its_report_and_its_analysis_prints_intervals(page: PageRun) -> None:
    assert (page.clone.root / "runs" / "loss" / "report.md").is_file()
    rows = pd.read_parquet(page.clone.root / "runs" / "loss" / "results.parquet")
    assert len(rows) == 18 and set(rows["status"]) == {"ok"}
    analysis = page.python_ran()[-1]
    assert "tasks_per_min_ci_low" in analysis.stdout, analysis.told()


def the_stand_in_runs_leave_their_figures_and_their_domain(page: PageRun) -> None:
    for run in ("lab-real-in-virtual", "lab-mixed"):
        figures = page.clone.root / "runs" / run / "figures"
        assert (figures / "trajectories.png").is_file(), run
        assert _summary(page, f"runs/{run}")["physical_dds_domain"] is not None


def the_hand_written_policy_reaches_goals_and_the_learnt_one_beats_random(page: PageRun) -> None:
    ran = page.python_ran()[-1]
    goals = re.findall(r"(\d+) goals, \d+ contacts", ran.stdout)[-1]
    assert int(goals) >= 3, ran.told()  # the task can be done in 30 s
    curve = pd.read_csv(REPO / "studies" / "results" / "agents_training" / "learning_curve.csv")
    last = curve.iloc[-1]
    assert last["goals_per_min"] > 4 * last["random"]  # the committed figure's claim
    study = pd.read_parquet(REPO / "studies" / "results" / "agents" / "results.parquet")
    by_policy = study.groupby("agents.policy")["agent_arrivals"].mean()
    assert by_policy["sb3"] > 10 * by_policy["random"]


PROMISES: dict[str, tuple[Callable[[PageRun], None], ...]] = {
    "tutorials/write-an-adapter.md": (
        battery_takes_its_settings_and_records_its_table,
        battery_given_in_code_without_its_package_reads_its_defaults,
    ),
    "tutorials/write-a-protocol.md": (cheapest_pairs_serves_tasks_alone_and_in_its_study,),
    "tutorials/write-a-controller.md": (turn_then_go_drives_robots_to_their_goals_within_limits,),
    "tutorials/run-a-study.md": (the_study_writes_its_report_and_its_analysis_prints_intervals,),
    "tutorials/physical-robot.md": (the_stand_in_runs_leave_their_figures_and_their_domain,),
    "tutorials/train-an-agent.md": (
        the_hand_written_policy_reaches_goals_and_the_learnt_one_beats_random,
    ),
}
"""What each tutorial's slow part must show once its blocks ran."""


@pytest.mark.parametrize(
    "part",
    [
        pytest.param(part, id=part.name, marks=[pytest.mark.slow] if part.slow else [])
        for part in parts(TUTORIALS)
    ],
)
def test_a_tutorial_runs_as_its_reader_would_run_it_and_does_what_it_says(
    part: Part, page_runs: PageRuns, subtests: pytest.Subtests
):
    page = run_part(part, page_runs, subtests)
    for promise in PROMISES[part.page] if part.slow else ():
        with subtests.test(msg=f"{part.page}: {promise.__name__.replace('_', ' ')}"):
            promise(page)


def test_every_tutorial_has_its_promises_checked():
    assert set(PROMISES) == set(TUTORIALS)
