"""The tutorials' code, taken from the pages themselves, installed and run as a reader would.

Every code block with a ``title="path"`` is a file of the tutorial's package; the package is
installed into a folder of its own (``pip install --target``) and used through cosim's
command line, so a tutorial that stops working fails here, not for its reader. The plugin
tutorials end with tests written with cosim's testing kit (``tests/test_*.py`` blocks): they
run here with pytest, and ``cosim check-plugin`` on the plugin.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from tests.conftest import REPO

pytestmark = pytest.mark.slow

TUTORIALS = REPO / "docs" / "tutorials"
BLOCK = re.compile(r'^```(\w+)(?: title="([^"]+)")?\n(.*?)^```$', re.M | re.S)


def blocks(page: str) -> list[tuple[str, str | None, str]]:
    """(language, title or None, code) of every fenced block of a tutorial page."""
    text = (TUTORIALS / page).read_text()
    return [(m.group(1), m.group(2), m.group(3)) for m in BLOCK.finditer(text)]


def write_files(page: str, folder: Path) -> Path:
    """The page's titled blocks as files under ``folder``."""
    for _, title, code in blocks(page):
        if title is not None:
            path = folder / title
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_text(code)
    return folder


def install(page: str, tmp_path: Path) -> tuple[Path, dict[str, str]]:
    """Build the page's package, install it into a folder; the environment that sees it."""
    source = write_files(page, tmp_path / "src")
    site = tmp_path / "site"
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--no-build-isolation",
         "--target", str(site), str(source)],
        check=True, capture_output=True, timeout=300,
    )  # fmt: skip
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(REPO)])}
    return source, env


def cosim(
    env: dict[str, str], *args: str, cwd: Path | None = None
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "cosim", *args], capture_output=True, text=True, env=env, cwd=cwd,
        timeout=600,
    )  # fmt: skip


def check_and_test(env: dict[str, str], source: Path, name: str, tests: int) -> None:
    """The page's plugin passes `cosim check-plugin`, and its kit-written tests pass.

    The tests run as the reader runs them, with pytest; cosim's pytest plugin is asked for
    by name (the shared environment's metadata predates its pytest11 entry point).
    """
    checked = cosim(env, "check-plugin", name)
    assert checked.returncode == 0, checked.stdout + checked.stderr
    assert checked.stdout.splitlines()[-1].startswith(f"{name}: ")
    ran = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "cosim.testing.plugin",
         "-p", "no:cacheprovider", str(source / "tests")],
        capture_output=True, text=True, env=env, cwd=source, timeout=600,
    )  # fmt: skip
    assert ran.returncode == 0, ran.stdout + ran.stderr
    assert f"{tests} passed" in ran.stdout


def test_the_adapter_tutorials_battery_installs_runs_and_takes_its_settings(tmp_path):
    source, env = install("write-an-adapter.md", tmp_path)
    listed = cosim(env, "plugins", "adapter", "section")
    assert re.search(r"^  battery\s+fleet-battery\s", listed.stdout, re.M), listed.stdout
    out = tmp_path / "run"
    done = cosim(env, "run", "warehouse-random", "--set", 'scenario.adapters=["battery"]',
                 "--set", "battery.idle_w=35", "--duration-s", "30", "--out", str(out))  # fmt: skip
    assert done.returncode == 0, done.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert 0.9 < summary["battery_lowest"] < 1.0
    battery = pd.read_parquet(out / "tables" / "battery.parquet")
    assert list(battery.columns) == ["t_s", "robot", "charge_wh", "percentage"]
    assert "[battery]\ncapacity_wh = 270.0" in (out / "scenario.toml").read_text()
    info = cosim(env, "bag", "info", str(out / "bag"))
    assert "sensor_msgs/msg/BatteryState" in info.stdout
    refused = cosim(env, "check", "warehouse-random", "--set", "battery.idle_w=-1")
    assert refused.returncode == 2 and "[battery] idle_w = -1" in refused.stderr
    # from Python, with the package's source on the path but not installed: defaults
    (snippet,) = [code for lang, title, code in blocks("write-an-adapter.md")
                  if lang == "python" and title is None]  # fmt: skip
    code = snippet + "\nprint(result.summary['battery_lowest'])\n"
    plain = {**os.environ, "PYTHONPATH": os.pathsep.join([str(source), str(REPO)])}
    ran = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=plain, timeout=300)  # fmt: skip
    assert ran.returncode == 0, ran.stderr
    assert 0.0 < float(ran.stdout.split()[-1]) < 1.0
    check_and_test(env, source, "battery", tests=3)


def test_the_protocol_tutorials_cheapest_pairs_runs_alone_and_in_its_study(tmp_path):
    source, env = install("write-a-protocol.md", tmp_path)
    out = tmp_path / "run"
    done = cosim(env, "run", "warehouse-random", "--set", "robots.driver=tasks",
                 "--set", "assignment.protocol=cheapest_pairs",
                 "--set", "cheapest_pairs.quiet_rounds=2", "--duration-s", "60",
                 "--out", str(out))  # fmt: skip
    assert done.returncode == 0, done.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["tasks_completed"] >= 3
    assert summary["optimality_gap"] is not None and summary["optimality_gap"] >= 0.0
    typo = cosim(env, "check", "warehouse-random", "--set", "assignment.protocol=cheapest_pair")
    assert typo.returncode == 2 and "did you mean 'cheapest_pairs'?" in typo.stderr
    study = cosim(env, "study", str(source / "pairs_study.toml"), "--out", str(tmp_path / "s"),
                  "--workers", "2")  # fmt: skip
    assert study.returncode == 0, study.stderr
    rows = pd.read_parquet(tmp_path / "s" / "results.parquet")
    assert len(rows) == 8 and set(rows["status"]) == {"ok"}
    check_and_test(env, source, "cheapest_pairs", tests=3)


def test_the_controller_tutorials_turn_then_go_drives_robots_to_their_goals(tmp_path):
    source, env = install("write-a-controller.md", tmp_path)
    out = tmp_path / "run"
    done = cosim(env, "run", "warehouse-random", "--set", "navigation.controller=turn_then_go",
                 "--set", "turn_then_go.heading_gain=3", "--duration-s", "60",
                 "--out", str(out))  # fmt: skip
    assert done.returncode == 0, done.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["arrivals"] >= 4
    assert summary["controller_commands_clipped"] == 0  # it keeps to the limits, as the page says
    refused = cosim(env, "check", "warehouse-random", "--set", "turn_then_go.stop_m=0")
    assert refused.returncode == 2 and "expected a number > 0" in refused.stderr
    check_and_test(env, source, "turn_then_go", tests=3)


def test_the_study_tutorial_runs_and_its_analysis_reads_the_results(tmp_path):
    write_files("run-a-study.md", tmp_path)
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    done = cosim(env, "study", "loss_study.toml", "--out", "runs/loss", "--workers", "2",
                 cwd=tmp_path)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "runs" / "loss" / "report.md").is_file()
    (analysis,) = [code for lang, title, code in blocks("run-a-study.md")
                   if lang == "python" and title is None]  # fmt: skip
    ran = subprocess.run([sys.executable, "-c", analysis], capture_output=True, text=True,
                         cwd=tmp_path, env=env, timeout=300)  # fmt: skip
    assert ran.returncode == 0, ran.stderr
    assert "tasks_per_min_ci_low" in ran.stdout


def test_the_physical_robot_tutorials_scenario_checks_without_touching_the_network(tmp_path):
    write_files("physical-robot.md", tmp_path)
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    done = cosim(env, "check", "lab-with-my-robot.toml", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
