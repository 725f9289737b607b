"""The study workers' fork server: tied to the study first, then every kernel loaded once."""

from __future__ import annotations

import importlib
import os
import subprocess
import sys

import pytest

from cosim.runner import execute
from cosim.studies import lifeline
from cosim.studies.lifeline import STUDY_PID_VARIABLE
from tests.conftest import REPO

WARM = "cosim.studies.warm"


@pytest.fixture
def fresh_import():
    """Import the module anew (its work is done at import), then leave sys.modules as it was."""
    before = sys.modules.pop(WARM, None)
    yield lambda: importlib.import_module(WARM)
    sys.modules.pop(WARM, None)
    if before is not None:
        sys.modules[WARM] = before


def test_the_fork_server_binds_itself_to_the_study_before_it_runs_one_tiny_scenario(
    monkeypatch, fresh_import
):
    calls: list[object] = []
    monkeypatch.setattr(lifeline, "bind_fork_server", lambda: calls.append("bind"))
    monkeypatch.setattr(execute, "execute", lambda scenario: calls.append(scenario))
    fresh_import()
    assert len(calls) == 2 and calls[0] == "bind"
    scenario = calls[1]
    assert scenario.name == "warehouse-random"  # type: ignore[attr-defined]
    assert scenario.scenario.duration_s == 0.5  # type: ignore[attr-defined]
    assert scenario.robots.count == 2 and scenario.lidar.beams == 36  # type: ignore[attr-defined]
    assert scenario.record.messages is False  # type: ignore[attr-defined]


def _import_in_a_fresh_interpreter(study_pid: str | None) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k != STUDY_PID_VARIABLE}
    if study_pid is not None:
        env[STUDY_PID_VARIABLE] = study_pid
    return subprocess.run(
        [sys.executable, "-c", f"import {WARM}; print('warmed')"],
        capture_output=True, text=True, env=env, cwd=REPO, timeout=120,
    )  # fmt: skip


@pytest.mark.slow
def test_a_fork_server_whose_study_is_gone_leaves_at_once_without_running():
    # its parent (this process) is not the study it names: the study died meanwhile
    done = _import_in_a_fresh_interpreter("1")
    assert done.returncode == 0, done.stderr
    assert done.stdout == ""


@pytest.mark.slow
def test_a_fork_server_of_a_living_study_loads_the_kernels_and_goes_on():
    done = _import_in_a_fresh_interpreter(str(os.getpid()))
    assert done.returncode == 0, done.stderr
    assert done.stdout == "warmed\n"
