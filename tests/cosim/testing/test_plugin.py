"""The kit's pytest plugin, run by pytest itself: the ``cosim_run`` fixture in a user's tests."""

from __future__ import annotations

import subprocess
import sys
import tomllib

import pytest

from tests.conftest import REPO

pytest_plugins = ["pytester"]

USERS_TESTS = '''
from dataclasses import dataclass

from cosim.testing import SMALL_WAREHOUSE, assert_no_conflicts, assert_tasks_assigned_within
from adapters.assignment.protocols import Greedy


class Nearest(Greedy):
    """A user's protocol: greedy under another name."""

    name = "nearest"


def test_a_run_folder_goes_under_the_tests_tmp_path(cosim_run, tmp_path):
    result = cosim_run("warehouse-random", {**SMALL_WAREHOUSE, "robots.driver": "wander"},
                       duration_s=2.0, seed=5, out=True)
    assert result.out == tmp_path / "run-1" and (tmp_path / "run-1" / "summary.json").is_file()
    assert result.summary["seed"] == 5


def test_a_users_protocol_is_registered_for_its_run(cosim_run):
    result = cosim_run(
        "warehouse-random",
        {**SMALL_WAREHOUSE, "robots.driver": "tasks", "assignment.protocol": "nearest"},
        duration_s=15.0,
        plugins={"cosim.protocols": {"nearest": Nearest}},
    )
    assert_tasks_assigned_within(result, 20.0)
    assert_no_conflicts(result)
'''


@pytest.fixture
def pytester(pytester: pytest.Pytester, monkeypatch: pytest.MonkeyPatch) -> pytest.Pytester:
    """pytest in a process of its own (pytest in this one would import pyarrow twice), seeing
    this checkout's cosim."""
    monkeypatch.setenv("PYTHONPATH", str(REPO))
    return pytester


def test_the_fixture_runs_scenarios_and_a_broken_rule_is_reported_with_its_numbers(pytester):
    pytester.makepyfile(test_users=USERS_TESTS)
    done = pytester.runpytest_subprocess("-p", "cosim.testing.plugin", "-p", "no:cacheprovider")
    done.assert_outcomes(passed=1, failed=1)
    done.stdout.fnmatch_lines(
        [
            "*test_a_users_protocol_is_registered_for_its_run*",
            "E * AssertionError: 5 conflicts (a task claimed by two robots): task * at t = *",
        ]
    )


def test_without_the_plugin_a_test_asking_for_cosim_run_has_no_such_fixture(pytester):
    pytester.makepyfile(test_users="def test_it(cosim_run):\n    pass\n")
    done = pytester.runpytest_subprocess("-p", "no:cosim.testing.plugin", "-p", "no:cacheprovider")
    done.assert_outcomes(errors=1)
    done.stdout.fnmatch_lines(["*fixture 'cosim_run' not found*"])


def test_the_pytest11_entry_point_and_asking_by_name_load_the_kit_once(tmp_path):
    # cosim's own metadata is the shared environment's, installed before this entry point
    # existed: a package of metadata alone declares it here exactly as pyproject.toml does
    declared = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]["entry-points"]
    ((name, target),) = declared["pytest11"].items()
    info = tmp_path / "site" / "kitprobe-0.1.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: kitprobe\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(f"[pytest11]\n{name} = {target}\n")
    (tmp_path / "test_probe.py").write_text(
        "def test_the_fixture_is_there(cosim_run):\n    assert callable(cosim_run)\n"
    )
    env = {"PYTHONPATH": f"{tmp_path / 'site'}:{REPO}", "PATH": "/usr/bin:/bin"}
    for asked in ([], ["-p", target]):
        done = subprocess.run(
            [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *asked,
             str(tmp_path / "test_probe.py")],
            capture_output=True, text=True, cwd=tmp_path, env=env, timeout=120,
        )  # fmt: skip
        assert done.returncode == 0, (asked, done.stdout, done.stderr)
        assert "1 passed" in done.stdout


def test_the_fixture_is_documented_for_pytest_fixtures(pytester):
    done = pytester.runpytest_subprocess("-p", "cosim.testing.plugin", "--fixtures")
    done.stdout.fnmatch_lines(["cosim_run -- *cosim*testing*plugin.py*", "*Run a scenario*"])
